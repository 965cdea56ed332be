#include "parcelscope/generation/ObbSubdivision.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "TestUtil.h"
#include "generation/RandomShapes.h"
#include "generation/StreetFrontage.h"
#include "generation/TilingCheck.h"
#include "parcelscope/analysis/Metrics.h"

namespace parcelscope::generation {
namespace {

using test::poly;
using test::rect;

ObbParameters params(double aMin, double aMax, double wMin, double wMax, double omega = 0.3, double xi = 1.0) {
  ObbParameters p;
  p.aMin = aMin;
  p.aMax = aMax;
  p.wMin = wMin;
  p.wMax = wMax;
  p.omega = omega;
  p.xi = xi;
  return p;
}

TEST(ObbSubdivision, RectangleSplitsIntoParcelsWithinBounds) {
  const Polygon block = rect(0, 0, 200, 60);
  const Subdivision s = subdivideObb(block, params(300, 900, 8, 40), 42);
  ASSERT_FALSE(s.failed) << s.failure;
  EXPECT_TILES(block, s.parcels, "rectangle");
  EXPECT_GE(s.parcels.size(), 14u);  // 12000 m2 / 900
  for (const Polygon& p : s.parcels) {
    EXPECT_GE(area(p), 300 - 1e-9);
    EXPECT_LE(area(p), 900 + 1e-9);
    const OrientedBox b = minimumAreaBox(p.outer);
    EXPECT_GE(b.width, 8 - 1e-9);
    EXPECT_LE(b.width, 40 + 1e-9);
  }
  EXPECT_EQ(s.oversize, 0);
  EXPECT_EQ(s.withoutAccess, 0);
}

TEST(ObbSubdivision, SameSeedSameParcelsOtherSeedOtherParcels) {
  const Polygon block = poly({{0, 0}, {180, -20}, {220, 90}, {30, 110}});
  const auto p = params(200, 700, 6, 35, 0.8);
  const Subdivision a = subdivideObb(block, p, 7), b = subdivideObb(block, p, 7), c = subdivideObb(block, p, 8);
  ASSERT_EQ(a.parcels.size(), b.parcels.size());
  for (std::size_t i = 0; i < a.parcels.size(); ++i) EXPECT_TRUE(sameVertices(a.parcels[i], b.parcels[i])) << i;
  bool differs = a.parcels.size() != c.parcels.size();
  for (std::size_t i = 0; !differs && i < a.parcels.size(); ++i) {
    differs = a.parcels[i].outer[0].x != c.parcels[i].outer[0].x;
  }
  EXPECT_TRUE(differs);
}

TEST(ObbSubdivision, WithoutStreetAccessPreferenceInnerParcelsAppear) {
  // A deep block: with xi = 0 some splits leave parcels without frontage; with xi = 1 none do.
  const Polygon block = rect(0, 0, 150, 150);
  int withoutAccess = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    withoutAccess += subdivideObb(block, params(150, 500, 5, 30, 0.3, 0.0), seed).withoutAccess;
    EXPECT_EQ(subdivideObb(block, params(150, 500, 5, 30, 0.3, 1.0), seed).withoutAccess, 0);
  }
  EXPECT_GT(withoutAccess, 0);
}

TEST(ObbSubdivision, BlockSmallerThanBoundsStaysWhole) {
  const Polygon block = rect(0, 0, 10, 10);
  const Subdivision s = subdivideObb(block, params(200, 800, 8, 30), 1);
  ASSERT_EQ(s.parcels.size(), 1u);
  EXPECT_DOUBLE_EQ(area(s.parcels[0]), 100);
}

TEST(ObbSubdivision, HolesAreKeptOutOfParcels) {
  Polygon block = rect(0, 0, 120, 120);
  block.holes.push_back({{40, 40}, {40, 80}, {80, 80}, {80, 40}});
  normalise(block);
  const Subdivision s = subdivideObb(block, params(200, 900, 8, 40), 3);
  ASSERT_FALSE(s.failed) << s.failure;
  EXPECT_TILES(block, s.parcels, "courtyard block");
}

// A block of 900 small courtyards on a grid (its validity was once checked
// by CGAL's Boolean operations alone: minutes for such blocks) is subdivided
// into a tiling that keeps every courtyard out.
TEST(ObbSubdivision, BlockWithManyHolesIsSubdivided) {
  Polygon block = rect(0, 0, 1000, 1000);
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) {
      const double x = 20 + 32 * i, y = 20 + 32 * j;
      block.holes.push_back({{x, y}, {x, y + 6}, {x + 6, y + 6}, {x + 6, y}});
    }
  }
  normalise(block);
  const Subdivision s = subdivideObb(block, params(2000, 8000, 20, 120), 5);
  ASSERT_FALSE(s.failed) << s.failure;
  EXPECT_GT(s.parcels.size(), 60u);
  std::size_t holes = 0;
  for (const Polygon& p : s.parcels) holes += p.holes.size();
  EXPECT_GT(holes, 0u);
  EXPECT_TILES(block, s.parcels, "block of 900 courtyards");
}

TEST(ObbSubdivision, SelfIntersectingBlockComesBackWholeAndFlagged) {
  const Polygon bowtie = poly({{0, 0}, {100, 100}, {100, 0}, {0, 100}});
  const Subdivision s = subdivideObb(bowtie, params(100, 500, 5, 30), 1);
  EXPECT_TRUE(s.failed);
  EXPECT_EQ(s.parcels.size(), 1u);
}

TEST(ObbSubdivision, SplitSnapsToNearbyContourVertex) {
  // A kink in the street line at x = 101 lies 1 m from the middle split at x = 100.
  const Polygon block = poly({{0, 0}, {101, 0}, {200, 0}, {200, 40}, {0, 40}});
  ObbParameters p = params(1000, 5000, 5, 45, 0.0);
  p.snapDistance = 2.0;
  const Subdivision s = subdivideObb(block, p, 1);
  ASSERT_EQ(s.parcels.size(), 2u);
  EXPECT_NEAR(std::max(area(s.parcels[0]), area(s.parcels[1])), 101 * 40, 1e-6);
  p.snapDistance = 0.0;
  const Subdivision t = subdivideObb(block, p, 1);
  EXPECT_NEAR(std::min(area(t.parcels[0]), area(t.parcels[1])), 100 * 40, 1e-6);
}

TEST(ObbSubdivision, LocalEditChangesOnlyNearbyParcels) {
  // Moving a concave vertex of the street line leaves the OBB and the first
  // splits as they were; only parcels near the edit change (Vanegas et al. 2012, 4.3).
  auto block = [](double notch) {
    Polygon p = poly({{0, 0}, {200, 0}, {200, 60}, {40, 60}, {30, 60 - notch}, {20, 60}, {0, 60}});
    normalise(p);
    return p;
  };
  const auto p = params(200, 700, 8, 35, 0.5);
  const Subdivision before = subdivideObb(block(2.0), p, 11), after = subdivideObb(block(3.0), p, 11);
  auto same = [](const Polygon& a, const Polygon& b) {
    if (a.outer.size() != b.outer.size()) return false;
    for (std::size_t k = 0; k < a.outer.size(); ++k) {
      if (a.outer[k].x != b.outer[k].x || a.outer[k].y != b.outer[k].y) return false;
    }
    return true;
  };
  int unchanged = 0;
  for (const Polygon& a : after.parcels) {
    for (const Polygon& b : before.parcels) unchanged += same(a, b);
  }
  std::printf("%d of %zu parcels unchanged\n", unchanged, after.parcels.size());
  EXPECT_GE(unchanged, static_cast<int>(after.parcels.size()) * 2 / 3);
  EXPECT_LT(unchanged, static_cast<int>(after.parcels.size()));  // the parcel at the notch did change
}

// ---- Randomised shapes (generation/RandomShapes.h) -------------------------

constexpr int kRandomShapes = 1400 / test::kSanitizerDivisor;

TEST(ObbSubdivision, RandomShapesAreTiledValidlyAndReproducibly) {
  std::mt19937_64 rng = test::seededRandom(20261121, "random shapes");
  std::uniform_real_distribution<double> u(0, 1);
  int shapes = 0, parcels = 0, accessExceptions = 0, withoutAccess = 0, narrowChecked = 0;
  for (int i = 0; i < kRandomShapes; ++i) {
    const int kind = i % 7;
    const Polygon block = test::randomShape(rng, kind);
    const double a = area(block);
    ObbParameters p = test::randomBounds(rng, a);
    p.xi = i % 3 == 0 ? 1.0 : u(rng);
    const std::uint64_t s = rng();
    const Subdivision sub = subdivideObb(block, p, s);
    const std::string what = "shape " + std::to_string(i) + " kind " + std::to_string(kind);
    ASSERT_FALSE(sub.failed) << what << ": " << sub.failure;
    EXPECT_TILES(block, sub.parcels, what);
    // Every split's pieces keep A_min and W_min (obb.md, stopping rule), so
    // once the block is split, no parcel is below either; a parcel left
    // unsplit (oversize) came from an admissible split too. Only a block left
    // whole may be smaller or narrower.
    if (sub.parcels.size() > 1) {
      for (const Polygon& q : sub.parcels) EXPECT_GE(area(q), p.aMin * (1 - 1e-9)) << what;
      EXPECT_EQ(test::narrowerThan(sub.parcels, p.wMin), 0) << what << ": parcels narrower than W_min " << p.wMin;
      narrowChecked += static_cast<int>(sub.parcels.size());
    }
    if (p.xi == 1.0) accessExceptions += sub.withoutAccess;
    // The access the subdivision decided on is the measured one, by its own
    // test and by GEOS.
    const int measuredWithout = test::measuredWithoutAccess(block, sub.parcels, p.minFrontage);
    EXPECT_EQ(measuredWithout, sub.withoutAccess) << what;
    EXPECT_EQ(test::geosWithoutAccess(block, sub.parcels, p.minFrontage), sub.withoutAccess) << what;
    withoutAccess += measuredWithout;
    if (i % 50 == 0) {  // reproducible from the seed, vertex for vertex
      const Subdivision again = subdivideObb(block, p, s);
      ASSERT_EQ(again.parcels.size(), sub.parcels.size()) << what;
      for (std::size_t k = 0; k < sub.parcels.size(); ++k) {
        EXPECT_TRUE(sameVertices(again.parcels[k], sub.parcels[k])) << what << " parcel " << k;
      }
    }
    ++shapes;
    parcels += static_cast<int>(sub.parcels.size());
  }
  std::printf("%d shapes, %d parcels, %d without street access (%d at xi = 1)\n", shapes, parcels, withoutAccess,
              accessExceptions);
  EXPECT_EQ(accessExceptions, 0);
  EXPECT_GT(withoutAccess, 0);
  EXPECT_GT(narrowChecked, parcels / 2);  // the width bound was checked on most parcels
}

// Moving A_max and W_max up and down while reusing the recorded splits gives,
// at every step, exactly the parcels a fresh run gives; the other parameters
// make the splits unusable.
TEST(ObbSubdivision, ReusedSplitsGiveWhatAFreshRunGives) {
  const std::uint64_t seed = 290106;  // fixed: a failure replays with the same seed
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> scale(0.3, 3.0);
  int reusedSteps = 0;
  for (int i = 0; i < 200 / test::kSanitizerDivisor; ++i) {
    const Polygon block = test::randomShape(rng, i % 7);
    ObbParameters p = test::randomBounds(rng, area(block));
    const std::uint64_t s = rng();
    Subdivision last = subdivideObb(block, p, s, {nullptr, true});
    ASSERT_NE(last.obbSplits, nullptr);
    for (int step = 0; step < 6; ++step) {
      const ObbParameters before = p;
      p.aMax = std::max(p.aMin, p.aMax * scale(rng));
      p.wMax = std::max(p.wMin, p.wMax * scale(rng));
      ASSERT_TRUE(obbSplitsReusable(before, p));
      const Subdivision reused = subdivideObb(block, p, s, {last.obbSplits.get(), true});
      const Subdivision fresh = subdivideObb(block, p, s);
      const std::string what = "shape " + std::to_string(i) + " step " + std::to_string(step);
      ASSERT_EQ(reused.parcels.size(), fresh.parcels.size()) << what;
      for (std::size_t k = 0; k < fresh.parcels.size(); ++k) {
        EXPECT_TRUE(sameVertices(reused.parcels[k], fresh.parcels[k])) << what << " parcel " << k;
      }
      if (fresh.parcels.size() > 1) EXPECT_EQ(test::narrowerThan(fresh.parcels, p.wMin), 0) << what;
      EXPECT_EQ(reused.oversize, fresh.oversize) << what;
      EXPECT_EQ(reused.withoutAccess, fresh.withoutAccess) << what;
      reusedSteps += fresh.parcels.size() > 1;
      last = reused;
    }
  }
  EXPECT_GT(reusedSteps, 0);
  ObbParameters a, b = a;
  b.omega = 0.5;
  EXPECT_FALSE(obbSplitsReusable(a, b));
  b = a;
  b.wMin = a.wMin + 1;
  EXPECT_FALSE(obbSplitsReusable(a, b));
}

TEST(ObbSubdivision, ArbitraryPointRingsNeverThrowAndTileWhenValid) {
  // Random rings of 3 to 12 points: mostly self-intersecting, some with repeated
  // or collinear points. Invalid ones come back whole and flagged.
  std::mt19937_64 rng = test::seededRandom(99, "garbage rings");
  std::uniform_int_distribution<int> count(3, 12), grid(0, 20);
  int failed = 0, tiled = 0;
  for (int i = 0; i < 600; ++i) {
    Polygon p;
    const int n = count(rng);
    for (int k = 0; k < n; ++k) p.outer.push_back({10.0 * grid(rng), 10.0 * grid(rng)});
    if (!normalise(p)) continue;
    Subdivision s;
    ASSERT_NO_THROW(s = subdivideObb(p, params(100, 800, 4, 30, 0.5, 0.5), static_cast<std::uint64_t>(i)));
    if (s.failed) {
      ++failed;
      EXPECT_EQ(s.parcels.size(), 1u);
      continue;
    }
    ++tiled;
    EXPECT_TILES(p, s.parcels, "ring " + std::to_string(i));
    if (s.parcels.size() > 1) EXPECT_EQ(test::narrowerThan(s.parcels, 4), 0) << "ring " << i;
  }
  std::printf("%d rings subdivided, %d refused as invalid\n", tiled, failed);
  EXPECT_GT(failed, 0);
  EXPECT_GT(tiled, 0);
}

}  // namespace
}  // namespace parcelscope::generation
