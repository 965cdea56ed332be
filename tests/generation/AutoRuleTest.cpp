// The auto style's rule: block features, the training table and the vote.
#include "parcelscope/generation/AutoRule.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/generation/Styles.h"

namespace parcelscope::generation {
namespace {

const std::string kHeader =
    "city,f_log_area,f_box_ratio,f_convexity,f_access,f_log_mean_area,f_log_parcels,f_log_aspect,style\n";

TEST(AutoRule, FeaturesDescribeTheBlockAndItsObservedParcels) {
  ObservedSample s;
  s.areas = {100, 300, 200, 400};
  s.aspectRatios = {1, 2, 4, 8};
  const AutoFeatures f = autoFeatures(test::rect(0, 0, 100, 50), s, 0.75, 0.5);
  EXPECT_NEAR(f[0], std::log10(5000.0), 1e-12);  // area
  EXPECT_NEAR(f[1], 0.5, 1e-12);                 // box width / length
  EXPECT_NEAR(f[2], 1.0, 1e-12);                 // convex
  EXPECT_EQ(f[3], 0.75);
  EXPECT_NEAR(f[4], std::log10(250.0), 1e-12);  // mean observed area
  EXPECT_NEAR(f[5], std::log10(2.0), 1e-12);    // half of the 4 parcels in this part
  EXPECT_NEAR(f[6], std::log10(4.0), 1e-12);    // the upper median of 1, 2, 4, 8
  // An L: convexity below 1.
  Polygon l;
  l.outer = {{0, 0}, {40, 0}, {40, 10}, {10, 10}, {10, 40}, {0, 40}};
  EXPECT_NEAR(autoFeatures(l, s, 1.0)[2], 700.0 / 1150.0, 1e-9);
}

TEST(AutoRule, NearestRowsVoteByInverseDistanceTiesToTheNearest) {
  auto row = [](double x, const char* style) {
    AutoRule::Row r;
    r.features.fill(0);
    r.features[0] = x;
    r.style = style;
    return r;
  };
  const AutoRule rule({row(0, "obb"), row(1, "sexton"), row(2, "sexton"), row(10, "parish"), row(11, "parish"),
                       row(12, "parish"), row(13, "skeleton")},
                      3);
  AutoFeatures x{};
  x[0] = 0.5;
  EXPECT_EQ(rule.predict(x), "sexton");  // obb 1 / 0.5 against sexton 1 / 0.5 + 1 / 1.5
  x[0] = 0.2;
  EXPECT_EQ(rule.predict(x), "obb");  // obb 1 / 0.2 against sexton 1 / 0.8 + 1 / 1.8
  x[0] = 0;
  EXPECT_EQ(rule.predict(x), "obb");  // a training row's own features: its style
  x[0] = 12.4;
  EXPECT_EQ(rule.predict(x), "parish");  // parish 12 and 11 against skeleton 13
  x[0] = 12.9;
  EXPECT_EQ(rule.predict(x), "skeleton");  // skeleton 1 / 0.1 against parish 1 / 0.9 + 1 / 1.9
  x[0] = 13;
  EXPECT_EQ(rule.predict(x), "skeleton");  // its own row, whatever the two parish rows say
  // The rows' standard deviation is sqrt(28) = 5.29: beyond 3 of it from
  // every row, a block is unlike them all and takes sexton.
  x[0] = 28;
  EXPECT_EQ(rule.predict(x), "parish");  // 2.83 from the nearest row: parish 1 / 16 + 1 / 17 against skeleton 1 / 15
  x[0] = 30;
  EXPECT_EQ(rule.predict(x), "sexton");  // 3.21
  x[0] = 12;
  x[1] = 3.5;                            // a feature the rows all share (0): its scale is 1
  EXPECT_EQ(rule.predict(x), "sexton");  // 3.5 from parish's row, which the vote would give
  x[1] = 2.5;
  EXPECT_EQ(rule.predict(x), "parish");
  const AutoRule pairs({row(0, "obb"), row(1, "sexton"), row(5, "skeleton"), row(6, "template")}, 2);
  x[0] = 0.5;
  EXPECT_EQ(pairs.predict(x), "obb");  // equal votes: the nearer (the first of equals)
  x[0] = 0.6;
  EXPECT_EQ(pairs.predict(x), "sexton");
}

TEST(AutoRule, ReadsATableLeavesCitiesOutAndNamesTheLineOfABadRow) {
  const std::string table = kHeader + "a,3,0.5,0.9,1,2.5,1,0.3,obb\nb,4,0.5,0.9,1,2.5,1,0.3,sexton\n";
  EXPECT_EQ(AutoRule::fromCsv(table, "t.csv").rows().size(), 2u);
  const AutoRule onlyB = AutoRule::fromCsv(table, "t.csv", {"a"});
  ASSERT_EQ(onlyB.rows().size(), 1u);
  EXPECT_EQ(onlyB.rows()[0].style, "sexton");
  auto message = [](const std::string& text) {
    try {
      AutoRule::fromCsv(text, "t.csv");
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), Error::Kind::Input);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(kHeader + "a,3,x,0.9,1,2.5,1,0.3,obb\n"), "t.csv:2: f_box_ratio is 'x', not a number");
  EXPECT_EQ(message(kHeader + "a,3,0.5,0.9,1,2.5,1,0.3,auto\n"),
            "t.csv:2: style auto chooses per block; name a concrete one");
  EXPECT_NE(message(kHeader + "a,3,0.5,0.9,1,2.5,1,0.3,voronoi\n").find("t.csv:2: no subdivision style 'voronoi'"),
            std::string::npos);
  EXPECT_EQ(message(kHeader + "a,3,0.5\n"), "t.csv:2: 3 fields, the header has 9");
  EXPECT_EQ(message("city,style\n"), "t.csv: the auto rule table has no column 'f_log_area'");
  EXPECT_EQ(message(kHeader), "t.csv: the auto rule table has no training blocks");
  EXPECT_EQ(message(table), "no error");
}

TEST(AutoRule, TheBundledRuleIsTrainedOnTheSixSharedDatasetsWithConcreteStyles) {
  const AutoRule& rule = AutoRule::bundled();
  EXPECT_GT(rule.rows().size(), 1000u);
  std::set<std::string> styles;
  for (const AutoRule::Row& r : rule.rows()) styles.insert(r.style);
  EXPECT_GE(styles.size(), 3u);
  for (const std::string& s : styles) EXPECT_FALSE(choosesPerBlock(style(s))) << s;
  // A training block gives back its calibrated style (its own vote outweighs
  // its neighbours'), and one slightly moved still does.
  std::size_t same = 0, moved = 0;
  for (const AutoRule::Row& r : rule.rows()) {
    same += rule.predict(r.features) == r.style;
    AutoFeatures x = r.features;
    x[0] += 1e-7;
    moved += rule.predict(x) == r.style;
  }
  EXPECT_EQ(same, rule.rows().size());
  EXPECT_EQ(moved, rule.rows().size());
  // Leaving a city out leaves its rows out.
  const std::size_t withoutCambridge =
      AutoRule::fromCsv(AutoRule::bundledTable(), "auto_rule.csv", {"cambridge_ma"}).rows().size();
  EXPECT_GT(withoutCambridge, 0u);
  EXPECT_LT(withoutCambridge, rule.rows().size());
  // The auto style asks this rule when the block has observed parcels.
  ObservedSample s;
  s.areas = {400, 420, 380, 410, 390, 405};
  s.aspectRatios = {2.5, 2.6, 2.4, 2.5, 2.7, 2.3};
  const Polygon block = test::rect(0, 0, 120, 40);
  const AutoFeatures f = autoFeatures(block, s, 1.0);
  BlockFacts facts{1.0, &block, &s, 1.0};
  EXPECT_EQ(autoStyle().resolve(facts).name(), rule.predict(f));
}

}  // namespace
}  // namespace parcelscope::generation
