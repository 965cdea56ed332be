// Parcel matching across block edits (Vanegas et al. 2012, section 5.2): the
// relative position and its distance, the contour correspondence, and the
// one-to-one matching on blocks the library's own styles subdivide.
#include "parcelscope/generation/ParcelMatching.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <set>

#include "TestUtil.h"
#include "generation/RandomShapes.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/generation/Styles.h"

namespace parcelscope::generation {
namespace {

using test::poly;
using test::rect;

/// A similarity transform: rotation by `angle` and scaling by `scale` about
/// the origin, then a shift by (dx, dy).
struct Similarity {
  double angle = 0, scale = 1, dx = 0, dy = 0;
  Point operator()(const Point& p) const {
    const double c = std::cos(angle) * scale, s = std::sin(angle) * scale;
    return {dx + p.x * c - p.y * s, dy + p.x * s + p.y * c};
  }
  Polygon operator()(Polygon p) const {
    for (Point& q : p.outer) q = (*this)(q);
    for (Ring& h : p.holes)
      for (Point& q : h) q = (*this)(q);
    return p;
  }
  std::vector<Polygon> operator()(std::vector<Polygon> ps) const {
    for (Polygon& p : ps) p = (*this)(std::move(p));
    return ps;
  }
};

std::vector<int> identity(std::size_t n) {
  std::vector<int> v(n);
  std::iota(v.begin(), v.end(), 0);
  return v;
}

/// The parcels before of which the parcel after covers the most area (-1 when it covers none).
int counterpart(const Polygon& after, const std::vector<Polygon>& before) {
  const Box b = bounds(after);
  int best = -1;
  double most = 0;
  for (std::size_t j = 0; j < before.size(); ++j) {
    if (!bounds(before[j]).intersects(b)) continue;
    const double a = geos::intersectionArea(after, before[j]);
    if (a > most) {
      most = a;
      best = static_cast<int>(j);
    }
  }
  return best;
}

void expectOneToOne(const ParcelMatches& m, std::size_t before) {
  std::set<int> used;
  std::size_t matched = 0;
  for (int j : m.before) {
    if (j < 0) continue;
    ++matched;
    EXPECT_LT(j, static_cast<int>(before));
    EXPECT_TRUE(used.insert(j).second) << "parcel before " << j << " matched twice";
  }
  // Greedy one-to-one leaves unmatched only what the other side cannot supply.
  EXPECT_EQ(matched, std::min(before, m.before.size()));
}

// A non-symmetric block split into a row of 8 frontage lots and a back row.
const Polygon kBlock = poly({{0, 0}, {120, -6}, {135, 55}, {60, 70}, {-8, 48}});

std::vector<Polygon> blockParcels(const Polygon& block, const char* style, std::uint64_t seed) {
  const Subdivision s = subdivideBlock(block, style, {}, seed);
  EXPECT_FALSE(s.failed) << s.failure;
  return s.parcels;
}

TEST(ParcelMatching, RelativePositionIsTheShareOfEachVertexDistance) {
  const Ring square = rect(0, 0, 10, 10).outer;
  for (double l : relativePosition({5, 5}, square)) EXPECT_DOUBLE_EQ(l, 0.25);
  const std::vector<double> corner = relativePosition({0, 0}, square);
  const double sum = 10 + 10 * std::sqrt(2.0) + 10;
  EXPECT_DOUBLE_EQ(corner[0], 0);
  EXPECT_DOUBLE_EQ(corner[1], 10 / sum);
  EXPECT_DOUBLE_EQ(corner[2], 10 * std::sqrt(2.0) / sum);
  EXPECT_DOUBLE_EQ(std::accumulate(corner.begin(), corner.end(), 0.0), 1);
  // Degenerate: every vertex at the point.
  for (double l : relativePosition({1, 1}, {{1, 1}, {1, 1}})) EXPECT_DOUBLE_EQ(l, 0.5);
}

TEST(ParcelMatching, DistanceIsTheL1DistanceOfPositionsWherePapersDenominatorIsZero) {
  const std::vector<double> a{0.5, 0.25, 0.25}, b{0.25, 0.5, 0.25};
  // The printed formula divides by sum_k (a_k - b_k): 0 for any two positions.
  EXPECT_DOUBLE_EQ((a[0] - b[0]) + (a[1] - b[1]) + (a[2] - b[2]), 0);
  EXPECT_DOUBLE_EQ(positionDistance(a, b), 0.5);
  EXPECT_DOUBLE_EQ(positionDistance(b, a), 0.5);
  EXPECT_DOUBLE_EQ(positionDistance(a, a), 0);
  EXPECT_DOUBLE_EQ(positionDistance({1, 0, 0}, {0, 0, 1}), 2);  // the largest
}

TEST(ParcelMatching, RelativePositionIsInvariantToSimilarityTransforms) {
  const Similarity f{2.1, 0.37, -4e5, 3e5};
  const Ring moved = f(kBlock).outer;
  for (const Point& p : {Point{10, 10}, Point{100, 30}, Point{60, 60}, Point{-50, 200}}) {
    const std::vector<double> a = relativePosition(p, kBlock.outer), b = relativePosition(f(p), moved);
    EXPECT_LT(positionDistance(a, b), 1e-9);
  }
}

TEST(ParcelMatching, ContourDropsCollinearAndRepeatedVerticesWhateverItsStartAndOrientation) {
  // A vertex on an edge, a repeated vertex, one 5 mm off a 100 m chord
  // (5e-5 of it: dropped), one 2 cm off (2e-4: kept) and a spike (kept).
  const Ring ring{{0, 0},    {50, 0},    {100, 0},      {100, 0}, {100, 50},  {110, 50},
                  {100, 50}, {100, 100}, {50, 100.005}, {0, 100}, {-0.02, 50}};
  const Ring reduced = matchingContour(ring);
  const Ring expected{{0, 0}, {100, 0}, {100, 50}, {110, 50}, {100, 50}, {100, 100}, {0, 100}, {-0.02, 50}};
  ASSERT_EQ(reduced.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(reduced[i].x, expected[i].x) << i;
    EXPECT_EQ(reduced[i].y, expected[i].y) << i;
  }
  // Another start vertex gives the same cycle; the reversed ring, the same ring turned counter-clockwise.
  for (std::size_t start = 0; start < ring.size(); ++start) {
    Ring shifted = ring;
    std::rotate(shifted.begin(), shifted.begin() + static_cast<std::ptrdiff_t>(start), shifted.end());
    for (bool reverse : {false, true}) {
      if (reverse) std::reverse(shifted.begin(), shifted.end());
      const Ring r = matchingContour(shifted);
      ASSERT_EQ(r.size(), expected.size()) << start;
      const auto at = std::find_if(r.begin(), r.end(), [](const Point& p) { return p.x == 0 && p.y == 0; });
      ASSERT_NE(at, r.end());
      const std::size_t offset = static_cast<std::size_t>(at - r.begin());
      for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(r[(offset + i) % r.size()].x, expected[i].x) << start << " " << reverse << " " << i;
        EXPECT_EQ(r[(offset + i) % r.size()].y, expected[i].y) << start << " " << reverse << " " << i;
      }
    }
  }
}

TEST(ParcelMatching, ContoursCorrespondAcrossStartVertexSimilarityAndAnAddedCorner) {
  const Ring a = matchingContour(kBlock.outer);
  ASSERT_EQ(a.size(), 5u);
  const Similarity f{-2.5, 4.0, 1e6, -2e6};  // rotation by 143 degrees: no help from positions
  for (std::size_t start = 0; start < a.size(); ++start) {
    Ring b = f(kBlock).outer;
    std::rotate(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(start), b.end());
    const auto pairs = correspondContours(a, matchingContour(b));
    ASSERT_EQ(pairs.size(), 5u);
    for (std::size_t i = 0; i < 5; ++i) {
      EXPECT_EQ(pairs[i].first, i);
      EXPECT_EQ(pairs[i].second, (i + a.size() - start) % a.size()) << start;
    }
  }
  // A corner added off the edge between vertices 2 and 3: the other five keep their partners.
  Ring b = kBlock.outer;
  b.insert(b.begin() + 3, Point{100, 68});
  const auto pairs = correspondContours(a, matchingContour(b));
  const std::vector<std::pair<std::size_t, std::size_t>> expected{{0, 0}, {1, 1}, {2, 2}, {3, 4}, {4, 5}};
  EXPECT_EQ(pairs, expected);
  // The same contour clockwise (not through matchingContour): the nearest
  // vertices do not keep their order, so nothing corresponds.
  std::reverse(b.begin(), b.end());
  EXPECT_TRUE(correspondContours(a, b).empty());
  EXPECT_TRUE(correspondContours(a, {{0, 0}, {1, 1}}).empty());
}

TEST(ParcelMatching, SymmetricBlockReadsARotationBySymmetryAsANewStartVertex) {
  // A square's start vertex moved by one is the same input as the square
  // turned by 90 degrees: the correspondence needing no rotation is taken.
  const Ring square = rect(0, 0, 100, 100).outer;
  Ring shifted = square;
  std::rotate(shifted.begin(), shifted.begin() + 1, shifted.end());
  const auto pairs = correspondContours(square, shifted);
  ASSERT_EQ(pairs.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(pairs[i].second, (i + 3) % 4);
}

TEST(ParcelMatching, EveryParcelMatchesItselfUnderSimilarityTransformsStartShiftAndReversal) {
  for (const char* style : {"obb", "skeleton"}) {
    const std::vector<Polygon> parcels = blockParcels(kBlock, style, 5);
    ASSERT_GE(parcels.size(), 8u) << style;
    for (const Similarity& f : {Similarity{0.3, 1, 0, 0}, Similarity{2.9, 1, 0, 0}, Similarity{0, 25, 0, 0},
                                Similarity{0, 0.01, 0, 0}, Similarity{-1.7, 3.3, 5e5, -7e5}}) {
      Polygon block = f(kBlock);
      const ParcelMatches m = matchParcels(kBlock, parcels, block, f(parcels));
      EXPECT_EQ(m.before, identity(parcels.size())) << style << " angle " << f.angle << " scale " << f.scale;
      for (double d : m.distance) EXPECT_LT(d, 1e-9);
      std::rotate(block.outer.begin(), block.outer.begin() + 2, block.outer.end());
      EXPECT_EQ(matchParcels(kBlock, parcels, block, f(parcels)).before, identity(parcels.size())) << style;
      std::reverse(block.outer.begin(), block.outer.end());
      EXPECT_EQ(matchParcels(kBlock, parcels, block, f(parcels)).before, identity(parcels.size())) << style;
    }
  }
}

/// `block` with a vertex inserted on its edge from vertex `edge`, at share `t` of its length.
Polygon withVertexOnEdge(Polygon block, std::size_t edge, double t) {
  const Point a = block.outer[edge], b = block.outer[(edge + 1) % block.outer.size()];
  block.outer.insert(block.outer.begin() + static_cast<std::ptrdiff_t>(edge + 1),
                     Point{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)});
  return block;
}

TEST(ParcelMatching, CollinearVertexInsertedIntoAnEdgeChangesNothing) {
  // A T-junction added, and one moved to another street (the same vertex
  // count before and after, but not the same vertices): positions are taken
  // on the same five corners, so every distance stays exactly 0.
  const std::vector<Polygon> parcels = blockParcels(kBlock, "obb", 3);
  const Polygon tBefore = withVertexOnEdge(kBlock, 1, 0.37), tAfter = withVertexOnEdge(kBlock, 3, 0.6);
  for (const auto& [before, after] : {std::pair{&kBlock, &tBefore}, std::pair{&tBefore, &tAfter}}) {
    const ParcelMatches m = matchParcels(*before, parcels, *after, parcels);
    EXPECT_EQ(m.before, identity(parcels.size()));
    EXPECT_EQ(m.distance, std::vector<double>(parcels.size(), 0.0));
  }
}

TEST(ParcelMatching, OneToOneWithFewerAndMoreParcelsAfter) {
  // A 6 x 2 grid of lots; after the edit lot 4 is split into a 15 m and a
  // 5 m part and lot 9 is gone.
  const Polygon block = rect(0, 0, 120, 40);
  std::vector<Polygon> before;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 6; ++i) before.push_back(rect(20 * i, 20 * j, 20 * i + 20, 20 * j + 20));
  std::vector<Polygon> after = before;
  after[4] = rect(80, 0, 95, 20);
  after.push_back(rect(95, 0, 100, 20));
  after.erase(after.begin() + 9);
  // after: 0..3 = before 0..3, 4 = the wide part of 4, 5..8 = before 5..8,
  // 9..10 = before 10..11, 11 = the narrow part of 4. The wide part is
  // nearer to 4 and takes it; the narrow part takes what is left, lot 9,
  // further away (a caller may refuse such a pair by its distance).
  ParcelMatches m = matchParcels(block, before, block, after);
  expectOneToOne(m, before.size());
  EXPECT_EQ(m.before, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 10, 11, 9}));
  for (std::size_t i : {0, 1, 2, 3, 5, 6, 7, 8, 9, 10}) EXPECT_EQ(m.distance[i], 0) << i;
  EXPECT_GT(m.distance[4], 0);
  EXPECT_GT(m.distance[11], 3 * m.distance[4]);

  // Without the narrow part (fewer parcels after), and the other way round (more parcels after).
  after.pop_back();
  m = matchParcels(block, before, block, after);
  expectOneToOne(m, before.size());
  EXPECT_EQ(m.before, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 10, 11}));
  m = matchParcels(block, after, block, before);
  expectOneToOne(m, after.size());
  EXPECT_EQ(m.before, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, -1, 9, 10}));
  EXPECT_EQ(m.distance[9], -1);
}

TEST(ParcelMatching, TiesGoToTheLowerIndices) {
  const Polygon block = rect(0, 0, 40, 20), lot = rect(0, 0, 20, 20);
  const ParcelMatches m = matchParcels(block, {lot, lot}, block, {lot, lot, lot});
  EXPECT_EQ(m.before, (std::vector<int>{0, 1, -1}));
}

TEST(ParcelMatching, ADegenerateBlockMatchesNothing) {
  const std::vector<Polygon> lots{rect(0, 0, 10, 10), rect(10, 0, 20, 10)};
  const ParcelMatches m = matchParcels(rect(0, 0, 20, 10), lots, poly({{0, 0}, {10, 0}, {20, 0}}), lots);
  EXPECT_EQ(m.before, (std::vector<int>{-1, -1}));
  EXPECT_EQ(m.distance, (std::vector<double>{-1, -1}));
}

// Contours that cannot be put in correspondence (a square, and a triangle
// with two corners by one of the square's: fewer than 3 mutual nearest
// vertices) match parcels by their place relative to the block's centroid,
// in units of the square root of its area.
TEST(ParcelMatching, UncorrespondedContoursMatchByPlaceAroundTheCentroid) {
  const Polygon before = rect(-50, -50, 50, 50);
  Polygon after;
  for (double degrees : {25.0, 65.0, 225.0}) {
    const double a = degrees * M_PI / 180;
    after.outer.push_back({80 * std::cos(a), 80 * std::sin(a)});
  }
  ASSERT_TRUE(correspondContours(matchingContour(before.outer), matchingContour(after.outer)).empty());
  const Point ob = centroid(before), oa = centroid(after);
  const double ub = std::sqrt(area(before)), ua = std::sqrt(area(after));
  std::vector<Polygon> lotsBefore, lotsAfter;
  for (int i = 0; i < 6; ++i) {
    const double x = 0.1 * (i % 3) - 0.1, y = 0.12 * (i / 3) - 0.06;
    lotsBefore.push_back(rect(ob.x + x * ub - 1, ob.y + y * ub - 1, ob.x + x * ub + 1, ob.y + y * ub + 1));
    lotsAfter.push_back(rect(oa.x + x * ua - 1, oa.y + y * ua - 1, oa.x + x * ua + 1, oa.y + y * ua + 1));
  }
  std::reverse(lotsAfter.begin(), lotsAfter.end());
  const ParcelMatches m = matchParcels(before, lotsBefore, after, lotsAfter);
  EXPECT_EQ(m.before, (std::vector<int>{5, 4, 3, 2, 1, 0}));
  for (double d : m.distance) EXPECT_NEAR(d, 0, 1e-9);
}

/// `block` with one corner of its matching contour moved by `distance` in a
/// random direction, still a simple polygon; the block itself when no
/// direction of 20 keeps it simple.
Polygon movedCorner(const Polygon& block, std::mt19937_64& rng, double distance) {
  const Ring corners = matchingContour(block.outer);
  std::uniform_int_distribution<std::size_t> pick(0, corners.size() - 1);
  std::uniform_real_distribution<double> turn(0, 2 * kPi);
  const Point corner = corners[pick(rng)];
  for (int attempt = 0; attempt < 20; ++attempt) {
    const double a = turn(rng);
    Polygon moved = block;
    for (Point& p : moved.outer) {
      if (p.x == corner.x && p.y == corner.y) p = {p.x + distance * std::cos(a), p.y + distance * std::sin(a)};
    }
    if (normalise(moved) && geos::isValid(moved)) return moved;
  }
  return block;
}

TEST(ParcelMatching, CornerMovedBy2mKeepsMostParcelsOnGeneratedBlocks) {
  // Blocks of the property tests (convex, star, L, U, comb), subdivided with
  // obb and skeleton, one corner moved by 2 m and subdivided again with the
  // same seed: the share of parcels after matched to the parcel before they
  // overlap most.
  std::mt19937_64 rng = test::seededRandom(2012, "CornerMoved");
  for (const char* style : {"obb", "skeleton"}) {
    std::size_t parcels = 0, kept = 0, unchanged = 0, unchangedKept = 0;
    for (int shape = 0; shape < 20; ++shape) {
      const Polygon before = test::randomShape(rng, shape % 5);
      const Polygon after = movedCorner(before, rng, 2.0);
      const std::uint64_t seed = rng();
      const std::vector<Polygon> parcelsBefore = blockParcels(before, style, seed);
      const std::vector<Polygon> parcelsAfter = blockParcels(after, style, seed);
      const ParcelMatches m = matchParcels(before, parcelsBefore, after, parcelsAfter);
      expectOneToOne(m, parcelsBefore.size());
      for (std::size_t i = 0; i < parcelsAfter.size(); ++i) {
        const int c = counterpart(parcelsAfter[i], parcelsBefore);
        ++parcels;
        kept += m.before[i] == c;
        // Parcels the edit left (nearly) as they were: 99 % of both areas shared.
        const double shared = c < 0 ? 0 : geos::intersectionArea(parcelsAfter[i], parcelsBefore[c]);
        if (c >= 0 && shared >= 0.99 * std::max(area(parcelsAfter[i]), area(parcelsBefore[c]))) {
          ++unchanged;
          unchangedKept += m.before[i] == c;
        }
      }
    }
    const double share = static_cast<double>(kept) / static_cast<double>(parcels);
    const double unchangedShare = static_cast<double>(unchangedKept) / static_cast<double>(unchanged);
    std::printf("%s: %zu of %zu parcels matched to their counterpart (%.3f); unchanged parcels %zu of %zu (%.3f)\n",
                style, kept, parcels, share, unchangedKept, unchanged, unchangedShare);
    // Measured: obb 0.96, skeleton 0.98 over 50 shapes (0.93 and 0.96 at 5 m,
    // 0.91 and 0.92 at 10 m); the misses are parcels the edit reshaped, whose
    // largest overlap is no clear counterpart. Every unchanged parcel kept.
    EXPECT_GE(share, 0.9) << style;
    EXPECT_GE(unchangedShare, 0.99) << style;
  }
}

TEST(ParcelMatching, RandomBlocksWithFixedParcelsUnderSmallCornerMoves) {
  // Random convex and star-shaped blocks, their parcels (obb) kept as they
  // are while one corner moves by 2 % of the block's size: positions move
  // a little, parcels keep their matches. A similarity transform on top of
  // the move changes nothing more.
  std::mt19937_64 rng = test::seededRandom(52, "RandomBlocks");
  std::uniform_real_distribution<double> u(0, 1);
  std::size_t parcels = 0, kept = 0;
  for (int shape = 0; shape < 16; ++shape) {
    const Polygon before = test::randomShape(rng, shape % 2);
    const std::vector<Polygon> lots = blockParcels(before, "obb", rng());
    const Box b = bounds(before);
    const Polygon after = movedCorner(before, rng, 0.02 * std::max(b.width(), b.height()));
    const ParcelMatches m = matchParcels(before, lots, after, lots);
    expectOneToOne(m, lots.size());
    const Similarity f{2 * kPi * u(rng), 0.1 + 10 * u(rng), 1e5 * u(rng), -1e5 * u(rng)};
    const ParcelMatches moved = matchParcels(before, lots, f(after), f(lots));
    EXPECT_EQ(moved.before, m.before) << shape;
    for (std::size_t i = 0; i < lots.size(); ++i) {
      ++parcels;
      kept += m.before[i] == static_cast<int>(i);
    }
  }
  const double share = static_cast<double>(kept) / static_cast<double>(parcels);
  std::printf("%zu of %zu parcels kept (%.3f)\n", kept, parcels, share);
  // Measured: every parcel kept up to moves of 5 % of the block's size, 0.99
  // at 10 %, 0.94 at 20 %.
  EXPECT_GE(share, 0.98);
}

}  // namespace
}  // namespace parcelscope::generation
