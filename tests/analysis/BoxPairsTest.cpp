// Candidate pairs and frontage lengths take a short path for small inputs
// (one block) and CGAL's box intersection for large ones; both must find the
// same pairs and lengths.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "BoxPairs.h"
#include "Contacts.h"
#include "TestUtil.h"

using namespace parcelscope;

namespace {
// Boxes on a coarse integer grid, so that many only touch along a side or a corner.
std::vector<Box> randomBoxes(std::mt19937_64& rng, std::size_t n, int extent) {
  std::uniform_int_distribution<int> at(0, extent), size(0, 4);
  std::vector<Box> boxes(n);
  for (Box& b : boxes) {
    const double x = at(rng), y = at(rng);
    b = {x, y, x + size(rng), y + size(rng)};
  }
  return boxes;
}
}  // namespace

TEST(BoxPairs, EveryMeetingPairOnceSortedAtEverySize) {
  auto rng = test::seededRandom(20261121, "BoxPairs");
  // Up to one block every pair is tested, then CGAL searches one slab of the
  // plane per core (from 20,000 boxes).
  for (std::size_t n : {0, 1, 2, 7, 64, 128, 129, 300, 2000, 30000}) {
    const std::vector<Box> boxes = randomBoxes(rng, n, static_cast<int>(std::sqrt(double(n)) * 3) + 1);
    // Expected: boxes in order of minX, each against those starting before it ends.
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return boxes[a].minX < boxes[b].minX; });
    std::vector<std::pair<int, int>> expected;
    for (std::size_t k = 0; k < n; ++k) {
      const Box& a = boxes[order[k]];
      for (std::size_t l = k + 1; l < n && boxes[order[l]].minX <= a.maxX; ++l) {
        if (a.intersects(boxes[order[l]])) {
          expected.emplace_back(int(std::min(order[k], order[l])), int(std::max(order[k], order[l])));
        }
      }
    }
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(analysis::detail::intersectingPairs(boxes), expected) << n << " boxes";
    if (n >= 64) {
      EXPECT_GT(expected.size(), n / 4) << "the boxes should crowd";
    }
  }
}

TEST(LengthAlong, SameLengthsWhetherEveryEdgePairIsTestedOrCgalScans) {
  std::mt19937 rng(7);
  // Lots of a 3 x 3 grid with jittered corners, along the grid's outer square.
  const std::vector<Polygon> lots = test::jitteredGrid(rng, 3, 3, 1.0);
  const Ring square = {{0, 0}, {30, 0}, {30, 30}, {0, 30}};
  std::vector<const Polygon*> one;
  for (const Polygon& p : lots) one.push_back(&p);
  const std::vector<double> alone = analysis::detail::lengthAlong(one, {square}, 0.5);
  ASSERT_EQ(alone.size(), lots.size());
  int fronting = 0;
  for (double f : alone) fronting += f > 1.0;
  EXPECT_EQ(fronting, 8) << "every lot but the middle one fronts the square";
  EXPECT_EQ(alone[4], 0.0);

  // 30 copies 100 m apart: too many edge pairs to test every one.
  constexpr int kCopies = 30;
  std::vector<Polygon> copies;
  std::vector<Ring> squares;
  for (int c = 0; c < kCopies; ++c) {
    for (Polygon p : lots) {
      for (Point& q : p.outer) q.x += 100.0 * c;
      copies.push_back(p);
    }
    Ring r = square;
    for (Point& q : r) q.x += 100.0 * c;
    squares.push_back(r);
  }
  std::vector<const Polygon*> all;
  for (const Polygon& p : copies) all.push_back(&p);
  const std::vector<double> together = analysis::detail::lengthAlong(all, squares, 0.5);
  ASSERT_EQ(together.size(), copies.size());
  for (std::size_t i = 0; i < copies.size(); ++i) {
    EXPECT_NEAR(together[i], alone[i % lots.size()], 1e-9) << "lot " << i;
  }
}

namespace {
// lengthAlong as its definition reads: every polygon edge against every ring
// edge whose box meets its own (both grown by half the tolerance), covered
// intervals united per polygon edge, edges summed in ring order.
std::vector<double> lengthAlongEveryPair(const std::vector<const Polygon*>& polygons, const std::vector<Ring>& rings,
                                         double tolerance) {
  const double g = 0.5 * tolerance;
  auto edges = [](const Polygon& p) {
    std::vector<std::pair<Point, Point>> out;
    auto ring = [&](const Ring& r) {
      for (std::size_t i = 0; i < r.size(); ++i) out.emplace_back(r[i], r[(i + 1) % r.size()]);
    };
    ring(p.outer);
    for (const Ring& h : p.holes) ring(h);
    return out;
  };
  std::vector<std::pair<Point, Point>> along;
  for (const Ring& r : rings) {
    const auto e = edges(Polygon{r, {}});
    along.insert(along.end(), e.begin(), e.end());
  }
  std::vector<double> out;
  for (const Polygon* p : polygons) {
    double total = 0;
    for (const auto& [a, b] : edges(*p)) {
      std::vector<std::pair<double, double>> intervals;
      for (const auto& [c, d] : along) {
        if (std::min(a.x, b.x) - g > std::max(c.x, d.x) + g || std::min(c.x, d.x) - g > std::max(a.x, b.x) + g ||
            std::min(a.y, b.y) - g > std::max(c.y, d.y) + g || std::min(c.y, d.y) - g > std::max(a.y, b.y) + g) {
          continue;
        }
        double lo = 0, hi = 0;
        if (analysis::detail::coveredInterval(a, b, c, d, tolerance, lo, hi)) intervals.emplace_back(lo, hi);
      }
      if (!intervals.empty()) total += analysis::detail::unionLength(intervals);
    }
    out.push_back(total);
  }
  return out;
}
}  // namespace

// Jittered lots along noisy outlines (their vertices off the lots' edges by
// up to the tolerance and beyond, some edges reversed), small enough for the
// short path and large enough for CGAL's: the lengths are those of the
// definition, to the last bit.
TEST(LengthAlong, EqualsTheEdgeByEdgeDefinitionOnRandomLotsAndOutlines) {
  auto rng64 = test::seededRandom(20261122, "LengthAlong");
  std::mt19937 rng(static_cast<std::uint32_t>(rng64()));
  std::uniform_int_distribution<int> cells(1, 30);
  std::uniform_real_distribution<double> off(-0.08, 0.08), unit(0.0, 1.0);
  int fronting = 0, inside = 0;
  for (int round = 0; round < 40; ++round) {
    const int nx = cells(rng), ny = round % 4 == 0 ? 1 : cells(rng);
    std::vector<Polygon> lots = test::jitteredGrid(rng, nx, ny, 0.9);
    if (!lots.empty() && round % 3 == 0) {
      // A lot with a hole, whose ring the outline does not follow.
      Polygon& p = lots.front();
      const Point c = centroid(p);
      p.holes.push_back({{c.x - 1, c.y - 1}, {c.x - 1, c.y + 1}, {c.x + 1, c.y + 1}, {c.x + 1, c.y - 1}});
    }
    // The grid's outer square, walked with several vertices per cell side.
    Ring outline;
    auto walk = [&](Point from, Point to, int steps) {
      for (int k = 0; k < steps; ++k) {
        const double t = static_cast<double>(k) / steps;
        outline.push_back({from.x + t * (to.x - from.x) + off(rng), from.y + t * (to.y - from.y) + off(rng)});
      }
    };
    const double w = 10.0 * nx, h = 10.0 * ny;
    walk({0, 0}, {w, 0}, 3 * nx);
    walk({w, 0}, {w, h}, 3 * ny);
    walk({w, h}, {0, h}, 3 * nx);
    walk({0, h}, {0, 0}, 3 * ny);
    std::vector<Ring> rings{outline};
    if (unit(rng) < 0.5) rings.push_back({{w / 2, h / 2}, {w / 2 + 5, h / 2 + 0.01}, {w / 2 + 5, h / 2 + 4}});
    std::vector<const Polygon*> all;
    for (const Polygon& p : lots) all.push_back(&p);
    for (const double tolerance : {0.05, 0.3, 1.0}) {
      const std::vector<double> got = analysis::detail::lengthAlong(all, rings, tolerance);
      const std::vector<double> expected = lengthAlongEveryPair(all, rings, tolerance);
      ASSERT_EQ(got.size(), expected.size());
      for (std::size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i], expected[i]) << "round " << round << ", lot " << i << " of " << got.size() << ", tolerance "
                                       << tolerance;
        fronting += got[i] > 5.0;
        inside += got[i] == 0.0;
      }
    }
  }
  EXPECT_GT(fronting, 500) << "lots along the outline should front it";
  EXPECT_GT(inside, 500) << "lots inside should not";
}

// Lots of many vertices along outlines of many vertices (a street-network
// parcel, a curved block): each lot edge takes its candidates from an index
// of the outline's edges; the lengths are still those of the definition.
TEST(LengthAlong, LotsOfManyVerticesAlongLongOutlinesEqualTheDefinition) {
  auto rng64 = test::seededRandom(20261127, "LengthAlongLarge");
  std::mt19937 rng(static_cast<std::uint32_t>(rng64()));
  std::uniform_real_distribution<double> off(-0.08, 0.08);
  std::uniform_int_distribution<int> steps(30, 120);
  // A side from `from` to `to` walked in `n` jittered steps (its end left out).
  auto walk = [&](Ring& ring, Point from, Point to, int n) {
    for (int k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) / n;
      ring.push_back({from.x + t * (to.x - from.x) + off(rng), from.y + t * (to.y - from.y) + off(rng)});
    }
  };
  int fronting = 0;
  for (int round = 0; round < 12; ++round) {
    // Three lots side by side, 40 m x 60 m, each side walked in many steps.
    std::vector<Polygon> lots(3);
    for (int i = 0; i < 3; ++i) {
      const double x = 40.0 * i;
      Ring& r = lots[static_cast<std::size_t>(i)].outer;
      walk(r, {x, 0}, {x + 40, 0}, steps(rng));
      walk(r, {x + 40, 0}, {x + 40, 60}, steps(rng));
      walk(r, {x + 40, 60}, {x, 60}, steps(rng));
      walk(r, {x, 60}, {x, 0}, steps(rng));
    }
    Ring outline;
    walk(outline, {0, 0}, {120, 0}, 3 * steps(rng));
    walk(outline, {120, 0}, {120, 60}, steps(rng));
    walk(outline, {120, 60}, {0, 60}, 3 * steps(rng));
    walk(outline, {0, 60}, {0, 0}, steps(rng));
    std::vector<const Polygon*> all;
    for (const Polygon& p : lots) all.push_back(&p);
    for (const double tolerance : {0.05, 0.3, 1.0}) {
      const std::vector<double> got = analysis::detail::lengthAlong(all, {outline}, tolerance);
      const std::vector<double> expected = lengthAlongEveryPair(all, {outline}, tolerance);
      ASSERT_EQ(got.size(), expected.size());
      for (std::size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i], expected[i]) << "round " << round << ", lot " << i << ", tolerance " << tolerance;
        fronting += got[i] > 50.0;
      }
    }
  }
  EXPECT_GT(fronting, 50) << "every lot fronts the outline on two sides or more";
}

// Neighbours are counted from contacts measured only until one edge pair
// covers the threshold: the decision must be the one the whole length gives.
TEST(Contacts, StoppingAtEnoughDecidesAsTheWholeLength) {
  auto rng = test::seededRandom(20261122, "Contacts");
  std::uniform_real_distribution<double> width(0.3, 6.0), shift(-2.0, 2.0), split(0.1, 0.9);
  // Rows of lots of random widths, each row shifted, so that lots of
  // neighbouring rows share anything from nothing to several metres; every
  // lot's long sides are split at a random point, so that a shared stretch of
  // more than 1 m may be made of edge pairs of less than 1 m each.
  std::vector<Polygon> lots;
  for (int row = 0; row < 12; ++row) {
    double x = shift(rng);
    const double y = 3.0 * row;
    for (int k = 0; k < 12; ++k) {
      const double w = width(rng);
      const double sb = x + split(rng) * w, st = x + split(rng) * w;
      lots.push_back(Polygon{{{x, y}, {sb, y}, {x + w, y}, {x + w, y + 3.0}, {st, y + 3.0}, {x, y + 3.0}}, {}});
      x += w;
    }
  }
  std::vector<const Polygon*> all;
  for (const Polygon& p : lots) all.push_back(&p);
  const auto whole = analysis::detail::contacts(all, 0.05, 0.05);
  const auto stopped = analysis::detail::contacts(all, 0.05, 0.05, 1.0);
  ASSERT_EQ(whole.size(), stopped.size());
  int shortContacts = 0, longContacts = 0;
  for (std::size_t k = 0; k < whole.size(); ++k) {
    ASSERT_EQ(whole[k].a, stopped[k].a);
    ASSERT_EQ(whole[k].b, stopped[k].b);
    EXPECT_EQ(whole[k].shared >= 1.0, stopped[k].shared >= 1.0) << whole[k].a << "-" << whole[k].b;
    if (stopped[k].shared < 1.0) {
      EXPECT_EQ(stopped[k].shared, whole[k].shared);
    }
    (whole[k].shared >= 1.0 ? longContacts : shortContacts) += 1;
  }
  // Both kinds occur.
  EXPECT_GT(shortContacts, 20);
  EXPECT_GT(longContacts, 100);
}
