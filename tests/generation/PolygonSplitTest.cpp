// The floating-point split of the OBB style against the exact one: where the
// fast path applies, both give the same pieces (up to the rounding of the
// crossing points and the ring's first vertex); where it does not, it says so
// and the exact split is the one used.
#include "PolygonSplit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "Exact.h"
#include "TestUtil.h"
#include "generation/RandomShapes.h"

namespace parcelscope::generation::detail {
namespace {

using test::poly;
using test::rect;

// Same ring up to the first vertex, each vertex within `tolerance`.
bool sameRing(const Ring& a, const Ring& b, double tolerance) {
  if (a.size() != b.size()) return false;
  for (std::size_t shift = 0; shift < a.size(); ++shift) {
    bool same = true;
    for (std::size_t i = 0; same && i < a.size(); ++i) {
      const Point& p = a[i];
      const Point& q = b[(i + shift) % b.size()];
      same = std::fabs(p.x - q.x) <= tolerance && std::fabs(p.y - q.y) <= tolerance;
    }
    if (same) return true;
  }
  return false;
}

// The same elements in any order, matched one to one by `same`.
template <class T, class Same>
bool sameInAnyOrder(const std::vector<T>& a, const std::vector<T>& b, Same same) {
  if (a.size() != b.size()) return false;
  std::vector<char> used(b.size(), 0);
  for (const T& x : a) {
    bool found = false;
    for (std::size_t j = 0; !found && j < b.size(); ++j) {
      found = !used[j] && same(x, b[j]);
      if (found) used[j] = 1;
    }
    if (!found) return false;
  }
  return true;
}

// The same pieces (outer rings and holes) in any order.
bool samePieces(const std::vector<Polygon>& a, const std::vector<Polygon>& b, double tolerance) {
  const auto ring = [&](const Ring& x, const Ring& y) { return sameRing(x, y, tolerance); };
  return sameInAnyOrder(a, b, [&](const Polygon& p, const Polygon& q) {
    return ring(p.outer, q.outer) && sameInAnyOrder(p.holes, q.holes, ring);
  });
}

double sideArea(const std::vector<Polygon>& pieces) {
  double sum = 0;
  for (const Polygon& p : pieces) sum += area(p);
  return sum;
}

// A side the fast split pinched: the same area, and every vertex of its pieces
// is one of the exact split's (which gives the pieces meeting at a pinch as
// one ring touching itself there).
bool sameUpToPinches(const std::vector<Polygon>& fast, const std::vector<Polygon>& exact, double tolerance) {
  if (std::fabs(sideArea(fast) - sideArea(exact)) > 1e-9 * sideArea(exact)) return false;
  for (const Polygon& f : fast) {
    for (const Point& p : f.outer) {
      bool found = false;
      for (const Polygon& e : exact) {
        for (const Point& q : e.outer)
          found = found || (std::fabs(p.x - q.x) <= tolerance && std::fabs(p.y - q.y) <= tolerance);
      }
      if (!found) return false;
    }
  }
  return true;
}

// A ring passing one point twice.
bool touchesItself(const Ring& r) {
  for (std::size_t i = 0; i < r.size(); ++i)
    for (std::size_t j = i + 1; j < r.size(); ++j)
      if (r[i].x == r[j].x && r[i].y == r[j].y) return true;
  return false;
}

double totalArea(const SplitPieces& s) {
  double sum = 0;
  for (const auto* side : {&s.left, &s.right})
    for (const Polygon& p : *side) sum += area(p);
  return sum;
}

// A line across `block` at a random angle; the `i`th, when i is a multiple
// of 3, runs through a vertex of the ring, as snapped lines do.
void randomLine(std::mt19937_64& rng, const Polygon& block, int i, Point& pivot, Point& dir) {
  std::uniform_real_distribution<double> u(0, 1);
  const Box b = bounds(block);
  const double angle = u(rng) * kPi;
  dir = {std::cos(angle), std::sin(angle)};
  std::uniform_int_distribution<std::size_t> vertex(0, block.outer.size() - 1);
  pivot = i % 3 == 0 ? block.outer[vertex(rng)] : Point{b.minX + u(rng) * b.width(), b.minY + u(rng) * b.height()};
}

TEST(PolygonSplit, FastSplitMatchesExactSplitOnRandomShapes) {
  std::mt19937_64 rng = test::seededRandom(5, "random shapes");
  int fast = 0, declined = 0, multiple = 0, pinched = 0, holed = 0;
  for (int i = 0; i < 2000 / test::kSanitizerDivisor; ++i) {
    Polygon block = test::randomShape(rng, i % test::kShapeKinds);
    if (!normalise(block)) continue;
    const Box b = bounds(block);
    Point pivot, dir;
    randomLine(rng, block, i, pivot, dir);
    SplitPieces f;
    if (!splitByLineFast(block, pivot, dir, f)) {
      ++declined;
      continue;
    }
    ++fast;
    const SplitPieces e = splitByLine(block, pivot, dir);
    const std::string what = "shape " + std::to_string(i);
    const double tolerance = 1e-9 * (b.width() + b.height()) + 1e-12 * (std::fabs(b.minX) + std::fabs(b.minY));
    if (f.pinched) {
      // At least one side differs from the exact split by its pinches alone.
      ++pinched;
      const bool left = samePieces(f.left, e.left, tolerance), right = samePieces(f.right, e.right, tolerance);
      EXPECT_FALSE(left && right) << what;
      EXPECT_TRUE(left || sameUpToPinches(f.left, e.left, tolerance)) << what;
      EXPECT_TRUE(right || sameUpToPinches(f.right, e.right, tolerance)) << what;
      bool selfTouching = false;
      for (const auto* side : {&e.left, &e.right})
        for (const Polygon& p : *side) selfTouching = selfTouching || touchesItself(p.outer);
      EXPECT_TRUE(selfTouching) << what;
    } else {
      EXPECT_TRUE(samePieces(f.left, e.left, tolerance)) << what;
      EXPECT_TRUE(samePieces(f.right, e.right, tolerance)) << what;
    }
    EXPECT_NEAR(totalArea(f), area(block), 1e-9 * area(block)) << what;
    // The two sides share their crossing points exactly: two per cut.
    int shared = 0;
    for (const Polygon& l : f.left)
      for (const Polygon& r : f.right)
        for (const Point& p : l.outer)
          for (const Point& q : r.outer) shared += p.x == q.x && p.y == q.y;
    EXPECT_EQ(shared % 2, 0) << what;
    if (!f.left.empty() && !f.right.empty()) {
      EXPECT_GE(shared, 2) << what;
    }
    if (f.left.size() + f.right.size() > 2) ++multiple;
    holed += !block.holes.empty();
  }
  std::printf(
      "%d split in floating point (%d into more than two pieces, %d pinched, %d with holes), %d left to the "
      "exact split\n",
      fast, multiple, pinched, holed, declined);
  EXPECT_GT(multiple, 0);
  EXPECT_GT(pinched, 0);
  EXPECT_GT(holed, 0);
  EXPECT_GT(fast, 1000 / test::kSanitizerDivisor);
  EXPECT_GT(declined, 0);
}

TEST(PolygonSplit, LineThroughVertexSplitsThere) {
  const Polygon square = rect(0, 0, 10, 10);
  SplitPieces s;
  ASSERT_TRUE(splitByLineFast(square, {0, 0}, {std::sqrt(0.5), std::sqrt(0.5)}, s));  // the diagonal
  ASSERT_EQ(s.left.size(), 1u);
  ASSERT_EQ(s.right.size(), 1u);
  EXPECT_EQ(s.left[0].outer.size(), 3u);
  EXPECT_EQ(s.right[0].outer.size(), 3u);
  EXPECT_DOUBLE_EQ(area(s.left[0]), 50);
  EXPECT_DOUBLE_EQ(area(s.right[0]), 50);
}

TEST(PolygonSplit, FourCrossingsGiveThreePieces) {
  // A U cut across both arms: two cuts, the base below and both arm ends above.
  const Polygon u = poly({{0, 0}, {30, 0}, {30, 30}, {20, 30}, {20, 10}, {10, 10}, {10, 30}, {0, 30}});
  SplitPieces s;
  ASSERT_TRUE(splitByLineFast(u, {15, 20}, {1, 0}, s));
  ASSERT_EQ(s.left.size(), 2u);
  ASSERT_EQ(s.right.size(), 1u);
  EXPECT_DOUBLE_EQ(area(s.left[0]) + area(s.left[1]), 200);
  EXPECT_DOUBLE_EQ(area(s.right[0]), 500);
  const SplitPieces e = splitByLine(u, {15, 20}, {1, 0});
  EXPECT_TRUE(samePieces(s.left, e.left, 1e-12));
  EXPECT_TRUE(samePieces(s.right, e.right, 1e-12));
}

TEST(PolygonSplit, TouchAwayFromTheCutsStaysInItsPiece) {
  // The line y = 5 crosses the left arm and touches the spike at (25, 5) from below.
  const Polygon shape = poly({{0, -10}, {30, -10}, {30, 0}, {25, 5}, {20, 0}, {10, 0}, {10, 10}, {0, 10}});
  SplitPieces s;
  ASSERT_TRUE(splitByLineFast(shape, {15, 5}, {1, 0}, s));
  ASSERT_EQ(s.left.size(), 1u);
  ASSERT_EQ(s.right.size(), 1u);
  EXPECT_DOUBLE_EQ(area(s.left[0]), 50);
  EXPECT_DOUBLE_EQ(area(s.right[0]), 375);
  const SplitPieces e = splitByLine(shape, {15, 5}, {1, 0});
  EXPECT_TRUE(samePieces(s.left, e.left, 1e-12));
  EXPECT_TRUE(samePieces(s.right, e.right, 1e-12));
}

TEST(PolygonSplit, TouchOnACutPinchesItsPieceInTwo) {
  // The line y = 5 crosses both sides and touches (5, 5) from above, on the cut:
  // two triangles above, one piece below (with (5, 5) on its cut edge).
  const Polygon notch = poly({{0, 0}, {10, 0}, {10, 10}, {5, 5}, {0, 10}});
  SplitPieces s;
  ASSERT_TRUE(splitByLineFast(notch, {5, 5}, {1, 0}, s));
  EXPECT_TRUE(s.pinched);
  ASSERT_EQ(s.left.size(), 2u);
  ASSERT_EQ(s.right.size(), 1u);
  EXPECT_DOUBLE_EQ(area(s.left[0]), 12.5);
  EXPECT_DOUBLE_EQ(area(s.left[1]), 12.5);
  EXPECT_DOUBLE_EQ(area(s.right[0]), 50);
  EXPECT_EQ(s.right[0].outer.size(), 5u);  // (5, 5) on its cut
  SplitPieces e = splitByLine(notch, {5, 5}, {1, 0});
  ASSERT_EQ(e.left.size(), 1u);
  EXPECT_TRUE(touchesItself(e.left[0].outer));
  EXPECT_TRUE(sameUpToPinches(s.left, e.left, 1e-12));
  EXPECT_TRUE(samePieces(s.right, e.right, 1e-12));
  // Two touches on one cut, one from each side, and the line the other way.
  const Polygon zigzag =
      poly({{0, 0}, {10, 0}, {15, 5}, {20, 0}, {30, 0}, {30, 10}, {25, 10}, {20, 5}, {10, 10}, {0, 10}});
  ASSERT_TRUE(splitByLineFast(zigzag, {0, 5}, {-1, 0}, s));
  EXPECT_TRUE(s.pinched);
  EXPECT_EQ(s.left.size(), 2u);
  EXPECT_EQ(s.right.size(), 2u);
  EXPECT_DOUBLE_EQ(sideArea(s.left), 125);  // below: the line runs towards -x
  EXPECT_DOUBLE_EQ(sideArea(s.right), 112.5);
  e = splitByLine(zigzag, {0, 5}, {-1, 0});
  EXPECT_TRUE(sameUpToPinches(s.left, e.left, 1e-12));
  EXPECT_TRUE(sameUpToPinches(s.right, e.right, 1e-12));
  // Every piece is a simple ring: no point twice.
  for (const auto* side : {&s.left, &s.right})
    for (const Polygon& p : *side) EXPECT_FALSE(touchesItself(p.outer));
}

// Concave shapes (L, U, comb, star) with a few small holes, cut by random
// lines: where the fast split applies, the exact split gives the same pieces,
// holes included, also when a hole's side has several pieces.
TEST(PolygonSplit, FastSplitMatchesExactSplitWithHolesInConcaveShapes) {
  std::mt19937_64 rng = test::seededRandom(11, "holes in concave shapes");
  std::uniform_real_distribution<double> u(0, 1);
  int fast = 0, severalOnAHoleSide = 0;
  for (int i = 0; i < 600 / test::kSanitizerDivisor; ++i) {
    Polygon block = test::randomShape(rng, 1 + i % 4);
    if (!normalise(block)) continue;
    const Box b = bounds(block);
    const double r = 0.03 * std::min(b.width(), b.height());
    for (int tries = 0; tries < 40 && block.holes.size() < 3; ++tries) {
      const Point c{b.minX + u(rng) * b.width(), b.minY + u(rng) * b.height()};
      if (!pointInRing(c, block.outer)) continue;
      bool clear = true;
      for (std::size_t k = 0, n = block.outer.size(); clear && k < n; ++k) {
        clear = pointSegmentDistance(c, block.outer[k], block.outer[(k + 1) % n]) > 3 * r;
      }
      for (const Ring& h : block.holes) clear = clear && std::hypot(h[0].x - c.x, h[0].y - c.y) > 6 * r;
      if (clear)
        block.holes.push_back({{c.x - r, c.y - r}, {c.x - r, c.y + r}, {c.x + r, c.y + r}, {c.x + r, c.y - r}});
    }
    if (block.holes.empty() || !normalise(block)) continue;
    const double angle = u(rng) * kPi;
    const Point dir{std::cos(angle), std::sin(angle)};
    const Point pivot{b.minX + u(rng) * b.width(), b.minY + u(rng) * b.height()};
    SplitPieces f;
    if (!splitByLineFast(block, pivot, dir, f)) continue;
    ++fast;
    const SplitPieces e = splitByLine(block, pivot, dir);
    const std::string what = "shape " + std::to_string(i);
    const double tolerance = 1e-9 * (b.width() + b.height()) + 1e-12 * (std::fabs(b.minX) + std::fabs(b.minY));
    if (f.pinched) continue;  // compared above; holes change nothing there
    EXPECT_TRUE(samePieces(f.left, e.left, tolerance)) << what;
    EXPECT_TRUE(samePieces(f.right, e.right, tolerance)) << what;
    EXPECT_NEAR(totalArea(f), area(block), 1e-9 * area(block)) << what;
    for (const auto* side : {&f.left, &f.right}) {
      bool holes = false;
      for (const Polygon& p : *side) holes = holes || !p.holes.empty();
      severalOnAHoleSide += holes && side->size() > 1;
    }
  }
  std::printf("%d split in floating point, %d with several pieces on a side holding a hole\n", fast,
              severalOnAHoleSide);
  EXPECT_GT(fast, 200 / test::kSanitizerDivisor);
  EXPECT_GT(severalOnAHoleSide, 10 / test::kSanitizerDivisor);
}

// Holes the line misses go to the piece on their side that holds them, also
// when that side has more than one piece.
TEST(PolygonSplit, HolesOffTheLineGoToThePieceHoldingThem) {
  SplitPieces s;
  Polygon courtyard = rect(0, 0, 30, 30);
  courtyard.holes.push_back({{10, 10}, {10, 20}, {20, 20}, {20, 10}});
  normalise(courtyard);
  ASSERT_TRUE(splitByLineFast(courtyard, {0, 25}, {1, 0}, s));  // the line above the hole
  ASSERT_EQ(s.left.size(), 1u);
  ASSERT_EQ(s.right.size(), 1u);
  EXPECT_TRUE(s.left[0].holes.empty());
  ASSERT_EQ(s.right[0].holes.size(), 1u);
  EXPECT_LT(signedArea(s.right[0].holes[0]), 0);  // clockwise, as normalise leaves holes
  EXPECT_DOUBLE_EQ(area(s.left[0]) + area(s.right[0]), area(courtyard));
  // A U with a hole in its right arm, cut across both arms: two pieces above
  // the line (right of it, heading -x), the hole in the right arm's.
  Polygon u = poly({{0, 0}, {30, 0}, {30, 30}, {20, 30}, {20, 10}, {10, 10}, {10, 30}, {0, 30}});
  u.holes.push_back({{23, 22}, {23, 26}, {27, 26}, {27, 22}});
  normalise(u);
  ASSERT_TRUE(splitByLineFast(u, {15, 15}, {-1, 0}, s));
  ASSERT_EQ(s.left.size(), 1u);
  ASSERT_EQ(s.right.size(), 2u);
  std::size_t withHole = 0;
  for (const Polygon& p : s.right) {
    if (p.holes.empty()) continue;
    ++withHole;
    EXPECT_GT(bounds(p).minX, 15);
  }
  EXPECT_EQ(withHole, 1u);
  const SplitPieces e = splitByLine(u, {15, 15}, {-1, 0});
  EXPECT_TRUE(samePieces(s.left, e.left, 1e-9));
  EXPECT_TRUE(samePieces(s.right, e.right, 1e-9));
}

// The validity check of a block with holes (GEOS's validity and rings that
// share no point, else CGAL's) agrees with CGAL's own on holes apart, touching
// the outer ring or each other at a vertex or along an edge, crossing,
// nested, outside, and on random squares in random shapes.
TEST(PolygonSplit, ValidityWithHolesAgreesWithTheExactCheck) {
  const auto square = [](double x, double y, double s) { return Ring{{x, y}, {x, y + s}, {x + s, y + s}, {x + s, y}}; };
  const auto agrees = [](Polygon p, const std::string& what) {
    normalise(p);
    const bool exact = isValidExact(toExact(p));
    EXPECT_EQ(isValidForSplit(p), exact) << what;
    return exact;
  };
  Polygon apart = rect(0, 0, 100, 100);
  for (int i = 0; i < 4; ++i) apart.holes.push_back(square(10 + 20 * i, 10, 5));
  EXPECT_TRUE(agrees(apart, "holes apart"));
  Polygon touchOuter = rect(0, 0, 100, 100);
  touchOuter.holes.push_back({{0, 50}, {10, 60}, {10, 40}});
  agrees(touchOuter, "a hole touching the outer ring at a vertex");
  Polygon touchEachOther = rect(0, 0, 100, 100);
  touchEachOther.holes = {square(10, 10, 10), square(20, 20, 10)};
  agrees(touchEachOther, "holes touching at a vertex");
  Polygon sharedEdge = rect(0, 0, 100, 100);
  sharedEdge.holes = {square(10, 10, 10), square(20, 10, 10)};
  EXPECT_FALSE(agrees(sharedEdge, "holes sharing an edge"));
  Polygon crossing = rect(0, 0, 100, 100);
  crossing.holes = {square(90, 40, 20)};
  EXPECT_FALSE(agrees(crossing, "a hole crossing the outer ring"));
  Polygon outside = rect(0, 0, 100, 100);
  outside.holes = {square(200, 40, 20)};
  EXPECT_FALSE(agrees(outside, "a hole outside"));
  Polygon nested = rect(0, 0, 100, 100);
  nested.holes = {square(10, 10, 50), square(20, 20, 10)};
  EXPECT_FALSE(agrees(nested, "a hole inside another"));
  Polygon overlapping = rect(0, 0, 100, 100);
  overlapping.holes = {square(10, 10, 20), square(20, 20, 20)};
  EXPECT_FALSE(agrees(overlapping, "overlapping holes"));

  std::mt19937_64 rng = test::seededRandom(12, "validity with holes");
  std::uniform_real_distribution<double> u(0, 1);
  int valid = 0, invalid = 0;
  for (int i = 0; i < 300 / test::kSanitizerDivisor; ++i) {
    Polygon block = test::randomShape(rng, i % 4);
    if (!normalise(block)) continue;
    const Box b = bounds(block);
    const double side = (0.02 + 0.1 * u(rng)) * std::min(b.width(), b.height());
    // Squares on a coarse grid: some apart, some touching or overlapping, some
    // across the outer ring or outside it.
    const int count = 1 + static_cast<int>(u(rng) * 6);
    for (int k = 0; k < count; ++k) {
      const double x = b.minX + std::floor(u(rng) * 8) / 8 * b.width();
      const double y = b.minY + std::floor(u(rng) * 8) / 8 * b.height();
      block.holes.push_back(square(x, y, side));
    }
    (agrees(block, "random shape " + std::to_string(i)) ? valid : invalid)++;
  }
  std::printf("%d valid, %d invalid\n", valid, invalid);
  EXPECT_GT(valid, 20 / test::kSanitizerDivisor);
  EXPECT_GT(invalid, 20 / test::kSanitizerDivisor);
}

TEST(PolygonSplit, FastSplitDeclinesWhatOnlyTheExactSplitHandles) {
  SplitPieces s;
  // A hole.
  Polygon courtyard = rect(0, 0, 30, 30);
  courtyard.holes.push_back({{10, 10}, {10, 20}, {20, 20}, {20, 10}});
  normalise(courtyard);
  EXPECT_FALSE(splitByLineFast(courtyard, {15, 15}, {1, 0}, s));
  // A hole touching the line.
  EXPECT_FALSE(splitByLineFast(courtyard, {15, 10}, {1, 0}, s));
  // A U cut across both arms through its inner corners: vertices on the line
  // that are not crossings.
  const Polygon u = poly({{0, 0}, {30, 0}, {30, 30}, {20, 30}, {20, 10}, {10, 10}, {10, 30}, {0, 30}});
  EXPECT_FALSE(splitByLineFast(u, {15, 10}, {1, 0}, s));
  // A line along an edge.
  EXPECT_FALSE(splitByLineFast(rect(0, 0, 10, 10), {5, 0}, {1, 0}, s));
  // A touch too near a crossing to order them along the line.
  EXPECT_FALSE(splitByLineFast(poly({{0, 0}, {10, 0}, {10, 10}, {1e-12, 5}, {0, 10}}), {0, 5}, {1, 0}, s));
  const Polygon kite = poly({{0, 0}, {10, -5}, {20, 0}, {10, 5}});
  // A line missing the polygon leaves it whole on one side.
  ASSERT_TRUE(splitByLineFast(kite, {0, 10}, {1, 0}, s));
  EXPECT_TRUE(s.left.empty());
  EXPECT_EQ(s.right.size(), 1u);
}

// splitPieceIsSimple, which lets the OBB subdivision skip the whole-ring
// simplicity test of most pieces: on pieces of random strictly simple shapes
// it proves most of them, and every one it proves is simple by the exact test.
TEST(PolygonSplit, PiecesOfSimpleRingsAreProvenSimpleFromTheirNewEdges) {
  std::mt19937_64 rng = test::seededRandom(7, "pieces proven simple");
  int pieces = 0, proven = 0;
  for (int i = 0; i < 2000 / test::kSanitizerDivisor; ++i) {
    Polygon block = test::randomShape(rng, i % test::kShapeKinds);
    if (!normalise(block) || !block.holes.empty() || !isStrictlySimple(block.outer)) continue;
    Point pivot, dir;
    randomLine(rng, block, i, pivot, dir);
    SplitPieces f;
    if (!splitByLineFast(block, pivot, dir, f)) continue;
    for (const auto* side : {&f.left, &f.right}) {
      for (const Polygon& piece : *side) {
        ++pieces;
        if (!splitPieceIsSimple(piece.outer, bounds(piece.outer), pivot, dir)) continue;
        ++proven;
        EXPECT_TRUE(isStrictlySimple(piece.outer)) << "shape " << i;
      }
    }
  }
  std::printf("%d of %d pieces proven simple from their new edges\n", proven, pieces);
  EXPECT_GT(pieces, 1000 / test::kSanitizerDivisor);
  EXPECT_GE(proven, 9 * pieces / 10);
}

TEST(PolygonSplit, PieceEdgesCrossingOrNearlyTouchingAreNotProvenSimple) {
  const Point through{0, 0}, along{1, 0};  // the line y = 0
  const auto proven = [&](const Ring& r, bool cutsClear = false) {
    return splitPieceIsSimple(r, bounds(r), through, along, cutsClear);
  };
  // An edge from the line's vertex (0, 0) crosses another edge; it is
  // checked even when the edges along the line are known clear.
  EXPECT_FALSE(proven({{0, 0}, {4, 4}, {4, 1}, {-1, 3}}));
  EXPECT_FALSE(proven({{0, 0}, {4, 4}, {4, 1}, {-1, 3}}, true));
  // A V whose tip comes within 1e-13 of the edge leaving the line, and the
  // same V kept clear of it.
  EXPECT_FALSE(proven({{0, 0}, {10, 1}, {10, 3}, {5, 0.5 + 1e-13}, {0, 3}}));
  EXPECT_FALSE(proven({{0, 0}, {10, 1}, {10, 3}, {5, 0.5 + 1e-13}, {0, 3}}, true));
  EXPECT_TRUE(proven({{0, 0}, {10, 1}, {10, 3}, {5, 1.5}, {0, 3}}));
  // An edge along the line that another edge crosses: found unless the
  // caller vouches for the edges along the line.
  const Ring crossedCut{{0, 0}, {10, 0}, {10, 5}, {4, -1}, {2, 5}};
  EXPECT_FALSE(proven(crossedCut));
  EXPECT_TRUE(proven(crossedCut, true));
  // An edge folding back along the one before it at a vertex on the line.
  EXPECT_FALSE(proven({{0, 0}, {10, 0}, {5, 0}, {5, 5}}));
}

// The floating-point union of the skeleton style's pieces: shared edges
// cancel, T-junctions are split, and what it cannot certify it declines.
TEST(PolygonSplit, FastJoinDissolvesSharedEdgesAndTJunctions) {
  const Ring a{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, b{{1, 0}, {2, 0}, {2, 1}, {1, 1}};
  std::vector<Ring> out;
  ASSERT_TRUE(joinRingsFast({&a, &b}, 1e-9, out));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_DOUBLE_EQ(signedArea(out[0]), 2.0);
  EXPECT_EQ(out[0].size(), 6u);  // the shared edge's ends stay as (collinear) vertices
  // T-junctions: a 1 by 2 rectangle beside two unit squares, and a crossing
  // point rounded off the edge by less than the tolerance.
  const Ring tall{{0, 0}, {1, 0}, {1, 2}, {0, 2}}, low{{1, 0}, {2, 0}, {2, 1.0000000000001}, {1, 1.0000000000001}},
      high{{1, 1.0000000000001}, {2, 1.0000000000001}, {2, 2}, {1, 2}};
  ASSERT_TRUE(joinRingsFast({&tall, &low, &high}, 1e-9, out));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(signedArea(out[0]), 4.0, 1e-12);
  // Separate parts: two rings.
  const Ring far{{5, 0}, {6, 0}, {6, 1}, {5, 1}};
  ASSERT_TRUE(joinRingsFast({&a, &far}, 1e-9, out));
  EXPECT_EQ(out.size(), 2u);
}

TEST(PolygonSplit, FastJoinDeclinesHolesPinchesAndOverlaps) {
  std::vector<Ring> out{{{9, 9}, {10, 9}, {10, 10}}};
  const std::vector<Ring> before = out;
  // Four parts around a hole.
  const Ring s{{0, 0}, {3, 0}, {3, 1}, {0, 1}}, e{{2, 1}, {3, 1}, {3, 3}, {2, 3}}, n{{0, 2}, {2, 2}, {2, 3}, {0, 3}},
      w{{0, 1}, {1, 1}, {1, 2}, {0, 2}};
  EXPECT_FALSE(joinRingsFast({&s, &e, &n, &w}, 1e-9, out));
  // Two squares touching at a corner.
  const Ring a{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, c{{1, 1}, {2, 1}, {2, 2}, {1, 2}};
  EXPECT_FALSE(joinRingsFast({&a, &c}, 1e-9, out));
  // Overlapping parts: a repeated edge, or the area of the rings not the parts'.
  EXPECT_FALSE(joinRingsFast({&a, &a}, 1e-9, out));
  const Ring shifted{{0.5, 0}, {1.5, 0}, {1.5, 1}, {0.5, 1}};
  EXPECT_FALSE(joinRingsFast({&a, &shifted}, 1e-9, out));
  // A clockwise part.
  const Ring clockwise{{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  EXPECT_FALSE(joinRingsFast({&clockwise}, 1e-9, out));
  ASSERT_EQ(out.size(), before.size());  // untouched
  EXPECT_TRUE(sameRing(out[0], before[0], 0));
}

}  // namespace
}  // namespace parcelscope::generation::detail
