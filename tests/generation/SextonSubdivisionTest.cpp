// The sexton style (Sexton & Watson 2010): a spine along oblong blocks, then
// constrained random splits of the largest parcel to a target count, best of
// many tries against the observed parcels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "RandomShapes.h"
#include "StyleRun.h"
#include "TestUtil.h"
#include "TilingCheck.h"
#include "parcelscope/generation/Styles.h"

namespace parcelscope::generation {
namespace {

Subdivision sexton(const Polygon& block, const ParameterValues& values, std::uint64_t seed = 1,
                   const ObservedSample* observed = nullptr) {
  return test::runStyle(sextonStyle(), block, values, seed, observed);
}

// `n` observed parcels alike.
ObservedSample sampleOf(std::size_t n, double area, double width, double aspectRatio) {
  ObservedSample o;
  o.areas.assign(n, area);
  o.widths.assign(n, width);
  o.aspectRatios.assign(n, aspectRatio);
  return o;
}

TEST(Sexton, AnOblongBlockIsCutAlongItsSpineFromEndToEnd) {
  // 120 x 40 (1:3): the spine runs along the middle; two parcels wanted: the two halves.
  const Polygon block = test::rect(0, 0, 120, 40);
  const Subdivision s = sexton(block, {{"parcel-count", 2}, {"a-min", 10}, {"w-min", 1}});
  ASSERT_EQ(s.parcels.size(), 2u);
  for (const Polygon& p : s.parcels) {
    const Box b = bounds(p);
    EXPECT_NEAR(b.width(), 120, 1e-9);
    EXPECT_NEAR(b.height(), 20, 1e-9);
  }
  // A square block has no spine: its first split is across a side.
  const Subdivision q = sexton(test::rect(0, 0, 60, 60), {{"parcel-count", 2}, {"a-min", 10}, {"w-min", 1}});
  ASSERT_EQ(q.parcels.size(), 2u);
  for (const Polygon& p : q.parcels) EXPECT_NEAR(bounds(p).height() * bounds(p).width(), area(p), 1e-6);
}

TEST(Sexton, ReachesTheTargetCountWithStreetAccessAndThePapersConstraints) {
  const Polygon block = test::rect(0, 0, 160, 50);
  const Subdivision s = sexton(block, {{"parcel-count", 16}, {"a-min", 200}, {"w-min", 6}}, 3);
  EXPECT_TILES(block, s.parcels, "160 x 50");
  EXPECT_EQ(s.parcels.size(), 16u);
  EXPECT_EQ(s.targetParcels, 16);
  EXPECT_EQ(s.withoutAccess, 0);
  EXPECT_EQ(test::measuredWithoutAccess(block, s.parcels, 3.0), 0);  // frontage >= w-min / 2
  for (const Polygon& p : s.parcels) EXPECT_GE(area(p), 0.75 * 200 * (1 - 1e-9));
  // The same seed, the same parcels; another seed, others.
  const Subdivision again = sexton(block, {{"parcel-count", 16}, {"a-min", 200}, {"w-min", 6}}, 3);
  ASSERT_EQ(again.parcels.size(), s.parcels.size());
  for (std::size_t i = 0; i < s.parcels.size(); ++i) EXPECT_TRUE(sameVertices(again.parcels[i], s.parcels[i]));
  const Subdivision other = sexton(block, {{"parcel-count", 16}, {"a-min", 200}, {"w-min", 6}}, 4);
  bool differs = other.parcels.size() != s.parcels.size();
  for (std::size_t i = 0; !differs && i < s.parcels.size(); ++i)
    differs = !sameVertices(other.parcels[i], s.parcels[i]);
  EXPECT_TRUE(differs);
}

TEST(Sexton, OfManyTriesKeepsTheOneClosestToTheObservedParcels) {
  // Observed: 8 equal lots of 20 x 50 m. More tries can only bring the kept
  // subdivision closer (the first tries are among them).
  const Polygon block = test::rect(0, 0, 160, 50);
  const ObservedSample observed = sampleOf(8, 1000, 20, 2.5);
  const Subdivision one = sexton(block, {{"tries", 1}, {"a-min", 400}, {"w-min", 10}}, 5, &observed);
  const Subdivision many = sexton(block, {{"tries", 60}, {"a-min", 400}, {"w-min", 10}}, 5, &observed);
  EXPECT_EQ(one.targetParcels, 8);
  // The style's distance: KS of area, width and aspect ratio (MBR) against
  // the observed values, plus the relative count error.
  auto distance = [&](const Subdivision& s) {
    auto ks = [](const std::vector<double>& x, double v) {  // against a sample of one repeated value
      std::size_t below = 0, above = 0;
      for (double e : x) {
        below += e < v - 1e-6;
        above += e > v + 1e-6;
      }
      return static_cast<double>(std::max(below, above)) / static_cast<double>(x.size());
    };
    std::vector<double> a, w, r;
    for (const Polygon& p : s.parcels) {
      const OrientedBox box = minimumAreaBox(p.outer);
      a.push_back(area(p));
      w.push_back(box.width);
      r.push_back(box.length / box.width);
    }
    return std::fabs(static_cast<double>(s.parcels.size()) / 8 - 1) + ks(a, 1000) + ks(w, 20) + ks(r, 2.5);
  };
  EXPECT_LE(distance(many), distance(one));
  EXPECT_EQ(many.parcels.size(), 8u);
}

// Reaching the target count may take slivers (every parcel needs road
// access); with the constraints relaxed, no piece is thinner than the block's
// observed parcels at their 90th percentile of aspect ratio (at most 1:4),
// 1:10 without observed parcels: the block stops short instead.
TEST(Sexton, NoSliverThinnerThanTheObservedParcelsToReachTheCount) {
  const Polygon block = test::rect(0, 0, 60, 60);
  const ParameterValues values{{"parcel-count", 80}, {"a-min", 10}, {"w-min", 1}, {"tries", 5}};
  auto thinnest = [](const Subdivision& s) {
    double least = 1;
    for (const Polygon& p : s.parcels) {
      const OrientedBox b = minimumAreaBox(p.outer);
      least = std::min(least, b.width / b.length);
    }
    return least;
  };
  const ObservedSample squares = sampleOf(80, 45, std::sqrt(45.0), 1), long8 = sampleOf(80, 45, std::sqrt(45.0 / 8), 8);
  const Subdivision fromSquares = sexton(block, values, 2, &squares);
  const Subdivision fromLong = sexton(block, values, 2, &long8);
  const Subdivision alone = sexton(block, values, 2);
  for (const Subdivision* s : {&fromSquares, &fromLong, &alone}) EXPECT_TILES(block, s->parcels, "60 x 60");
  EXPECT_LT(fromSquares.parcels.size(), 80u);
  EXPECT_GE(thinnest(fromSquares), 0.25 - 1e-9);
  EXPECT_GE(thinnest(fromLong), 0.125 - 1e-9);
  EXPECT_LT(thinnest(fromLong), 0.25);
  EXPECT_GT(fromLong.parcels.size(), fromSquares.parcels.size());
  EXPECT_GE(thinnest(alone), 0.1 - 1e-9);
  std::printf("parcels of 80: %zu (observed squares), %zu (observed 1:8), %zu (none)\n", fromSquares.parcels.size(),
              fromLong.parcels.size(), alone.parcels.size());
}

// Where a third of the block's observed parcels have no street access,
// sexton cuts some parcels off along the street at the observed depth
// (interior parcels); `interior-parcels none` (the paper) keeps every parcel
// on a street.
TEST(Sexton, InteriorParcelsFollowTheObservedShareWithoutStreetAccess) {
  const Polygon block = test::rect(0, 0, 120, 120);
  ObservedSample observed = sampleOf(30, 480, 20, 1.2);
  observed.accessShare = 2.0 / 3.0;
  const ParameterValues values{{"a-min", 100}, {"w-min", 4}, {"tries", 10}};
  ParameterValues paper = values;
  paper["interior-parcels"] = 0;
  const Subdivision s = sexton(block, values, 3, &observed), p = sexton(block, paper, 3, &observed);
  EXPECT_TILES(block, s.parcels, "120 x 120");
  EXPECT_TILES(block, p.parcels, "120 x 120, the paper's");
  EXPECT_EQ(s.targetParcels, 30);
  EXPECT_EQ(p.withoutAccess, 0);
  EXPECT_EQ(test::measuredWithoutAccess(block, p.parcels, 2.0), 0);
  EXPECT_GT(s.withoutAccess, 0);
  EXPECT_LE(s.withoutAccess, 10);  // at most the observed third of the 30 wanted
  EXPECT_EQ(test::measuredWithoutAccess(block, s.parcels, 2.0), s.withoutAccess);
  std::printf("%zu parcels, %d without street access (the paper's: %zu, %d)\n", s.parcels.size(), s.withoutAccess,
              p.parcels.size(), p.withoutAccess);
}

// A block whose observed parcels are mostly interior (three in four) gets
// them: an interior parcel is split again, across any of its sides, at the
// area of an observed parcel, while the block's allowance lasts. Cut off only
// behind the street parcels, a 200 m square of 40 parcels had at most one
// interior parcel behind each street parcel.
TEST(Sexton, InteriorParcelsAreSplitAgainUpToTheObservedShare) {
  const Polygon block = test::rect(0, 0, 300, 300);
  ObservedSample observed = sampleOf(100, 900, 30, 1);
  observed.accessShare = 0.36;
  const ParameterValues values{{"a-min", 300}, {"w-min", 4}, {"tries", 10}};
  const Subdivision s = sexton(block, values, 5, &observed);
  EXPECT_TILES(block, s.parcels, "300 x 300");
  EXPECT_EQ(s.parcels.size(), 100u);
  EXPECT_LE(s.withoutAccess, 64);  // the allowance: floor(0.64 * 100)
  EXPECT_GE(s.withoutAccess, 25);  // 16, of 80 parcels, when interior parcels were not split again
  EXPECT_EQ(test::measuredWithoutAccess(block, s.parcels, 2.0), s.withoutAccess);
  std::printf("%zu parcels, %d without street access\n", s.parcels.size(), s.withoutAccess);
}

// A block of a few estates among many houses, nearly all interior: its
// interior parcels become the observed areas drawn for them, estates kept
// whole, not parcels of about the mean area.
TEST(Sexton, InteriorParcelsTakeTheObservedMixtureOfAreas) {
  const Polygon block = test::rect(0, 0, 400, 400);
  ObservedSample observed = sampleOf(264, 300, 12, 2.1);  // houses
  for (int i = 0; i < 16; ++i) {                          // estates
    observed.areas.push_back(5000);
    observed.widths.push_back(50);
    observed.aspectRatios.push_back(2);
  }
  observed.accessShare = 0.1;
  const ParameterValues values{{"a-min", 57}, {"w-min", 4}, {"tries", 10}};
  const Subdivision s = sexton(block, values, 1, &observed);
  EXPECT_TILES(block, s.parcels, "400 x 400");
  int estates = 0, houses = 0;
  for (const Polygon& p : s.parcels) {
    estates += area(p) >= 2500;
    houses += area(p) <= 600;
  }
  // Cutting off one drawn area at a time gave 179 parcels, 21 estates and
  // 138 houses (checked): the largest parcel, split first, was cut into
  // pieces too thin to split again.
  EXPECT_EQ(s.parcels.size(), 280u);
  EXPECT_GE(estates, 5);
  EXPECT_GE(houses, 200);
  std::printf("%zu parcels: %d estates, %d houses, %d without street access\n", s.parcels.size(), estates, houses,
              s.withoutAccess);
}

// A block of a few large street parcels around many interior houses (as
// seoul_jamsil's largest block: 52 road parcels of median 8,532 m², 804
// interior ones of median 314 m²): its street front is as deep as the
// observed street parcels are long, its interior parcels take the observed
// interior areas, and once it has its road parcels, a road parcel is only
// cut along the street.
TEST(Sexton, TheStreetFrontTakesTheObservedRoadParcels) {
  const Polygon block = test::rect(0, 0, 500, 500);
  ObservedSample observed = sampleOf(264, 300, 12, 2.1);  // interior houses
  observed.access.assign(264, 0);
  for (int i = 0; i < 16; ++i) {  // street parcels, 100 m deep
    observed.areas.push_back(5000);
    observed.widths.push_back(50);
    observed.aspectRatios.push_back(2);
    observed.access.push_back(1);
  }
  observed.accessShare = 16.0 / 280.0;
  const ParameterValues values{{"a-min", 57}, {"w-min", 4}, {"tries", 10}};
  const Subdivision s = sexton(block, values, 1, &observed);
  EXPECT_TILES(block, s.parcels, "500 x 500");
  const int road = static_cast<int>(s.parcels.size()) - s.withoutAccess;
  int houses = 0;
  double roadArea = 0;
  const analysis::PreparedBoundary outline(block, 1e-6);
  for (const Polygon& p : s.parcels) {
    houses += area(p) <= 600;
    if (outline.sharesAtLeast(p, 2.0)) roadArea += area(p);
  }
  EXPECT_EQ(test::measuredWithoutAccess(block, s.parcels, 2.0), s.withoutAccess);
  EXPECT_GE(s.parcels.size(), 250u);
  // Without the closing of road parcels: 60 on the road, 195 houses (checked).
  EXPECT_LE(road, 32);  // twice the observed
  EXPECT_GE(houses, 200);
  // A front 100 m deep is 64 % of the block. Cut at all the observed
  // parcels' median length (25 m), and with interior parcels split into all
  // the observed areas, the road parcels made 58 % (checked).
  EXPECT_GE(roadArea, 0.62 * area(block));
  std::printf("%zu parcels: %d on the road (%.0f %% of the area), %d houses\n", s.parcels.size(), road,
              100 * roadArea / area(block), houses);
}

// A block whose observed parcels are all (or all but one) interior starts as
// one road parcel, already as many as it is to have: road parcels are held to
// cuts along the street only while an interior parcel is left to split, so
// it still reaches its count. Held from the start, it stopped at 49 of 100
// (checked).
TEST(Sexton, ABlockOfInteriorParcelsOnlyReachesItsCount) {
  const Polygon block = test::rect(0, 0, 200, 200);
  for (const int road : {0, 1}) {
    ObservedSample observed = sampleOf(100, 400, 16, 1.5);
    observed.access.assign(100, 0);
    for (int k = 0; k < road; ++k) observed.access[static_cast<std::size_t>(k)] = 1;
    observed.accessShare = road / 100.0;
    const ParameterValues values{{"a-min", 57}, {"w-min", 4}, {"tries", 10}};
    const Subdivision s = sexton(block, values, 1, &observed);
    const std::string what = std::to_string(road) + " road parcels observed";
    EXPECT_TILES(block, s.parcels, what);
    EXPECT_EQ(s.parcels.size(), 100u) << what;
    EXPECT_GE(s.withoutAccess, 50) << what;
    std::printf("%s: %zu parcels, %d without street access\n", what.c_str(), s.parcels.size(), s.withoutAccess);
  }
}

// The least piece is 75 % of the smaller of a-min and the observed 5th
// percentile of area (the paper: the block's smallest parcel).
TEST(Sexton, TheLeastPieceFollowsTheObservedSmallParcels) {
  const Polygon block = test::rect(0, 0, 120, 60);
  ObservedSample observed = sampleOf(12, 600, 15, 2.7);
  for (std::size_t i = 0; i < 4; ++i) observed.areas[i] = 250;
  for (std::size_t i = 4; i < 12; ++i) observed.areas[i] = 775;
  const ParameterValues values{{"a-min", 600}, {"w-min", 4}, {"tries", 10}};
  const Subdivision s = sexton(block, values, 3, &observed);
  EXPECT_TILES(block, s.parcels, "120 x 60");
  EXPECT_EQ(s.parcels.size(), 12u);
  double least = 1e9;
  for (const Polygon& p : s.parcels) least = std::min(least, area(p));
  EXPECT_GE(least, 0.75 * 250 * (1 - 1e-9));
  EXPECT_LT(least, 0.75 * 600);  // with a-min alone, no piece below 450 m²
}

// A block whose observed parcels are thinner than 1:4 at their 90th
// percentile admits pieces thinner than that up to its thin quota (here 10
// of 100; on these seeds no other thin parcel arises), no thinner than their
// 95th percentile and no smaller than their 10th percentile of area; without
// the quota, none (the limit held every piece to the 90th percentile).
TEST(Sexton, ThinParcelsFollowTheObservedOnesThinnerThanTheLimit) {
  const Polygon block = test::rect(0, 0, 300, 60);
  // 70 parcels of 1:3, 20 of 1:5 (the 90th percentile), 10 of 1:9 (the 95th), all of 180 m².
  ObservedSample observed = sampleOf(100, 180, std::sqrt(180.0 / 3), 3);
  for (std::size_t i = 70; i < 100; ++i) {
    const double r = i < 90 ? 5 : 9;
    observed.aspectRatios[i] = r;
    observed.widths[i] = std::sqrt(180.0 / r);
  }
  const ParameterValues values{{"a-min", 100}, {"w-min", 2}, {"tries", 10}};
  for (std::uint64_t seed : {1, 2, 3}) {
    const Subdivision s = sexton(block, values, seed, &observed);
    EXPECT_TILES(block, s.parcels, "300 x 60");
    std::size_t thin = 0;
    double thinnest = 1, leastThinArea = 1e9;
    for (const Polygon& p : s.parcels) {
      const OrientedBox b = minimumAreaBox(p.outer);
      thinnest = std::min(thinnest, b.width / b.length);
      if (b.width / b.length < 0.2 - 1e-9) {
        ++thin;
        leastThinArea = std::min(leastThinArea, area(p));
      }
    }
    EXPECT_GE(thin, 1u) << "seed " << seed;
    EXPECT_LE(thin, 10u) << "seed " << seed;
    EXPECT_GE(thinnest, 1.0 / 9 - 1e-9) << "seed " << seed;
    if (thin > 0) EXPECT_GE(leastThinArea, 180 * (1 - 1e-9)) << "seed " << seed;
    std::printf("seed %llu: %zu parcels, %zu thinner than 1:5, thinnest 1:%.1f\n",
                static_cast<unsigned long long>(seed), s.parcels.size(), thin, 1 / thinnest);
  }
}

// Random shapes with observed parcels partly interior: a tiling, valid and
// reproducible, with no more interior parcels than the observed share allows.
TEST(Sexton, RandomShapesWithInteriorParcelsTile) {
  std::mt19937_64 rng(20261129);
  std::size_t thin = 0;  // parcels thinner than the limit in the shapes with thin observed parcels
  for (int i = 0; i < 40 / test::kSanitizerDivisor; ++i) {
    const Polygon block = test::randomShape(rng, i % test::kShapeKinds);
    const double a = area(block);
    const auto n = static_cast<std::size_t>(4 + rng() % 30);
    ObservedSample observed = sampleOf(n, a / static_cast<double>(n), std::sqrt(a / static_cast<double>(n) / 1.5), 1.5);
    for (double& o : observed.areas) o *= 0.3 + 1.4 * static_cast<double>(rng() % 1000) / 1000.0;
    observed.accessShare = 0.2 + 0.6 * static_cast<double>(rng() % 1000) / 1000.0;
    if (i % 2 == 1) {  // half the shapes know each observed parcel's access, in the share
      const auto with = static_cast<std::size_t>(std::round(observed.accessShare * static_cast<double>(n)));
      observed.access.assign(n, 0);
      for (std::size_t k = 0; k < with; ++k) observed.access[k] = 1;
      for (std::size_t k = 0; k < n; ++k) observed.aspectRatios[k] *= observed.access[k] ? 1.5 : 1;
      observed.accessShare = static_cast<double>(with) / static_cast<double>(n);
    }
    if (i % 3 == 0) {  // a third with a tail of thin parcels (1:5 to 1:10): the thin quota
      for (std::size_t k = 0; k < n; ++k) {
        if (rng() % 100 < 25) observed.aspectRatios[k] = 5 + static_cast<double>(rng() % 6);
      }
    }
    // The rectangularity limit: the observed 90th percentile of aspect ratio, at most 1:4.
    std::vector<double> ratios = observed.aspectRatios;
    std::sort(ratios.begin(), ratios.end());
    const double least = std::min(0.25, 1 / ratios[static_cast<std::size_t>(0.9 * static_cast<double>(n - 1))]);
    const std::uint64_t seed = rng();
    const ParameterValues values = {{"a-min", 0.2 * a / static_cast<double>(n)}, {"w-min", 1}, {"tries", 3}};
    const Subdivision s = sexton(block, values, seed, &observed);
    const std::string what = "shape " + std::to_string(i) + " kind " + std::to_string(i % test::kShapeKinds);
    ASSERT_FALSE(s.failed) << what << ": " << s.failure;
    EXPECT_TILES(block, s.parcels, what);
    EXPECT_LE(s.withoutAccess, static_cast<int>(std::floor((1 - observed.accessShare) * static_cast<double>(n) + 1e-9)))
        << what;
    const Subdivision again = sexton(block, values, seed, &observed);
    ASSERT_EQ(again.parcels.size(), s.parcels.size()) << what;
    for (std::size_t k = 0; k < s.parcels.size(); ++k) {
      EXPECT_TRUE(sameVertices(again.parcels[k], s.parcels[k])) << what << " parcel " << k;
      const OrientedBox b = minimumAreaBox(s.parcels[k].outer);
      if (i % 3 == 0 && b.width < least * b.length * (1 - 1e-9)) ++thin;
    }
  }
  EXPECT_GT(thin, 0u);  // the thin quota was used
  std::printf("parcels thinner than the limit where the observed ones have a thin tail: %zu\n", thin);
}

// Random shapes: a tiling, valid, reproducible, every parcel with access
// where the block was split, and the target reached on nearly all.
TEST(Sexton, RandomShapesTileAndMostReachTheirTarget) {
  std::mt19937_64 rng(20261128);
  int shapes = 0, atTarget = 0;
  for (int i = 0; i < 70 / test::kSanitizerDivisor; ++i, ++shapes) {
    const Polygon block = test::randomShape(rng, i % test::kShapeKinds);
    const ObbParameters b = test::randomBounds(rng, area(block));
    const std::uint64_t seed = rng();
    const ParameterValues values = {{"a-min", b.aMin}, {"a-max", b.aMax}, {"w-min", b.wMin}, {"tries", 5}};
    const Subdivision s = sexton(block, values, seed);
    const std::string what = "shape " + std::to_string(i) + " kind " + std::to_string(i % test::kShapeKinds);
    ASSERT_FALSE(s.failed) << what << ": " << s.failure;
    EXPECT_FALSE(s.fallback) << what << ": " << s.fallbackReason;
    EXPECT_TILES(block, s.parcels, what);
    EXPECT_GE(s.targetParcels, 1) << what;
    atTarget += static_cast<int>(s.parcels.size()) == s.targetParcels;
    const Subdivision again = sexton(block, values, seed);
    ASSERT_EQ(again.parcels.size(), s.parcels.size()) << what;
    for (std::size_t k = 0; k < s.parcels.size(); ++k) {
      EXPECT_TRUE(sameVertices(again.parcels[k], s.parcels[k])) << what << " parcel " << k;
    }
  }
  std::printf("%d random shapes, %d at their target count\n", shapes, atTarget);
  EXPECT_GE(atTarget, shapes * 9 / 10);
}

}  // namespace
}  // namespace parcelscope::generation
