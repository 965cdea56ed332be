#include "parcelscope/core/Geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "TestUtil.h"

namespace parcelscope {
namespace {

using test::poly;
using test::rect;

TEST(Geometry, AreaAndPerimeterOfRectangleWithHole) {
  Polygon p = rect(0, 0, 20, 10);
  p.holes.push_back({{5, 2}, {5, 4}, {7, 4}, {7, 2}});
  EXPECT_DOUBLE_EQ(area(p), 200.0 - 4.0);
  EXPECT_DOUBLE_EQ(perimeter(p), 60.0 + 8.0);
}

TEST(Geometry, NormaliseOrientsOuterCounterClockwiseAndHolesClockwise) {
  Polygon p = poly({{0, 0}, {0, 10}, {10, 10}, {10, 0}, {0, 0}}, {{{2, 2}, {4, 2}, {4, 4}, {2, 4}}});
  ASSERT_TRUE(normalise(p));
  EXPECT_EQ(p.outer.size(), 4u);  // closing vertex dropped
  EXPECT_GT(signedArea(p.outer), 0);
  EXPECT_LT(signedArea(p.holes[0]), 0);
}

TEST(Geometry, NormaliseRejectsZeroAreaRing) {
  Polygon p = poly({{0, 0}, {5, 0}, {10, 0}});
  EXPECT_FALSE(normalise(p));
}

TEST(Geometry, MinimumAreaBoxOfRotatedRectangle) {
  const double a = 0.3, c = std::cos(a), s = std::sin(a);
  Ring r;
  for (Point p : {Point{0, 0}, Point{40, 0}, Point{40, 10}, Point{0, 10}}) {
    r.push_back({1000 + p.x * c - p.y * s, -500 + p.x * s + p.y * c});
  }
  const OrientedBox box = minimumAreaBox(r);
  EXPECT_NEAR(box.length, 40, 1e-9);
  EXPECT_NEAR(box.width, 10, 1e-9);
  EXPECT_NEAR(std::fabs(box.u.x * c + box.u.y * s), 1.0, 1e-12);  // long axis along the rectangle
  EXPECT_NEAR(box.center.x, 1000 + 20 * c - 5 * s, 1e-9);
}

TEST(Geometry, MinimumAreaBoxIsNoLargerThanAxisAlignedBoxOnRandomPolygons) {
  std::mt19937 rng(7);
  std::printf("seed 7\n");
  std::uniform_real_distribution<double> u(-50, 50);
  for (int k = 0; k < 200; ++k) {
    Ring r;
    for (int i = 0; i < 12; ++i) r.push_back({u(rng), u(rng)});
    const OrientedBox box = minimumAreaBox(r);
    const Box b = bounds(r);
    EXPECT_LE(box.area(), b.width() * b.height() * (1 + 1e-12));
    // Every vertex lies inside the box.
    for (const Point& p : r) {
      const double along = (p.x - box.center.x) * box.u.x + (p.y - box.center.y) * box.u.y;
      const double across = -(p.x - box.center.x) * box.u.y + (p.y - box.center.y) * box.u.x;
      EXPECT_LE(std::fabs(along), 0.5 * box.length + 1e-9);
      EXPECT_LE(std::fabs(across), 0.5 * box.width + 1e-9);
    }
  }
}

// smallestBoxAlongEdges by testing every hull vertex for every edge (the
// method used below HullExtremes::kFastFrom hull vertices), for comparison.
OrientedBox boxByEveryVertex(const Ring& hull, const Ring& edges) {
  OrientedBox best;
  best.center = hull[0];
  const Point o = hull[0];
  double bestArea = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const Point& a = edges[i];
    const Point& b = edges[(i + 1) % edges.size()];
    const double l = norm(b.x - a.x, b.y - a.y);
    if (l == 0) continue;
    const Point e{(b.x - a.x) / l, (b.y - a.y) / l};
    double minE = std::numeric_limits<double>::max(), maxE = std::numeric_limits<double>::lowest();
    double minN = minE, maxN = maxE;
    for (const Point& h : hull) {
      const double dx = h.x - o.x, dy = h.y - o.y;
      const double pe = dx * e.x + dy * e.y, pn = -dx * e.y + dy * e.x;
      minE = std::min(minE, pe);
      maxE = std::max(maxE, pe);
      minN = std::min(minN, pn);
      maxN = std::max(maxN, pn);
    }
    const double w = maxE - minE, h = maxN - minN;
    if (w * h < bestArea * (1 - 1e-9)) {
      bestArea = w * h;
      const double ce = 0.5 * (minE + maxE), cn = 0.5 * (minN + maxN);
      best.center = {o.x + ce * e.x - cn * e.y, o.y + ce * e.y + cn * e.x};
      best.u = w >= h ? e : Point{-e.y, e.x};
      best.length = std::max(w, h);
      best.width = std::min(w, h);
    }
  }
  return best;
}

// Large hulls (ellipses of 600 to 20,000 vertices, jittered, turned, far from
// the origin) take their extremes from the edge angles: the boxes are those of
// testing every vertex, to the bit, for the hull's own edges and for the edges
// of a ring around it.
TEST(Geometry, SmallestBoxOfALargeHullIsThatOfTestingEveryVertex) {
  std::mt19937 rng(11);
  std::printf("seed 11\n");
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 40; ++k) {
    const int n = k < 36 ? 600 + 60 * k : 20000;
    const double a = 50 + 400 * u(rng), b = a * (0.3 + 0.7 * u(rng)), turn = 6.3 * u(rng);
    const double x0 = 1e5 * u(rng), y0 = -1e5 * u(rng);
    Ring ring;
    for (int i = 0; i < n; ++i) {
      const double t = 2 * M_PI * i / n, r = 1 + 1e-7 * u(rng);
      const double x = a * r * std::cos(t), y = b * r * std::sin(t);
      ring.push_back({x0 + x * std::cos(turn) - y * std::sin(turn), y0 + x * std::sin(turn) + y * std::cos(turn)});
    }
    const Ring hull = convexHull(ring);
    ASSERT_GE(hull.size(), 256u) << "case " << k;
    for (const Ring* edges : std::vector<const Ring*>{&hull, &ring}) {
      const OrientedBox fast = smallestBoxAlongEdges(hull, *edges), every = boxByEveryVertex(hull, *edges);
      EXPECT_EQ(fast.length, every.length) << "case " << k;
      EXPECT_EQ(fast.width, every.width) << "case " << k;
      EXPECT_EQ(fast.center.x, every.center.x) << "case " << k;
      EXPECT_EQ(fast.center.y, every.center.y) << "case " << k;
      EXPECT_EQ(fast.u.x, every.u.x) << "case " << k;
      EXPECT_EQ(fast.u.y, every.u.y) << "case " << k;
    }
  }
}

TEST(Geometry, PointInPolygonRespectsHoles) {
  Polygon p = rect(0, 0, 10, 10);
  p.holes.push_back({{4, 4}, {4, 6}, {6, 6}, {6, 4}});
  EXPECT_TRUE(pointInPolygon({1, 1}, p));
  EXPECT_FALSE(pointInPolygon({5, 5}, p));
  EXPECT_FALSE(pointInPolygon({11, 5}, p));
}

TEST(Geometry, InteriorPointOfConcaveShapeIsInside) {
  // A U shape whose centroid falls in the notch.
  Polygon u = poly({{0, 0}, {30, 0}, {30, 30}, {20, 30}, {20, 5}, {10, 5}, {10, 30}, {0, 30}});
  ASSERT_TRUE(normalise(u));
  EXPECT_FALSE(pointInPolygon(centroid(u), u));
  EXPECT_TRUE(pointInPolygon(interiorPoint(u), u));
}

TEST(Geometry, SegmentDistanceIsZeroForCrossingSegments) {
  EXPECT_DOUBLE_EQ(segmentDistance({0, 0}, {10, 10}, {0, 10}, {10, 0}), 0.0);
  EXPECT_DOUBLE_EQ(segmentDistance({0, 0}, {10, 0}, {0, 2}, {10, 2}), 2.0);
  EXPECT_DOUBLE_EQ(segmentDistance({0, 0}, {10, 0}, {13, 4}, {20, 4}), 5.0);  // end to end
}

TEST(Geometry, ConvexHullDropsInteriorAndCollinearPoints) {
  const Ring hull = convexHull({{0, 0}, {5, 0}, {10, 0}, {10, 10}, {0, 10}, {5, 5}});
  EXPECT_EQ(hull.size(), 4u);
  EXPECT_DOUBLE_EQ(signedArea(hull), 100.0);
}

// Melkman's hull of a simple ring against the sorting hull: on rings with
// integer coordinates (exact orientation tests) the very same ring, collinear
// points dropped alike; on real coordinates, the same in all but rounding.
TEST(Geometry, HullOfSimpleRingIsTheSortingHull) {
  std::mt19937_64 rng = test::seededRandom(11, "simple ring hulls");
  std::uniform_real_distribution<double> u(0, 1);
  int compared = 0, sameReal = 0, comparedReal = 0;
  Ring melkman, sorted;
  for (int i = 0; i < 3000; ++i) {
    // A star around the origin: angles in order, random radii; every third
    // integer one with the midpoints of its edges added where they fall on
    // the grid (collinear points, exactly).
    const bool integer = i % 2 == 0;
    const int n = 3 + static_cast<int>(u(rng) * 40);
    const double start = u(rng) * 2 * kPi;
    Ring star;
    for (int k = 0; k < n; ++k) {
      const double angle = start + 2 * kPi * (k + 0.8 * u(rng)) / n, radius = 5 + 95 * u(rng);
      Point p{radius * std::cos(angle), radius * std::sin(angle)};
      if (integer) p = {std::round(p.x), std::round(p.y)};
      star.push_back(p);
    }
    if (integer && i % 3 == 0) {
      Ring withMidpoints;
      for (std::size_t k = 0; k < star.size(); ++k) {
        const Point& a = star[k];
        const Point& b = star[(k + 1) % star.size()];
        withMidpoints.push_back(a);
        if (std::fmod(a.x + b.x, 2) == 0 && std::fmod(a.y + b.y, 2) == 0) {
          withMidpoints.push_back({(a.x + b.x) / 2, (a.y + b.y) / 2});
        }
      }
      star = withMidpoints;
    }
    Polygon p{star, {}};
    if (!normalise(p) || !isClearlySimple(p.outer)) continue;
    convexHullOfSimpleRing(p.outer, melkman);
    convexHullInto(p.outer, sorted);
    const bool same = melkman.size() == sorted.size() &&
                      std::equal(melkman.begin(), melkman.end(), sorted.begin(),
                                 [](const Point& a, const Point& b) { return a.x == b.x && a.y == b.y; });
    if (integer) {
      ++compared;
      EXPECT_TRUE(same) << "ring " << i << " of " << p.outer.size() << " vertices: hulls of " << melkman.size()
                        << " and " << sorted.size();
      if (!same) {
        for (const Point& q : p.outer) std::printf("{%g, %g}, ", q.x, q.y);
        std::printf("\n");
      }
    } else {
      ++comparedReal;
      sameReal += same;
      EXPECT_NEAR(signedArea(melkman), signedArea(sorted), 1e-9 * signedArea(sorted)) << "ring " << i;
      if (std::fabs(signedArea(melkman) - signedArea(sorted)) > 1e-9 * signedArea(sorted)) {
        for (const Point& q : p.outer) std::printf("{%.17g, %.17g}, ", q.x, q.y);
        std::printf("\nmelkman %zu sorted %zu\n", melkman.size(), sorted.size());
      }
    }
  }
  std::printf("%d integer rings compared, %d of %d real ones the same\n", compared, sameReal, comparedReal);
  EXPECT_GT(compared, 1000);
  EXPECT_GT(comparedReal, 1000);
  EXPECT_GE(sameReal, 99 * comparedReal / 100);
}

}  // namespace
}  // namespace parcelscope

namespace parcelscope {
namespace {

TEST(Geometry, ClearlySimpleAcceptsPlainRingsAndDefersDoubtfulOnes) {
  EXPECT_TRUE(isClearlySimple(test::rect(0, 0, 10, 5).outer));
  EXPECT_FALSE(isClearlySimple({{0, 0}, {10, 10}, {10, 0}, {0, 10}}));          // bow-tie
  EXPECT_FALSE(isClearlySimple({{0, 0}, {10, 0}, {10, 10}, {5, 0}, {0, 10}}));  // touches itself
  EXPECT_FALSE(isClearlySimple({{0, 0}, {10, 0}, {5, 0}, {5, 5}}));             // folds back
  // Long rings (checked by a sweep): a circle, then the circle with one
  // vertex moved onto a far edge, and with two vertices swapped (a crossing).
  Ring many;
  for (int i = 0; i < 100; ++i) many.push_back({std::cos(i * 0.0628), std::sin(i * 0.0628)});
  EXPECT_TRUE(isClearlySimple(many));
  Ring touching = many;
  touching[10] = {0.5 * (many[60].x + many[61].x), 0.5 * (many[60].y + many[61].y)};
  EXPECT_FALSE(isClearlySimple(touching));
  Ring crossing = many;
  std::swap(crossing[20], crossing[22]);
  EXPECT_FALSE(isClearlySimple(crossing));
}

// The pairs of edges of a ring (not adjacent along it) that come within eps,
// by brute force: the reference for the sweep over long rings.
bool hasClosePair(const Ring& r, double eps) {
  const std::size_t n = r.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;
      if (segmentDistance(r[i], r[(i + 1) % n], r[j], r[(j + 1) % n]) <= eps) return true;
    }
  }
  return false;
}

TEST(Geometry, ClearlySimpleSweepAgreesWithEveryPairOnLongRandomRings) {
  std::mt19937_64 rng = test::seededRandom(11, "random rings");
  std::uniform_real_distribution<double> u(0, 1);
  int simple = 0, notSimple = 0;
  for (int k = 0; k < 300; ++k) {
    // A star-shaped ring around the origin (simple), with, one time in two,
    // a few vertices moved at random (often making it cross itself).
    const std::size_t n = 65 + static_cast<std::size_t>(u(rng) * 400);
    Ring r;
    for (std::size_t i = 0; i < n; ++i) {
      const double a = 2 * kPi * static_cast<double>(i) / static_cast<double>(n), radius = 50 + 50 * u(rng);
      r.push_back({1000 + radius * std::cos(a), 2000 + radius * std::sin(a)});
    }
    if (k % 2) {
      for (int m = 0; m < 3; ++m)
        r[static_cast<std::size_t>(u(rng) * static_cast<double>(n))] = {1000 + 200 * u(rng) - 100,
                                                                        2000 + 200 * u(rng) - 100};
    }
    const Box b = bounds(r);
    const bool reference = !hasClosePair(r, 1e-9 * std::max(b.width(), b.height()));
    const bool clearly = isClearlySimple(r);
    // The sweep finds every close pair; the other checks (short edges,
    // fold-backs) can only make it more cautious.
    if (!reference) {
      EXPECT_FALSE(clearly) << "ring " << k;
    }
    if (reference && k % 2 == 0) {
      EXPECT_TRUE(clearly) << "ring " << k;
    }
    (clearly ? simple : notSimple) += 1;
  }
  std::printf("%d clearly simple, %d not\n", simple, notSimple);
  EXPECT_GT(simple, 140);
  EXPECT_GT(notSimple, 50);
}

}  // namespace
}  // namespace parcelscope
