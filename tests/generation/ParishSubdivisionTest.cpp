// The parish style (Parish & Muller 2001): lots split across their longest
// pair of parallel edges until under A_max, lots without street access kept
// as unassigned land, the whole still tiling the block.
#include <gtest/gtest.h>

#include <random>

#include "RandomShapes.h"
#include "StreetFrontage.h"
#include "TestUtil.h"
#include "TilingCheck.h"
#include "parcelscope/generation/Styles.h"

namespace parcelscope::generation {
namespace {

Subdivision parish(const Polygon& block, double aMax, std::uint64_t seed = 1, double minFrontage = 1.0) {
  return parishStyle().subdivide({block, {{"a-max", aMax}, {"min-frontage", minFrontage}}, seed, {}});
}

// The assigned parcels (all but the trailing unassigned ones).
std::vector<Polygon> assignedOf(const Subdivision& s) {
  return {s.parcels.begin(), s.parcels.end() - s.unassignedParcels};
}
std::vector<Polygon> unassignedOf(const Subdivision& s) {
  return {s.parcels.end() - s.unassignedParcels, s.parcels.end()};
}

TEST(Parish, SplitsAcrossTheLongestPairOfParallelEdges) {
  // 120 x 60 with A_max just over half: one cut, across the long sides, at their middle.
  const Subdivision s = parish(test::rect(0, 0, 120, 60), 3700);
  ASSERT_EQ(s.parcels.size(), 2u);
  EXPECT_EQ(s.unassignedParcels, 0);
  for (const Polygon& p : s.parcels) {
    const Box b = bounds(p);
    EXPECT_NEAR(b.width(), 60, 1e-9);
    EXPECT_NEAR(b.height(), 60, 1e-9);
  }
  // A_max over the block: left whole.
  EXPECT_EQ(parish(test::rect(0, 0, 120, 60), 8000).parcels.size(), 1u);
}

TEST(Parish, LotsBelowTheThresholdAndInteriorLotsUnassigned) {
  // A deep block: 4 x 4 lots of 50 m, the 4 inner ones without street access.
  const Polygon block = test::rect(0, 0, 200, 200);
  const Subdivision s = parish(block, 2600);
  EXPECT_TILES(block, s.parcels, "200 m square");
  ASSERT_EQ(s.parcels.size(), 16u);
  EXPECT_EQ(s.unassignedParcels, 4);
  EXPECT_EQ(s.withoutAccess, 0);
  EXPECT_EQ(s.oversize, 0);
  for (const Polygon& p : s.parcels) EXPECT_NEAR(area(p), 2500, 1e-6);
  EXPECT_EQ(test::measuredWithoutAccess(block, assignedOf(s), 1.0), 0);
  EXPECT_EQ(test::measuredWithoutAccess(block, unassignedOf(s), 1.0), 4);
  EXPECT_EQ(test::geosWithoutAccess(block, unassignedOf(s), 1.0), 4);
}

TEST(Parish, TrianglesAndBlocksWithHolesAreSplitToo) {
  const Polygon triangle{{{0, 0}, {100, 0}, {0, 80}}, {}};
  const Subdivision t = parish(triangle, 500);
  EXPECT_TILES(triangle, t.parcels, "triangle");
  EXPECT_GT(t.parcels.size(), 4u);
  EXPECT_FALSE(t.failed || t.fallback) << t.failure << t.fallbackReason;
  Polygon courtyard = test::rect(0, 0, 100, 100);
  courtyard.holes.push_back({{40, 40}, {40, 60}, {60, 60}, {60, 40}});
  const Subdivision c = parish(courtyard, 700);
  EXPECT_TILES(courtyard, c.parcels, "courtyard");
  EXPECT_FALSE(c.failed || c.fallback) << c.failure << c.fallbackReason;
  for (const Polygon& p : assignedOf(c)) EXPECT_LE(area(p), 700 * (1 + 1e-9));
}

// Random shapes (convex, concave, with holes, rotated far from the origin):
// a tiling, valid, reproducible; lots above A_max only where no split was
// admissible (counted); the unassigned lots are exactly those without access.
TEST(Parish, RandomShapesTileWithAccessDecidedAsMeasured) {
  std::mt19937_64 rng(20261127);
  int shapes = 0, unassigned = 0, parcels = 0;
  for (int i = 0; i < 140 / test::kSanitizerDivisor; ++i, ++shapes) {
    const Polygon block = test::randomShape(rng, i % test::kShapeKinds);
    const ObbParameters b = test::randomBounds(rng, area(block));
    const std::uint64_t seed = rng();
    const Subdivision s = parish(block, b.aMax, seed, b.minFrontage);
    const std::string what = "shape " + std::to_string(i) + " kind " + std::to_string(i % test::kShapeKinds);
    ASSERT_FALSE(s.failed) << what << ": " << s.failure;
    EXPECT_FALSE(s.fallback) << what << ": " << s.fallbackReason;
    EXPECT_TILES(block, s.parcels, what);
    int above = 0;
    for (const Polygon& p : s.parcels) above += area(p) > b.aMax * (1 + 1e-9);
    EXPECT_EQ(above, s.oversize) << what;
    EXPECT_EQ(test::measuredWithoutAccess(block, assignedOf(s), b.minFrontage), 0) << what;
    EXPECT_EQ(test::measuredWithoutAccess(block, unassignedOf(s), b.minFrontage), s.unassignedParcels) << what;
    const Subdivision again = parish(block, b.aMax, seed, b.minFrontage);
    ASSERT_EQ(again.parcels.size(), s.parcels.size()) << what;
    for (std::size_t k = 0; k < s.parcels.size(); ++k) {
      EXPECT_TRUE(sameVertices(again.parcels[k], s.parcels[k])) << what << " parcel " << k;
    }
    unassigned += s.unassignedParcels;
    parcels += static_cast<int>(s.parcels.size());
  }
  std::printf("%d random shapes: %d parcels, %d unassigned\n", shapes, parcels, unassigned);
  EXPECT_GT(unassigned, 0);
}

}  // namespace
}  // namespace parcelscope::generation
