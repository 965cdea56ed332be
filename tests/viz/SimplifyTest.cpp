// Simplification of map shapes for coarse scales (viz/src/Simplify.h): random
// partitions whose neighbours share long noisy boundaries, run in opposite
// directions, a hole filled by another shape, lots split across leaving edges
// to one neighbour only; and real parcels block by block.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "Simplify.h"
#include "TestUtil.h"
#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/Geometry.h"
#include "parcelscope/io/ParcelReader.h"

namespace {

using parcelscope::Point;
using parcelscope::Polygon;
using parcelscope::Ring;
using parcelscope::viz::detail::simplifyShared;

using Key = std::pair<double, double>;
Key key(const Point& p) { return {p.x, p.y}; }

double segmentDistance(const Point& p, const Point& a, const Point& b) {
  const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
  const double t = l2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(a.x + t * dx - p.x, a.y + t * dy - p.y);
}

double ringDistance(const Point& p, const Ring& r) {
  double d = 1e300;
  for (std::size_t i = 0; i < r.size(); ++i) d = std::min(d, segmentDistance(p, r[i], r[(i + 1) % r.size()]));
  return d;
}

// A jittered nx by ny grid over 100 x 100 m: each cell one shape, every edge
// between grid points carrying `inner` noisy points shared (as the same
// coordinates) by the two cells beside it, which run it in opposite
// directions. Some cells are split in two by a straight line whose pieces
// leave the noisy points of the bottom and top edges to the neighbours there
// (runs held by one ring only); the middle cell gets a hole, filled by one
// more shape.
std::vector<Polygon> randomPartition(std::mt19937& rng, int nx, int ny, int inner, double noise) {
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), wobble(-noise, noise), coin(0, 1);
  const double cx = 100.0 / nx, cy = 100.0 / ny;
  std::vector<std::vector<Point>> grid(static_cast<std::size_t>(nx + 1),
                                       std::vector<Point>(static_cast<std::size_t>(ny + 1)));
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      const bool border = i == 0 || j == 0 || i == nx || j == ny;
      grid[i][j] = {cx * (i + (border ? 0 : jitter(rng))), cy * (j + (border ? 0 : jitter(rng)))};
    }
  }
  // The points strictly inside the edge from grid point a to b, in that order.
  std::map<std::pair<Key, Key>, std::vector<Point>> edges;
  const auto edge = [&](const Point& a, const Point& b) -> std::vector<Point> {
    if (const auto it = edges.find({key(b), key(a)}); it != edges.end()) {
      return {it->second.rbegin(), it->second.rend()};
    }
    std::vector<Point> pts;
    const double nxv = -(b.y - a.y), nyv = b.x - a.x, len = std::hypot(nxv, nyv);
    const double bend = wobble(rng) * 4;  // a gentle arc, as streets and lot lines have
    for (int k = 1; k <= inner; ++k) {
      const double t = static_cast<double>(k) / (inner + 1);
      const double off = (bend * std::sin(M_PI * t) + wobble(rng)) / len;
      pts.push_back({a.x + t * (b.x - a.x) + off * nxv, a.y + t * (b.y - a.y) + off * nyv});
    }
    edges[{key(a), key(b)}] = pts;
    return pts;
  };
  std::vector<Polygon> shapes;
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      const Point corners[4] = {grid[i][j], grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]};
      Polygon cell;
      for (int c = 0; c < 4; ++c) {
        cell.outer.push_back(corners[c]);
        for (const Point& p : edge(corners[c], corners[(c + 1) % 4])) cell.outer.push_back(p);
      }
      if (i == nx / 2 && j == ny / 2) {
        Ring hole;
        const Point m{0.5 * (corners[0].x + corners[2].x), 0.5 * (corners[0].y + corners[2].y)};
        for (int k = 0; k < 12; ++k) {
          const double a = -2 * M_PI * k / 12;  // clockwise
          hole.push_back({m.x + 0.15 * cx * std::cos(a) + wobble(rng), m.y + 0.15 * cy * std::sin(a) + wobble(rng)});
        }
        Polygon filling;
        filling.outer.assign(hole.rbegin(), hole.rend());
        cell.holes.push_back(hole);
        shapes.push_back(filling);
        shapes.push_back(cell);
      } else if (coin(rng) < 0.3) {
        // Split across between points inside the bottom and top edges (the
        // pieces leave those edges' noisy points to the neighbours).
        const std::size_t quarter = cell.outer.size() / 4;  // corners at 0, q, 2q, 3q
        const Point bottom{0.5 * (corners[0].x + corners[1].x), 0.5 * (corners[0].y + corners[1].y) + 0.5};
        const Point top{0.5 * (corners[2].x + corners[3].x), 0.5 * (corners[2].y + corners[3].y) - 0.5};
        Polygon left, right;
        left.outer = {corners[0], bottom, top};
        for (std::size_t k = 3 * quarter; k < cell.outer.size(); ++k) left.outer.push_back(cell.outer[k]);
        right.outer = {bottom};
        for (std::size_t k = quarter; k <= 2 * quarter; ++k) right.outer.push_back(cell.outer[k]);
        right.outer.push_back(top);
        shapes.push_back(left);
        shapes.push_back(right);
      } else {
        shapes.push_back(cell);
      }
    }
  }
  return shapes;
}

bool same(const Ring& a, const Ring& b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](const Point& p, const Point& q) { return key(p) == key(q); });
}

std::vector<const Polygon*> pointers(const std::vector<Polygon>& shapes) {
  std::vector<const Polygon*> out;
  for (const Polygon& s : shapes) out.push_back(&s);
  return out;
}

std::size_t vertexCount(const std::vector<Polygon>& shapes) {
  std::size_t n = 0;
  for (const Polygon& s : shapes) {
    n += s.outer.size();
    for (const Ring& h : s.holes) n += h.size();
  }
  return n;
}

// Every vertex held by drawn rings is kept by all of them or by none (so
// neighbours keep their shared boundary), every drawn ring keeps at least three
// of its vertices in their order, and every vertex lies within the tolerance
// of its drawn ring.
void expectSharedAndClose(const std::vector<Polygon>& shapes, const std::vector<Polygon>& simple, double tolerance) {
  ASSERT_EQ(simple.size(), shapes.size());
  std::map<Key, std::pair<int, int>> heldKept;  // rings holding it, rings keeping it
  int far = 0;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    if (simple[k].outer.empty()) continue;
    const auto ring = [&](const Ring& original, const Ring& drawn) {
      ASSERT_GE(drawn.size(), 3u);
      std::set<Key> kept;
      for (const Point& p : drawn) kept.insert(key(p));
      for (const Point& p : original) {
        auto& [held, keeps] = heldKept[key(p)];
        ++held;
        keeps += kept.count(key(p)) ? 1 : 0;
        if (ringDistance(p, drawn) > tolerance * (1 + 1e-9) && far++ < 5) {
          ADD_FAILURE() << "vertex " << p.x << ", " << p.y << " of shape " << k << " lies " << ringDistance(p, drawn)
                        << " from its drawn ring";
        }
      }
      std::size_t at = 0;
      for (const Point& p : drawn) {
        while (at < original.size() && key(original[at]) != key(p)) ++at;
        ASSERT_LT(at, original.size()) << "drawn vertices out of the original order";
      }
    };
    ring(shapes[k].outer, simple[k].outer);
    // (A hole simplified away is left out; then the holes are not matched.)
    if (simple[k].holes.size() == shapes[k].holes.size()) {
      for (std::size_t h = 0; h < shapes[k].holes.size(); ++h) ring(shapes[k].holes[h], simple[k].holes[h]);
    }
  }
  int split = 0;
  for (const auto& [p, hk] : heldKept) {
    if (hk.second != 0 && hk.second != hk.first && split++ < 5) {
      ADD_FAILURE() << "vertex " << p.first << ", " << p.second << " held by " << hk.first << " rings, kept by "
                    << hk.second;
    }
  }
  EXPECT_EQ(far, 0);
  EXPECT_EQ(split, 0);
}

}  // namespace

TEST(SimplifyShared, NeighboursKeepTheSameVerticesAndStayWithinTheTolerance) {
  std::mt19937 rng(20261122);
  for (int trial = 0; trial < 40; ++trial) {
    SCOPED_TRACE(trial);
    std::uniform_int_distribution<int> cells(2, 6), inner(0, 12);
    const double noise = trial % 2 ? 0.05 : 0.6;
    const std::vector<Polygon> shapes = randomPartition(rng, cells(rng), cells(rng), inner(rng), noise);
    for (double tolerance : {0.1, 0.5, 2.0}) {
      SCOPED_TRACE(tolerance);
      std::vector<Polygon> simple;
      simplifyShared(pointers(shapes), tolerance, simple);
      expectSharedAndClose(shapes, simple, tolerance);
    }
  }
}

TEST(SimplifyShared, DropsNoisyVerticesAtCoarseScalesAndCopiesAtZero) {
  std::mt19937 rng(7);
  const std::vector<Polygon> shapes = randomPartition(rng, 5, 5, 10, 0.05);
  std::vector<Polygon> copy, coarse;
  simplifyShared(pointers(shapes), 0.0, copy);
  ASSERT_EQ(copy.size(), shapes.size());
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    EXPECT_TRUE(same(copy[k].outer, shapes[k].outer));
    ASSERT_EQ(copy[k].holes.size(), shapes[k].holes.size());
    for (std::size_t h = 0; h < shapes[k].holes.size(); ++h) EXPECT_TRUE(same(copy[k].holes[h], shapes[k].holes[h]));
  }
  // The arcs bend by up to 0.2 m: at 1 m every edge's inner points go.
  simplifyShared(pointers(shapes), 1.0, coarse);
  EXPECT_LT(vertexCount(coarse), vertexCount(shapes) / 3);
  // The output's memory is reused: a second run over it gives the same.
  std::vector<Polygon> again = coarse;
  simplifyShared(pointers(shapes), 1.0, again);
  for (std::size_t k = 0; k < shapes.size(); ++k) EXPECT_TRUE(same(again[k].outer, coarse[k].outer));
}

TEST(SimplifyShared, ARingSharedWholeKeepsTheSameAnchorsOnBothSides) {
  // A noisy circle as a hole and as the shape filling it (opposite directions).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> wobble(-0.01, 0.01);
  Ring circle;
  for (int k = 0; k < 64; ++k) {
    const double a = 2 * M_PI * k / 64;
    circle.push_back({10 * std::cos(a) + wobble(rng), 10 * std::sin(a) + wobble(rng)});
  }
  Polygon filling{circle, {}};
  Polygon around{{{-20, -20}, {20, -20}, {20, 20}, {-20, 20}}, {Ring(circle.rbegin(), circle.rend())}};
  std::vector<Polygon> out;
  simplifyShared({&filling, &around}, 0.5, out);
  ASSERT_EQ(out.size(), 2u);
  ASSERT_EQ(out[1].holes.size(), 1u);
  std::set<Key> a, b;
  for (const Point& p : out[0].outer) a.insert(key(p));
  for (const Point& p : out[1].holes[0]) b.insert(key(p));
  EXPECT_EQ(a, b);
  EXPECT_LT(a.size(), 64u);
  EXPECT_GE(a.size(), 8u);  // 0.5 m from a circle of 10 m needs 8 or more sides
  EXPECT_EQ(out[1].outer.size(), 4u);
}

TEST(SimplifyShared, RealParcelsByBlockAtTheScalesOfTheApplication) {
  PARCELSCOPE_REQUIRE_SHARED_DATASETS();
  // cambridge_ma's parcels (topology: neighbours share their vertices), each
  // block's on its own as the map layer draws them.
  parcelscope::io::ReadOptions read;
  read.path = parcelscope::test::sharedDataset("cambridge_ma/ASSESSING_ParcelsFY2014.topojson");
  read.where = "ML <> 'ROAD'";
  const parcelscope::io::ParcelLayer layer = parcelscope::io::readParcels(read);
  const parcelscope::analysis::ObservedAnalysis a = parcelscope::analysis::analyseParcels(layer.parcels, {});
  std::map<int, std::vector<Polygon>> blocks;
  for (std::size_t i = 0; i < layer.parcels.size(); ++i) {
    if (a.blockOf[i] >= 0) blocks[a.blockOf[i]].push_back(layer.parcels[i].shape);
  }
  ASSERT_GT(blocks.size(), 500u);
  for (double tolerance : {0.5, 4.0}) {
    SCOPED_TRACE(tolerance);
    std::size_t before = 0, after = 0;
    for (const auto& [id, shapes] : blocks) {
      SCOPED_TRACE(id);
      std::vector<Polygon> simple;
      simplifyShared(pointers(shapes), tolerance, simple);
      expectSharedAndClose(shapes, simple, tolerance);
      before += vertexCount(shapes);
      after += vertexCount(simple);
      if (HasFailure()) return;
    }
    // At the whole city's scale (about 9 m per pixel, 4 m tolerance) most
    // vertices go.
    EXPECT_LT(after, before);
    if (tolerance == 4.0) {
      EXPECT_LT(after, before * 6 / 10);
    }
    std::printf("tolerance %.1f m: %zu of %zu vertices drawn\n", tolerance, after, before);
  }
}
