#include "parcelscope/analysis/StreetWidth.h"

#include <gtest/gtest.h>

#include <cmath>

#include "TestUtil.h"

namespace parcelscope::analysis {
namespace {

using test::rect;

TEST(StreetWidth, FacingEdgesMeasureTheGapAndOpenEdgesAreUnknown) {
  // Two blocks 12 m apart across a street running north-south, a third 25 m
  // north of the first.
  const Polygon west = rect(0, 0, 100, 50), east = rect(112, 0, 200, 50), north = rect(0, 75, 100, 120);
  const auto w = streetWidths({&west, &east, &north});
  ASSERT_EQ(w.size(), 3u);
  // Normalised rectangles run (x0,y0) (x1,y0) (x1,y1) (x0,y1): bottom, right, top, left.
  ASSERT_EQ(w[0].size(), 1u);
  ASSERT_EQ(w[0][0].size(), 4u);
  EXPECT_TRUE(std::isnan(w[0][0][0]));  // nothing south
  EXPECT_NEAR(w[0][0][1], 12.0, 1e-9);  // east: the street to `east`
  EXPECT_NEAR(w[0][0][2], 25.0, 1e-9);  // north: the street to `north`
  EXPECT_TRUE(std::isnan(w[0][0][3]));  // nothing west
  EXPECT_NEAR(w[1][0][3], 12.0, 1e-9);  // `east` looks back west
  EXPECT_NEAR(w[2][0][0], 25.0, 1e-9);  // `north` looks back south
  // Beyond the cap nothing counts.
  const auto capped = streetWidths({&west, &north}, 20.0);
  EXPECT_TRUE(std::isnan(capped[0][0][2]));
}

TEST(StreetWidth, HolesLookInward) {
  Polygon ring = rect(0, 0, 100, 100);
  ring.holes.push_back({{20, 20}, {20, 80}, {80, 80}, {80, 20}});
  normalise(ring);
  const Polygon island = rect(30, 30, 70, 70);
  const auto w = streetWidths({&ring, &island});
  ASSERT_EQ(w[0].size(), 2u);
  for (double x : w[0][1]) EXPECT_NEAR(x, 10.0, 1e-9);  // hole edges face the island 10 m away
  for (double x : w[1][0]) EXPECT_NEAR(x, 10.0, 1e-9);
}

}  // namespace
}  // namespace parcelscope::analysis
