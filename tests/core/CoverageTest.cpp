#include "parcelscope/core/Coverage.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "TestUtil.h"

namespace parcelscope {
namespace {

using test::rect;

std::vector<const Polygon*> pointers(const std::vector<Polygon>& polygons) {
  std::vector<const Polygon*> out;
  for (const Polygon& p : polygons) out.push_back(&p);
  return out;
}

double totalArea(const std::vector<Polygon>& polygons) {
  double a = 0;
  for (const Polygon& p : polygons) a += area(p);
  return a;
}

TEST(DissolveCoverage, GridOfLotsBecomesItsOutline) {
  std::vector<Polygon> lots;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) lots.push_back(rect(i, j, i + 1, j + 1));
  const auto outline = dissolveCoverage(pointers(lots));
  ASSERT_TRUE(outline.has_value());
  ASSERT_EQ(outline->size(), 1u);
  const Polygon& block = outline->front();
  EXPECT_TRUE(block.holes.empty());
  EXPECT_DOUBLE_EQ(signedArea(block.outer), 9.0);  // counter-clockwise
  EXPECT_EQ(block.outer.size(), 12u);             // where inner edges meet the outline too
  EXPECT_DOUBLE_EQ(block.outer.front().x, 0.0);   // starts at the lowest vertex
  EXPECT_DOUBLE_EQ(block.outer.front().y, 0.0);
}

TEST(DissolveCoverage, TJunctionsNeedTheSnap) {
  // One long lot above two short ones: the vertex (1, 1) lies on the long lot's edge.
  const std::vector<Polygon> lots = {rect(0, 0, 1, 1), rect(1, 0, 2, 1), rect(0, 1, 2, 2)};
  EXPECT_FALSE(dissolveCoverage(pointers(lots)).has_value());
  const auto outline = dissolveCoverage(pointers(lots), {1e-6});
  ASSERT_TRUE(outline.has_value());
  ASSERT_EQ(outline->size(), 1u);
  EXPECT_DOUBLE_EQ(area(outline->front()), 4.0);
  EXPECT_TRUE(outline->front().holes.empty());
  // A vertex 1 mm off the edge is not on it.
  const std::vector<Polygon> off = {rect(0, 0, 1, 1.001), rect(1, 0, 2, 1), rect(0, 1, 2, 2)};
  EXPECT_FALSE(dissolveCoverage(pointers(off), {1e-6}).has_value());
}

TEST(DissolveCoverage, CourtyardKeepsItsHoleAndSeparatePartsStaySeparate) {
  const std::vector<Polygon> ring = {rect(0, 0, 30, 10), rect(0, 20, 30, 30), rect(0, 10, 10, 20),
                                     rect(20, 10, 30, 20), rect(50, 0, 60, 10)};
  const auto outline = dissolveCoverage(pointers(ring), {1e-6});
  ASSERT_TRUE(outline.has_value());
  ASSERT_EQ(outline->size(), 2u);
  EXPECT_EQ((*outline)[0].holes.size(), 1u);
  EXPECT_DOUBLE_EQ(area((*outline)[0]), 800.0);
  EXPECT_LT(signedArea((*outline)[0].holes[0]), 0.0);  // clockwise
  EXPECT_DOUBLE_EQ(area((*outline)[1]), 100.0);
}

TEST(DissolveCoverage, RefusesWhatIsNotACleanCoverage) {
  const Polygon a = rect(0, 0, 1, 1);
  // The same lot twice: its edges occur twice in one direction.
  EXPECT_FALSE(dissolveCoverage({&a, &a}).has_value());
  // Lots touching at one corner: two edges left start at (1, 1).
  const Polygon b = rect(1, 1, 2, 2);
  EXPECT_FALSE(dissolveCoverage({&a, &b}).has_value());
}

// Jittered grids: lots share their corners exactly, some cells are left out
// (holes and separate parts). The outline's area is the lots' area, and it
// does not depend on the order of the lots.
TEST(DissolveCoverage, RandomJitteredGrids) {
  const unsigned seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  for (int round = 0; round < 50; ++round) {
    std::vector<Polygon> lots =
        test::jitteredGrid(rng, 2 + static_cast<int>(rng() % 6), 2 + static_cast<int>(rng() % 6), 0.85);
    if (lots.empty()) continue;
    const auto outline = dissolveCoverage(pointers(lots));
    if (!outline) continue;  // cells meeting at one corner only: refused, checked above
    EXPECT_NEAR(totalArea(*outline), totalArea(lots), 1e-9 * totalArea(lots));
    std::shuffle(lots.begin(), lots.end(), rng);
    const auto again = dissolveCoverage(pointers(lots));
    ASSERT_TRUE(again.has_value());
    ASSERT_EQ(again->size(), outline->size());
    for (std::size_t k = 0; k < outline->size(); ++k) {
      ASSERT_EQ((*again)[k].outer.size(), (*outline)[k].outer.size());
      for (std::size_t v = 0; v < (*outline)[k].outer.size(); ++v) {
        EXPECT_EQ((*again)[k].outer[v].x, (*outline)[k].outer[v].x);
        EXPECT_EQ((*again)[k].outer[v].y, (*outline)[k].outer[v].y);
      }
      EXPECT_EQ((*again)[k].holes.size(), (*outline)[k].holes.size());
    }
  }
}

}  // namespace
}  // namespace parcelscope
