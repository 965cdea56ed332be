// The style registry: one description per style, read by everything that
// lists styles; plans hold only the values their style reads.
#include "parcelscope/generation/Styles.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "TestUtil.h"
#include "generation/StyleRun.h"
#include "generation/TilingCheck.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::generation {
namespace {

TEST(Styles, EachStyleIsRegisteredOnceWithItsParametersAndTheListsFollowTheRegistry) {
  std::set<std::string> names;
  for (const Style* s : styles()) {
    EXPECT_TRUE(names.insert(s->name()).second) << s->name();
    EXPECT_FALSE(s->description().empty()) << s->name();
    std::set<std::string> parameters;
    for (const auto& d : s->parameters()) parameters.insert(d.name);
    EXPECT_EQ(parameters.count("a-max"), 1u) << s->name() << " lacks a-max";
    EXPECT_EQ(parameters.count("min-frontage"), 1u) << s->name() << " lacks min-frontage";
    // parish reads only its threshold area (Parish & Muller 2001), sexton no W_max nor omega, template no omega.
    if (s->name() == "parish" || s->name() == "sexton" || s->name() == "template") continue;
    for (const char* bound : {"a-min", "w-min", "w-max", "omega", "seed"}) {
      EXPECT_EQ(parameters.count(bound), 1u) << s->name() << " lacks " << bound;
    }
    EXPECT_EQ(&style(s->name()), s);
  }
  EXPECT_EQ(names,
            (std::set<std::string>{"obb", "skeleton", "offset", "parish", "sexton", "template", "access", "auto"}));
  ASSERT_EQ(generationStyles().size(), styles().size());
  for (std::size_t i = 0; i < styles().size(); ++i) EXPECT_EQ(generationStyles()[i].first, styles()[i]->name());
  try {
    style("voronoi");
    FAIL() << "an unknown style is a usage error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Usage);
    EXPECT_NE(std::string(e.what()).find("obb, skeleton, offset, parish, sexton, template, access, auto"),
              std::string::npos)
        << e.what();
  }
}

TEST(Styles, StyleValuesHoldWhatTheStyleReadsAndNothingElse) {
  ParameterValues values = defaultValues(generationParameterDescriptions());
  values["street-angle"] = 45;
  values["block-tolerance"] = 2;
  const ParameterValues obb = styleValues(obbStyle(), values);
  EXPECT_EQ(obb.count("street-angle"), 0u);     // a skeleton parameter
  EXPECT_EQ(obb.count("block-tolerance"), 0u);  // builds blocks, not parcels
  EXPECT_EQ(obb.at("a-max"), values.at("a-max"));
  const ParameterValues skeleton = styleValues(skeletonStyle(), values);
  EXPECT_EQ(skeleton.at("street-angle"), 45);
  EXPECT_EQ(skeleton.at("a-max"), values.at("a-max"));
}

TEST(Styles, AccessAndAutoChoosePerBlockAndDoNotSubdivideThemselves) {
  // access: the paper's rule, on the observed parcels' street access alone.
  EXPECT_EQ(&accessStyle().resolve({0.5}), &obbStyle());
  EXPECT_EQ(&accessStyle().resolve({0.95}), &skeletonStyle());
  EXPECT_EQ(&accessStyle().resolve({std::nan("")}), &skeletonStyle());
  // auto without observed parcels: the paper's rule.
  EXPECT_EQ(&autoStyle().resolve({0.5}), &obbStyle());
  EXPECT_EQ(&autoStyle().resolve({std::nan("")}), &skeletonStyle());
  EXPECT_EQ(&obbStyle().resolve({0.5}), &obbStyle());
  EXPECT_TRUE(choosesPerBlock(autoStyle()));
  EXPECT_TRUE(choosesPerBlock(accessStyle()));
  // The paper's rule slices evenly (its skeleton's default draws observed widths); auto pins nothing.
  ParameterValues values = styleValues(skeletonStyle(), {});
  EXPECT_EQ(values.at("slice-widths"), 1);
  autoStyle().pinValues(values);
  EXPECT_EQ(values.at("slice-widths"), 1);
  accessStyle().pinValues(values);
  EXPECT_EQ(values.at("slice-widths"), 0);
  EXPECT_FALSE(choosesPerBlock(sextonStyle()));
  for (const char* name : {"auto", "access"})
    EXPECT_THROW(subdivideBlock(test::rect(0, 0, 60, 40), name, {}, 1), Error);
  // Every parameter of every style auto may pick is one of auto's.
  std::set<std::string> names;
  for (const auto& d : autoStyle().parameters()) names.insert(d.name);
  for (const Style* s : styles()) {
    if (choosesPerBlock(*s)) continue;
    for (const auto& d : s->parameters()) EXPECT_EQ(names.count(d.name), 1u) << s->name() << ": " << d.name;
  }
}

// The offset style's d_offset, when not given, is the block's parcel depth:
// its observed parcels' mean length (30 m without observed parcels).
TEST(Styles, OffsetDepthIsTheObservedParcelsMeanLength) {
  const Polygon block = test::rect(0, 0, 200, 100);
  auto patioArea = [&](const Subdivision& s) {
    double inner = 0;  // parcels away from every street: the patio's
    for (const Polygon& q : s.parcels) {
      const Box b = bounds(q);
      if (b.minX > 1 && b.maxX < 199 && b.minY > 1 && b.maxY < 99) inner += area(q);
    }
    return inner;
  };
  ObservedSample observed;
  observed.widths = {10, 10, 12};
  observed.aspectRatios = {2, 1.5, 2.5};  // lengths 20, 15, 30: mean 21.67 m
  const Subdivision deep = test::runStyle(offsetStyle(), block, {{"slice-widths", 0}}, 1);
  const Subdivision fitted = test::runStyle(offsetStyle(), block, {{"slice-widths", 0}}, 1, &observed);
  const double d = (20.0 + 15.0 + 30.0) / 3;
  EXPECT_TILES(block, fitted.parcels, "offset, observed depth");
  EXPECT_NEAR(patioArea(deep), 140.0 * 40.0, 1e-3);  // the skeleton's input is jittered by up to 1e-6 m
  EXPECT_NEAR(patioArea(fitted), (200 - 2 * d) * (100 - 2 * d), 1e-3);
  // A depth given wins.
  const Subdivision given = test::runStyle(offsetStyle(), block, {{"slice-widths", 0}, {"offset", 25}}, 1, &observed);
  EXPECT_NEAR(patioArea(given), 150.0 * 50.0, 1e-3);
}

TEST(Styles, ConcreteStylesTileARectangleReproducibly) {
  const Polygon block = test::rect(0, 0, 120, 60);
  for (const char* name : {"obb", "skeleton", "offset", "parish", "sexton", "template"}) {
    const Subdivision a = subdivideBlock(block, name, {}, 7), b = subdivideBlock(block, name, {}, 7);
    ASSERT_GT(a.parcels.size(), 1u) << name;
    ASSERT_EQ(a.parcels.size(), b.parcels.size()) << name;
    double sum = 0;
    for (std::size_t i = 0; i < a.parcels.size(); ++i) {
      EXPECT_TRUE(test::sameBits(a.parcels[i], b.parcels[i])) << name << " parcel " << i;
      sum += area(a.parcels[i]);
    }
    EXPECT_NEAR(sum, area(block), 1e-9 * area(block)) << name;
    EXPECT_FALSE(a.failed) << name;
  }
}

}  // namespace
}  // namespace parcelscope::generation
