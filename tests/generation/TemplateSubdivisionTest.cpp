// The template style (Yang et al. 2013, section 4): templates matched to a
// block by its corners, warped onto it (section 4.1), their interior lines
// used as split lines.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <random>

#include "RandomShapes.h"
#include "StyleRun.h"
#include "TemplateWarp.h"
#include "TestUtil.h"
#include "TilingCheck.h"
#include "parcelscope/generation/Styles.h"

namespace parcelscope::generation {
namespace {

Subdivision withTemplate(const Polygon& block, const ParameterValues& values, std::uint64_t seed = 1,
                         const ObservedSample* observed = nullptr) {
  return test::runStyle(templateStyle(), block, values, seed, observed);
}

TEST(Template, ARectangleGetsARowOrGridWithParcelsWithinTheBounds) {
  const Polygon block = test::rect(0, 0, 200, 60);
  const ParameterValues bounds = {{"a-min", 300}, {"a-max", 900}, {"w-min", 10}, {"w-max", 25}};
  const Subdivision s = withTemplate(block, bounds);
  ASSERT_FALSE(s.fallback) << s.fallbackReason;
  EXPECT_TRUE(s.variant == "row" || s.variant == "grid") << s.variant;
  EXPECT_TILES(block, s.parcels, "200 x 60");
  EXPECT_GT(s.parcels.size(), 6u);
  EXPECT_EQ(s.withoutAccess, 0);
  EXPECT_EQ(s.oversize, 0);
  for (const Polygon& p : s.parcels) {
    const OrientedBox box = minimumAreaBox(p.outer);
    EXPECT_GE(box.width, 10 - 1e-6);
    EXPECT_LE(box.width, 25 + 1e-6);
    EXPECT_GE(area(p), 300 - 1e-6);
    EXPECT_LE(area(p), 900 + 1e-6);
  }
  // Observed parcels 20 m wide and 600 m² (two rows of 30 m deep lots): the
  // grid of two rows, 10 parcels each.
  ObservedSample observed;
  observed.areas.assign(20, 600.0);
  observed.widths.assign(20, 20.0);
  observed.aspectRatios.assign(20, 1.5);
  const Subdivision fitted = withTemplate(block, bounds, 1, &observed);
  EXPECT_EQ(fitted.variant, "grid");
  EXPECT_EQ(fitted.parcels.size(), 20u);
  for (const Polygon& p : fitted.parcels) EXPECT_NEAR(area(p), 600, 1e-6);
}

// A row's count follows the observed parcels' shape too, not only their
// frontage and area: the same widths and areas, observed as near squares, give
// fewer and squarer parcels than observed as strips.
TEST(Template, TheCountFollowsTheObservedAspectRatio) {
  const Polygon block = test::rect(0, 0, 200, 80);
  const ParameterValues bounds = {{"a-min", 50}, {"a-max", 5000}, {"w-min", 2}, {"w-max", 100}};
  auto observedOf = [](double aspect) {
    ObservedSample o;
    o.areas.assign(20, 200.0);
    o.widths.assign(20, 10.0);
    o.aspectRatios.assign(20, aspect);
    return o;
  };
  auto medianAspect = [](const Subdivision& s) {
    std::vector<double> r;
    for (const Polygon& p : s.parcels) {
      const OrientedBox b = minimumAreaBox(p.outer);
      r.push_back(b.length / b.width);
    }
    std::sort(r.begin(), r.end());
    return r[r.size() / 2];
  };
  const ObservedSample squares = observedOf(1.2), strips = observedOf(4);
  const Subdivision fromSquares = withTemplate(block, bounds, 1, &squares);
  const Subdivision fromStrips = withTemplate(block, bounds, 1, &strips);
  ASSERT_FALSE(fromSquares.fallback) << fromSquares.fallbackReason;
  ASSERT_FALSE(fromStrips.fallback) << fromStrips.fallbackReason;
  EXPECT_TILES(block, fromSquares.parcels, "200 x 80");
  EXPECT_LT(fromSquares.parcels.size(), fromStrips.parcels.size());
  EXPECT_LT(medianAspect(fromSquares), medianAspect(fromStrips));
  std::printf("parcels %zu (observed 1:1.2), %zu (observed 1:4); median aspect %.2f, %.2f\n",
              fromSquares.parcels.size(), fromStrips.parcels.size(), medianAspect(fromSquares),
              medianAspect(fromStrips));
}

TEST(Template, ADeadEndGetsTheSpikeATriangleARowAndADiscFallsBack) {
  // 160 x 120 with a dead-end street 20 m wide and 60 m long from the bottom side.
  const Polygon block = test::poly({{0, 0}, {70, 0}, {70, 60}, {90, 60}, {90, 0}, {160, 0}, {160, 120}, {0, 120}});
  const ParameterValues bounds = {{"a-min", 300}, {"a-max", 1500}, {"w-min", 10}, {"w-max", 40}};
  const Subdivision s = withTemplate(block, bounds);
  ASSERT_FALSE(s.fallback) << s.fallbackReason;
  EXPECT_EQ(s.variant, "spike");
  EXPECT_TILES(block, s.parcels, "dead end");
  EXPECT_EQ(s.withoutAccess, 0);
  // The fan: several parcels touch the dead end's end (y = 60, 70 < x < 90).
  int atEnd = 0;
  for (const Polygon& p : s.parcels) {
    double along = 0;
    for (std::size_t i = 0; i < p.outer.size(); ++i) {
      const Point &a = p.outer[i], &b = p.outer[(i + 1) % p.outer.size()];
      if (std::fabs(a.y - 60) < 1e-6 && std::fabs(b.y - 60) < 1e-6 && std::min(a.x, b.x) >= 70 - 1e-6 &&
          std::max(a.x, b.x) <= 90 + 1e-6)
        along += std::fabs(b.x - a.x);
    }
    atEnd += along > 1;
  }
  EXPECT_GE(atEnd, 2);
  // A triangle has three corners: a fourth, virtual one in the middle of its
  // longest side lets a row or grid fit it.
  const Polygon triangle = test::poly({{0, 0}, {200, 0}, {60, 150}});
  const Subdivision t = withTemplate(triangle, bounds);
  EXPECT_FALSE(t.fallback) << t.fallbackReason;
  EXPECT_TRUE(t.variant == "row" || t.variant == "grid") << t.variant;
  EXPECT_TILES(triangle, t.parcels, "triangle");
  // A disc has no corners at all: obb subdivides it, the reason given.
  Polygon disc;
  for (int i = 0; i < 64; ++i) disc.outer.push_back({80 * std::cos(2 * kPi * i / 64), 80 * std::sin(2 * kPi * i / 64)});
  const Subdivision d = withTemplate(disc, bounds);
  EXPECT_TRUE(d.fallback);
  EXPECT_NE(d.fallbackReason.find("no template fits"), std::string::npos) << d.fallbackReason;
  EXPECT_TRUE(d.variant.empty());
  EXPECT_TILES(disc, d.parcels, "disc");
}

// Random shapes: a tiling, valid, reproducible; most get a template.
TEST(Template, RandomShapesTileReproduciblyAndMostGetATemplate) {
  std::mt19937_64 rng(20261129);
  int shapes = 0, fallbacks = 0;
  std::map<std::string, int> used;
  for (int i = 0; i < 70 / test::kSanitizerDivisor; ++i, ++shapes) {
    const Polygon block = test::randomShape(rng, i % test::kShapeKinds);
    const ObbParameters b = test::randomBounds(rng, area(block));
    const std::uint64_t seed = rng();
    const ParameterValues values = {{"a-min", b.aMin}, {"a-max", b.aMax}, {"w-min", b.wMin}, {"w-max", b.wMax}};
    const Subdivision s = withTemplate(block, values, seed);
    const std::string what = "shape " + std::to_string(i) + " kind " + std::to_string(i % test::kShapeKinds);
    ASSERT_FALSE(s.failed) << what << ": " << s.failure;
    EXPECT_TILES(block, s.parcels, what);
    EXPECT_EQ(s.fallback, s.variant.empty()) << what;
    fallbacks += s.fallback;
    ++used[s.fallback ? "fallback" : s.variant];
    if (s.fallback) {
      EXPECT_NE(s.fallbackReason.find("no template fits"), std::string::npos) << what << ": " << s.fallbackReason;
    } else {
      EXPECT_GT(s.parcels.size(), 1u) << what;
    }
    const Subdivision again = withTemplate(block, values, seed);
    EXPECT_EQ(again.variant, s.variant) << what;
    ASSERT_EQ(again.parcels.size(), s.parcels.size()) << what;
    for (std::size_t k = 0; k < s.parcels.size(); ++k) {
      EXPECT_TRUE(sameVertices(again.parcels[k], s.parcels[k])) << what << " parcel " << k;
    }
  }
  for (const auto& [name, n] : used) std::printf("%s: %d\n", name.c_str(), n);
  // Regions no template fits are split at concave corners or through holes:
  // combs, stars, L and holed shapes too get templates.
  EXPECT_LE(fallbacks, shapes / 10);
  EXPECT_GT(used["spike"], 0);  // the U shapes
}

// A template of two 20 x 20 squares side by side, the left one rigid.
detail::Template twoSquares(detail::PartClass right) {
  detail::Template t;
  t.name = "test";
  t.vertices = {{0, 0}, {20, 0}, {40, 0}, {40, 20}, {20, 20}, {0, 20}};
  t.boundary = {0, 1, 2, 3, 4, 5};
  t.corners = {1, 0, 1, 1, 0, 1};
  detail::TemplatePart rigid;
  rigid.kind = detail::PartClass::Rigid;
  rigid.ring = {0, 1, 4, 5};
  rigid.tolerance = 0.01;
  detail::TemplatePart other;
  other.kind = right;
  other.ring = {1, 2, 3, 4};
  other.scaleMin = other.scaleMinY = 0.5;
  other.scaleMax = other.scaleMaxY = 2;
  other.tolerance = 0.5;
  t.parts = {rigid, other};
  t.splits = {{1, 4}};
  return t;
}

TEST(TemplateWarp, ARigidPartKeepsItsEdgeLengthsOnASkewedQuadrilateral) {
  // A quadrilateral 50 m long, slightly skewed: arc-length scaling alone
  // would stretch the rigid square to 25 m along the long sides.
  const Ring quad = {{0, 0}, {50, 1}, {51, 21}, {-1, 20}};
  const detail::Template t = twoSquares(detail::PartClass::Affine);
  const detail::Warp init = detail::warpTemplate(t, quad, {0, 1, 2, 3}, 0);
  const detail::Warp w = detail::warpTemplate(t, quad, {0, 1, 2, 3}, 30);
  EXPECT_EQ(w.iterations, 30);
  auto edge = [&](const detail::Warp& x, int a, int b) {
    return norm(x.positions[b].x - x.positions[a].x, x.positions[b].y - x.positions[a].y);
  };
  EXPECT_GT(edge(init, 0, 1), 24);  // initialised at half of each long side
  for (const auto& [a, b] : {std::pair{0, 1}, std::pair{1, 4}, std::pair{4, 5}, std::pair{5, 0}}) {
    EXPECT_NEAR(edge(w, a, b), 20, 0.5) << a << "-" << b;
  }
  EXPECT_LT(w.residual, init.residual);
  // The shared vertices stay on the block's boundary (bottom and top sides).
  EXPECT_NEAR(w.positions[1].y, w.positions[1].x / 50, 1e-9);
  EXPECT_NEAR(w.positions[4].y, 20 + (w.positions[4].x + 1) / 52, 1e-9);
  // The affine part takes the rest: about 30 m along.
  EXPECT_NEAR(edge(w, 1, 2), 30, 1.5);
}

TEST(TemplateWarp, RegistrationStaysWithinEachClass) {
  detail::TemplatePart part;
  const std::vector<Point> from = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  std::vector<Point> to;
  for (const Point& p : from) to.push_back({3 + 2 * p.x, -1 + 2 * p.y});  // twice the size, moved
  part.kind = detail::PartClass::Rigid;
  detail::AffineMap m = detail::registerPart(from, to, part);
  EXPECT_NEAR(m.a11 * m.a22 - m.a12 * m.a21, 1, 1e-12);
  part.kind = detail::PartClass::Similarity;
  part.scaleMin = 0.5;
  part.scaleMax = 1.5;
  m = detail::registerPart(from, to, part);
  EXPECT_NEAR(m.a11, 1.5, 1e-12);  // the scale clamped to its range
  EXPECT_NEAR(m.a21, 0, 1e-12);
  part.scaleMax = 3;
  m = detail::registerPart(from, to, part);
  const Point q = m({10, 10});
  EXPECT_NEAR(q.x, 23, 1e-9);
  EXPECT_NEAR(q.y, 19, 1e-9);
  // Affine: scales along the template's axes, each within its range.
  std::vector<Point> stretched;
  for (const Point& p : from) stretched.push_back({3 * p.x, 0.5 * p.y});
  part.kind = detail::PartClass::Affine;
  part.scaleMin = 0.5;
  part.scaleMax = 2;
  part.scaleMinY = 0.8;
  part.scaleMaxY = 1.25;
  m = detail::registerPart(from, stretched, part);
  EXPECT_NEAR(m.a11, 2, 1e-12);
  EXPECT_NEAR(m.a22, 0.8, 1e-12);
}

TEST(TemplateWarp, MeanValueCoordinatesReproduceLinearFunctions) {
  const std::vector<Point> polygon = {{0, 0}, {40, 0}, {50, 30}, {10, 35}, {-5, 15}};
  const Point x{17, 12};
  const std::vector<double> w = detail::meanValueCoordinates(x, polygon);
  Point back;
  double sum = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    EXPECT_GT(w[i], 0);  // positive inside a convex polygon
    back.x += w[i] * polygon[i].x;
    back.y += w[i] * polygon[i].y;
    sum += w[i];
  }
  EXPECT_NEAR(sum, 1, 1e-12);
  EXPECT_NEAR(back.x, x.x, 1e-9);
  EXPECT_NEAR(back.y, x.y, 1e-9);
}

TEST(TemplateWarp, CornersAreTheSharpTurnsBetweenSides) {
  // A rectangle with extra vertices along its sides and a 20-degree bend.
  const Ring ring = {{0, 0}, {50, 0}, {100, 0}, {150, 18}, {150, 60}, {75, 60}, {0, 60}};
  const std::vector<detail::Corner> corners = detail::cornersOf(ring, 30.0 * kPi / 180.0, 12);
  ASSERT_EQ(corners.size(), 4u);
  for (const detail::Corner& c : corners) EXPECT_EQ(c.type, 1);
  const Ring notch = {{0, 0}, {40, 0}, {40, 30}, {60, 30}, {60, 0}, {100, 0}, {100, 80}, {0, 80}};
  int concave = 0;
  for (const detail::Corner& c : detail::cornersOf(notch, 30.0 * kPi / 180.0, 12)) concave += c.type < 0;
  EXPECT_EQ(concave, 2);
}

}  // namespace
}  // namespace parcelscope::generation
