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
  EXPECT_EQ(block.outer.size(), 12u);              // where inner edges meet the outline too
  EXPECT_DOUBLE_EQ(block.outer.front().x, 0.0);    // starts at the lowest vertex
  EXPECT_DOUBLE_EQ(block.outer.front().y, 0.0);
}

TEST(DissolveCoverage, TJunctionsNeedTheSnap) {
  // One long lot above two short ones: the vertex (1, 1) lies on the long lot's edge.
  // Without the snap the edges left run back along each other, making no
  // clean outline.
  const std::vector<Polygon> lots = {rect(0, 0, 1, 1), rect(1, 0, 2, 1), rect(0, 1, 2, 2)};
  const auto raw = dissolveCoverage(pointers(lots));
  EXPECT_FALSE(raw && raw->size() == 1 && raw->front().outer.size() == 7 && raw->front().holes.empty());
  const auto outline = dissolveCoverage(pointers(lots), {1e-6});
  ASSERT_TRUE(outline.has_value());
  ASSERT_EQ(outline->size(), 1u);
  EXPECT_DOUBLE_EQ(area(outline->front()), 4.0);
  EXPECT_EQ(outline->front().outer.size(), 7u);
  EXPECT_TRUE(outline->front().holes.empty());
  // A vertex 1 mm off the edge is not on it.
  const std::vector<Polygon> off = {rect(0, 0, 1, 1.001), rect(1, 0, 2, 1), rect(0, 1, 2, 2)};
  EXPECT_FALSE(dissolveCoverage(pointers(off), {1e-6}).has_value());
}

TEST(DissolveCoverage, CourtyardKeepsItsHoleAndSeparatePartsStaySeparate) {
  const std::vector<Polygon> ring = {rect(0, 0, 30, 10), rect(0, 20, 30, 30), rect(0, 10, 10, 20), rect(20, 10, 30, 20),
                                     rect(50, 0, 60, 10)};
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
  // Overlapping without shared edges: the rings are returned as they are,
  // crossing; only a validity check can tell.
  const Polygon c = rect(0.5, 0.5, 1.5, 1.5);
  const auto crossing = dissolveCoverage({&a, &c});
  ASSERT_TRUE(crossing.has_value());
  EXPECT_EQ(crossing->size(), 2u);
}

TEST(DissolveCoverage, RingsTouchingAtAVertexStayApart) {
  // Two lots meeting at one corner: two parts.
  const Polygon a = rect(0, 0, 1, 1), b = rect(1, 1, 2, 2);
  const auto parts = dissolveCoverage({&a, &b});
  ASSERT_TRUE(parts.has_value());
  ASSERT_EQ(parts->size(), 2u);
  EXPECT_EQ((*parts)[0].outer.size(), 4u);
  EXPECT_EQ((*parts)[1].outer.size(), 4u);
  // Lots around a courtyard that touches the outline at (2, 0): one outer
  // ring and one hole, meeting at that vertex.
  const std::vector<Polygon> lots = {
      test::poly({{0, 0}, {2, 0}, {1, 1}, {1, 2}, {0, 2}}), test::poly({{2, 0}, {4, 0}, {4, 2}, {3, 2}, {3, 1}}),
      test::poly({{1, 2}, {1, 1}, {3, 1}, {3, 2}, {3, 3}, {1, 3}}), test::poly({{0, 2}, {1, 2}, {1, 3}, {0, 3}}),
      test::poly({{3, 2}, {4, 2}, {4, 3}, {3, 3}})};
  std::vector<const Polygon*> members;
  for (const Polygon& p : lots) members.push_back(&p);
  const auto block = dissolveCoverage(members);
  ASSERT_TRUE(block.has_value());
  ASSERT_EQ(block->size(), 1u);
  ASSERT_EQ(block->front().holes.size(), 1u);
  EXPECT_EQ(block->front().holes[0].size(), 3u);  // (2, 0), (1, 1), (3, 1)
  EXPECT_EQ(block->front().outer.size(), 9u);     // (2, 0) on the outline too
  EXPECT_NEAR(area(block->front()), 12.0 - 1.0, 1e-12);
}

// Jittered grids: lots share their corners exactly, some cells are left out
// (holes and separate parts). The outline's area is the lots' area, and it
// does not depend on the order of the lots.
TEST(DissolveCoverage, RandomJitteredGrids) {
  const unsigned seed = 290104;  // fixed: a failure replays with the same seed
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  for (int round = 0; round < 50; ++round) {
    std::vector<Polygon> lots =
        test::jitteredGrid(rng, 2 + static_cast<int>(rng() % 6), 2 + static_cast<int>(rng() % 6), 0.85);
    if (lots.empty()) continue;
    const auto outline = dissolveCoverage(pointers(lots));
    ASSERT_TRUE(outline.has_value());  // holes and cells meeting at one corner included
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
