// Ear clipping of map shapes (viz/src/EarClip.h): random simple rings of every
// size it takes, both orientations, with collinear and reflex vertices, and the
// parcels of two shared real datasets are covered by their triangles exactly
// once, checked at sample points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include "EarClip.h"
#include "parcelscope/io/ParcelReader.h"

namespace parcelscope::viz::detail {
namespace {

double cross(const Point& a, const Point& b, const Point& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

bool inTriangle(const Point& a, const Point& b, const Point& c, const Point& p) {
  const double d1 = cross(a, b, p), d2 = cross(b, c, p), d3 = cross(c, a, p);
  return (d1 > 0 && d2 > 0 && d3 > 0) || (d1 < 0 && d2 < 0 && d3 < 0);
}

// A star-shaped ring: sorted random angles, random radii (many reflex vertices).
Ring star(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), radius(0.2, 1.0);
  std::vector<double> angles(static_cast<std::size_t>(n));
  for (double& a : angles) a = angle(rng);
  std::sort(angles.begin(), angles.end());
  Ring ring;
  for (double a : angles) {
    const double r = radius(rng);
    ring.push_back({r * std::cos(a), r * std::sin(a)});
  }
  return ring;
}

// A staircase: an orthogonal ring with reflex corners and, on its long
// edges, collinear vertices.
Ring staircase(std::mt19937& rng, int steps) {
  std::uniform_int_distribution<int> rise(1, 3);
  Ring ring{{0, 0}};
  double x = 0, y = 0;
  for (int s = 0; s < steps; ++s) {
    y += rise(rng);
    ring.push_back({x, y});
    x += 1;
    ring.push_back({x, y});
  }
  for (double down = x; down > 0; --down) ring.push_back({down, -1});  // collinear along the bottom
  ring.push_back({0, -1});
  return ring;
}

void expectExactCover(const Ring& ring, std::mt19937& rng) {
  std::vector<int> t{7, 7, 7};  // earlier content is kept
  ASSERT_TRUE(earClip(ring, t)) << ring.size() << " vertices";
  ASSERT_EQ(t.size(), 3 + 3 * (ring.size() - 2));
  const double area = signedArea(ring);
  double sum = 0;
  for (std::size_t i = 3; i < t.size(); i += 3) {
    const double a = cross(ring[static_cast<std::size_t>(t[i])], ring[static_cast<std::size_t>(t[i + 1])],
                           ring[static_cast<std::size_t>(t[i + 2])]) /
                     2;
    EXPECT_GE(a * (area > 0 ? 1 : -1), -1e-12) << "triangle turning against the ring";
    sum += std::abs(a);
  }
  EXPECT_NEAR(sum, std::abs(area), 1e-9 * std::abs(area));
  double minX = 1e300, minY = 1e300, maxX = -1e300, maxY = -1e300;
  for (const Point& p : ring) {
    minX = std::min(minX, p.x), minY = std::min(minY, p.y), maxX = std::max(maxX, p.x), maxY = std::max(maxY, p.y);
  }
  std::uniform_real_distribution<double> x(minX, maxX), y(minY, maxY);
  for (int s = 0; s < 400; ++s) {
    const Point p{x(rng), y(rng)};
    int covering = 0;
    for (std::size_t i = 3; i < t.size(); i += 3) {
      covering += inTriangle(ring[static_cast<std::size_t>(t[i])], ring[static_cast<std::size_t>(t[i + 1])],
                             ring[static_cast<std::size_t>(t[i + 2])], p);
    }
    ASSERT_EQ(covering, pointInRing(p, ring) ? 1 : 0)
        << "at (" << p.x << ", " << p.y << "), " << ring.size() << " vertices";
  }
}

TEST(EarClip, RandomSimpleRingsAreCoveredExactlyOnceInBothOrientations) {
  std::mt19937 rng(20261121);
  for (int round = 0; round < 300; ++round) {
    const int n = 3 + static_cast<int>(rng() % (kEarClipMaxVertices - 2));
    Ring ring = round % 2 ? star(rng, n) : staircase(rng, std::max(1, n / 3));
    if (ring.size() > kEarClipMaxVertices) continue;
    expectExactCover(ring, rng);
    std::reverse(ring.begin(), ring.end());
    expectExactCover(ring, rng);
  }
}

// Every parcel ring (without holes, up to kEarClipMaxVertices) of cambridge_ma
// (curved lots) and Paris 18e (cadastre, many vertices) is clipped; every
// 25th is also checked point by point.
TEST(EarClip, RealParcelRingsAreCoveredExactlyOnce) {
  const std::string root = PARCELSCOPE_SHARED_DATASETS;
  std::mt19937 rng(1);
  int datasets = 0;
  for (const char* file :
       {"cambridge_ma/ASSESSING_ParcelsFY2014.topojson", "paris_18e/cadastre-75118-parcelles.json"}) {
    io::ReadOptions in;
    in.path = root + "/" + file;
    if (!std::ifstream(in.path)) continue;
    ++datasets;
    const io::ParcelLayer layer = io::readParcels(in);
    std::size_t clipped = 0;
    for (const Parcel& p : layer.parcels) {
      if (!p.shape.holes.empty() || p.shape.outer.size() > kEarClipMaxVertices) continue;
      if (++clipped % 25 == 0) {
        expectExactCover(p.shape.outer, rng);
        continue;
      }
      const Ring& ring = p.shape.outer;
      const auto at = [&](int v) { return ring[static_cast<std::size_t>(v)]; };
      std::vector<int> t;
      ASSERT_TRUE(earClip(ring, t)) << file << ": parcel of source feature " << p.sourceFid;
      const double ringArea = signedArea(ring);
      double sum = 0;
      for (std::size_t i = 0; i < t.size(); i += 3) {
        const double a = cross(at(t[i]), at(t[i + 1]), at(t[i + 2])) / 2;
        ASSERT_GE(a * (ringArea > 0 ? 1 : -1), -1e-9) << file << ": parcel of source feature " << p.sourceFid;
        sum += std::abs(a);
      }
      ASSERT_NEAR(sum, std::abs(ringArea), 1e-9 * std::abs(ringArea))
          << file << ": parcel of source feature " << p.sourceFid;
    }
    EXPECT_GT(clipped, 5000u) << file;  // 6,800 to 13,000 rings each
  }
  if (datasets == 0) GTEST_SKIP() << "shared datasets not found under " << root;
}

TEST(EarClip, RefusesWhatItCannotClipAndLeavesTheOutputAlone) {
  std::vector<int> t{1, 2, 3};
  EXPECT_FALSE(earClip({{0, 0}, {1, 0}}, t));                  // too few vertices
  EXPECT_FALSE(earClip({{0, 0}, {1, 0}, {2, 0}, {3, 0}}, t));  // no area
  EXPECT_FALSE(earClip({{0, 0}, {1, 1}, {1, 0}, {0, 1}}, t));  // a bow tie: its two lobes cancel
  std::mt19937 rng(7);
  EXPECT_FALSE(earClip(star(rng, kEarClipMaxVertices + 1), t));  // left to VTK
  EXPECT_EQ(t, (std::vector<int>{1, 2, 3}));
}

}  // namespace
}  // namespace parcelscope::viz::detail
