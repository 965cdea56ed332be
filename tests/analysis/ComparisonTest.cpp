// The comparison measures on samples small enough to check by hand, and their
// edge cases: empty sets, identical sets (distance 0), disjoint sets (KS 1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <tuple>

#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::analysis {
namespace {

const double kInf = HUGE_VAL;

TEST(KsStatistic, HandComputedValues) {
  EXPECT_DOUBLE_EQ(ksStatistic({1, 2, 3}, {3, 1, 2}), 0.0);  // same values, any order
  EXPECT_DOUBLE_EQ(ksStatistic({1, 2}, {3, 4}), 1.0);        // disjoint
  EXPECT_DOUBLE_EQ(ksStatistic({3, 4}, {1, 2}), 1.0);
  EXPECT_DOUBLE_EQ(ksStatistic({1, 2, 3, 4}, {3, 4, 5, 6}), 0.5);  // F_a(2) = 1/2, F_b(2) = 0
  // Ties across samples: at x = 1, F_a = 2/3 and F_b = 1/3; at x = 2 both reach 1.
  EXPECT_NEAR(ksStatistic({1, 1, 2}, {1, 2, 2}), 1.0 / 3.0, 1e-15);
  // Different sizes: F_a(1) = 1, F_b(1) = 1/4.
  EXPECT_DOUBLE_EQ(ksStatistic({1}, {1, 2, 3, 4}), 0.75);
}

TEST(KsStatistic, EmptyOrNonFiniteSamplesGiveNaN) {
  EXPECT_TRUE(std::isnan(ksStatistic({}, {1, 2})));
  EXPECT_TRUE(std::isnan(ksStatistic({1, 2}, {})));
  EXPECT_TRUE(std::isnan(ksStatistic({kInf}, {1})));  // no finite value left
  // Infinite values are left out, not compared.
  EXPECT_DOUBLE_EQ(ksStatistic({1, 2, kInf}, {1, 2}), 0.0);
}

TEST(Wasserstein1, HandComputedValues) {
  EXPECT_DOUBLE_EQ(wasserstein1({0}, {5}), 5.0);
  EXPECT_DOUBLE_EQ(wasserstein1({1, 2, 3}, {2, 3, 4}), 1.0);  // a shift by 1
  EXPECT_DOUBLE_EQ(wasserstein1({3, 1, 2}, {1, 2, 3}), 0.0);
  // Half the mass moves from 1 to 0: F_a - F_b = -1/2 on [0, 1).
  EXPECT_DOUBLE_EQ(wasserstein1({0, 1}, {0, 0}), 0.5);
  // Unequal sizes: {0, 10} against {4}: |1/2 - 0| on [0, 4) plus |1/2 - 1| on [4, 10).
  EXPECT_DOUBLE_EQ(wasserstein1({0, 10}, {4}), 0.5 * 4 + 0.5 * 6);
  EXPECT_TRUE(std::isnan(wasserstein1({}, {1})));
}

TEST(Wasserstein1, IsSymmetricScalesWithTheUnitAndBoundsTheMeanShift) {
  std::mt19937 rng(42);
  std::normal_distribution<double> n(100, 30);
  std::vector<double> a(200), b(150);
  for (double& x : a) x = n(rng);
  for (double& x : b) x = n(rng) + 20;
  std::vector<double> a2(a), b2(b);
  for (double& x : a2) x *= 3;
  for (double& x : b2) x *= 3;
  const double w = wasserstein1(a, b);
  EXPECT_DOUBLE_EQ(w, wasserstein1(b, a));
  EXPECT_NEAR(wasserstein1(a2, b2), 3 * w, 1e-9 * w);
  double ma = 0, mb = 0;
  for (double x : a) ma += x / static_cast<double>(a.size());
  for (double x : b) mb += x / static_cast<double>(b.size());
  EXPECT_GE(w, std::fabs(ma - mb) - 1e-9);  // W1 >= |difference of means|
}

TEST(SharedHistogram, BinsBothSamplesOnTheSameEdges) {
  const SharedHistogram h = sharedHistogram({0, 1, 2, 3}, {0, 1, 2, 3}, 3);
  EXPECT_EQ(h.edges, (std::vector<double>{0, 1, 2, 3}));
  EXPECT_EQ(h.a, (std::vector<int>{1, 1, 2}));  // the largest value closes the last bin
  EXPECT_EQ(h.b, h.a);
  EXPECT_DOUBLE_EQ(histogramIntersection(h), 1.0);
}

TEST(SharedHistogram, UpperQuantileSendsTheTailToTheLastBin) {
  // Pooled: 1 1 2 2 3 3 4 100; the 0.75 quantile (6th of 8) is 3.
  const SharedHistogram h = sharedHistogram({1, 2, 3, 100}, {1, 2, 3, 4}, 2, 0.75);
  EXPECT_EQ(h.edges, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(h.a, (std::vector<int>{1, 3}));
  EXPECT_EQ(h.b, (std::vector<int>{1, 3}));
  EXPECT_EQ(h.aOverflow, 1);
  EXPECT_EQ(h.bOverflow, 1);
}

// Random samples with ties, one side sometimes empty, infinities and NaN left
// out: the last edge is the pooled nearest-rank quantile (the largest value
// when that equals the smallest), every finite value is counted once, and
// those above the last edge are the overflow.
TEST(SharedHistogram, LastEdgeIsThePooledNearestRankQuantileOnRandomSamples) {
  const unsigned seed = 290101;  // fixed: a failure replays with the same seed
  std::mt19937 rng(seed);
  SCOPED_TRACE("seed " + std::to_string(seed));
  const double quantiles[] = {1.0, 0.99, 0.75, 0.5, 0.01};
  for (int round = 0; round < 200; ++round) {
    std::vector<double> a(rng() % 40), b(rng() % 40);
    for (auto* v : {&a, &b}) {
      for (double& x : *v) {
        const auto r = rng() % 20;
        x = r == 0 ? kInf : r == 1 ? std::nan("") : static_cast<double>(rng() % 12);  // many ties
      }
    }
    std::vector<double> pooled;
    for (const auto* v : {&a, &b}) {
      for (double x : *v) {
        if (std::isfinite(x)) pooled.push_back(x);
      }
    }
    std::sort(pooled.begin(), pooled.end());
    const double q = quantiles[rng() % std::size(quantiles)];
    const int bins = 1 + static_cast<int>(rng() % 6);
    const SharedHistogram h = sharedHistogram(a, b, bins, q);
    if (pooled.empty()) {
      EXPECT_TRUE(h.edges.empty());
      continue;
    }
    const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(pooled.size())));
    double hi = pooled[std::max<std::size_t>(rank, 1) - 1];
    if (hi <= pooled.front()) hi = pooled.back();
    if (hi <= pooled.front()) hi = pooled.front() + 1;
    ASSERT_FALSE(h.edges.empty());
    EXPECT_EQ(h.edges.front(), pooled.front()) << "round " << round;
    EXPECT_EQ(h.edges.back(), hi) << "round " << round;
    for (const auto& [values, counts, overflow] :
         {std::tuple{&a, &h.a, h.aOverflow}, std::tuple{&b, &h.b, h.bOverflow}}) {
      int finite = 0, above = 0;
      for (double x : *values) {
        finite += std::isfinite(x);
        above += std::isfinite(x) && x > hi;
      }
      EXPECT_EQ(std::accumulate(counts->begin(), counts->end(), 0), finite) << "round " << round;
      EXPECT_EQ(overflow, above) << "round " << round;
    }
  }
}

TEST(SharedHistogram, EqualValuesShareOneBinAndBadArgumentsAreRefused) {
  const SharedHistogram h = sharedHistogram({5, 5}, {5}, 10);
  EXPECT_EQ(h.edges, (std::vector<double>{5, 6}));
  EXPECT_EQ(h.a, (std::vector<int>{2}));
  EXPECT_EQ(h.b, (std::vector<int>{1}));
  EXPECT_TRUE(sharedHistogram({}, {}, 10).edges.empty());
  EXPECT_THROW(sharedHistogram({1}, {2}, 0), Error);
  EXPECT_THROW(sharedHistogram({1}, {2}, 5, 0.0), Error);
  EXPECT_THROW(sharedHistogram({1}, {2}, 5, 1.5), Error);
}

TEST(HistogramIntersection, HandComputedValues) {
  EXPECT_DOUBLE_EQ(histogramIntersection(sharedHistogram({0, 1}, {10, 11}, 2)), 0.0);  // disjoint
  // a = {2, 0} -> {1, 0}; b = {1, 1} -> {1/2, 1/2}: min sums to 1/2.
  EXPECT_DOUBLE_EQ(histogramIntersection(sharedHistogram({0, 0}, {0, 10}, 2)), 0.5);
  // Counts do not matter, proportions do: 1 copy against 3 copies of the same values.
  EXPECT_DOUBLE_EQ(histogramIntersection(sharedHistogram({1, 2, 3}, {1, 1, 1, 2, 2, 2, 3, 3, 3}, 3)), 1.0);
  EXPECT_TRUE(std::isnan(histogramIntersection(sharedHistogram({}, {1}, 2))));
}

TEST(Undesirable, FollowsYangEtAl2013Thresholds) {
  ShapeMetrics m;
  m.pAngle = 15;
  m.pArea = 1.2;
  EXPECT_FALSE(isUndesirable(m));  // both thresholds are strict
  m.pAngle = 15.01;
  EXPECT_TRUE(isUndesirable(m));
  m.pAngle = 0;
  m.pArea = 1.21;
  EXPECT_TRUE(isUndesirable(m));
}

ParcelMetrics parcel(double area, double width, double aspect, double pAngle, double pArea, bool access) {
  ParcelMetrics m;
  m.area = area;
  m.width = width;
  m.aspectRatio = aspect;
  m.pAngle = pAngle;
  m.pArea = pArea;
  m.streetAccess = access;
  return m;
}

TEST(SummarizeSet, HandComputedValues) {
  const SetSummary s = summarizeSet({parcel(100, 10, 2, 0, 1.0, true), parcel(300, 20, kInf, 20, 1.1, false)});
  EXPECT_EQ(s.parcels, 2);
  EXPECT_DOUBLE_EQ(s.meanArea, 200);
  EXPECT_DOUBLE_EQ(s.sdArea, std::sqrt(2.0) * 100);  // sample SD
  EXPECT_DOUBLE_EQ(s.meanWidth, 15);
  EXPECT_DOUBLE_EQ(s.sdWidth, std::sqrt(50.0));
  EXPECT_DOUBLE_EQ(s.meanAspectRatio, 2);  // the infinite aspect ratio is left out
  EXPECT_DOUBLE_EQ(s.streetAccessShare, 0.5);
  EXPECT_DOUBLE_EQ(s.meanPAngle, 10);
  EXPECT_DOUBLE_EQ(s.meanPArea, 1.05);
  EXPECT_DOUBLE_EQ(s.undesirableShare, 0.5);
  const SetSummary empty = summarizeSet({});
  EXPECT_EQ(empty.parcels, 0);
  EXPECT_TRUE(std::isnan(empty.meanArea));
  EXPECT_TRUE(std::isnan(empty.undesirableShare));
}

TEST(CompareSets, IdenticalSetsAreAtDistanceZeroAndDisjointAtKsOne) {
  const std::vector<ParcelMetrics> a = {parcel(100, 10, 1.5, 2, 1.0, true), parcel(400, 15, 3, 3, 1.1, true),
                                        parcel(900, 25, 2, 1, 1.0, false)};
  const Comparison same = compareSets(a, a, 10, 1.0);
  for (ComparedMetric m : kComparedMetrics) {
    EXPECT_DOUBLE_EQ(same.distances(m).ks, 0.0) << metricName(m);
    EXPECT_DOUBLE_EQ(same.distances(m).wasserstein, 0.0) << metricName(m);
    EXPECT_DOUBLE_EQ(same.distances(m).intersection, 1.0) << metricName(m);
  }
  const std::vector<ParcelMetrics> big = {parcel(5000, 60, 4, 2, 1.0, true), parcel(6000, 70, 5, 2, 1.0, true)};
  const Comparison apart = compareSets(a, big, 10, 1.0);
  EXPECT_DOUBLE_EQ(apart.area.ks, 1.0);
  EXPECT_DOUBLE_EQ(apart.width.ks, 1.0);
  EXPECT_DOUBLE_EQ(apart.aspectRatio.ks, 1.0);
  EXPECT_DOUBLE_EQ(apart.area.intersection, 0.0);
  EXPECT_NEAR(apart.area.wasserstein, 5500.0 - 1400.0 / 3.0, 1e-9);  // every value moves up: mean difference
  EXPECT_EQ(apart.observed.parcels, 3);
  EXPECT_EQ(apart.generated.parcels, 2);
  const Comparison none = compareSets(a, {}, 10, 1.0);
  EXPECT_TRUE(std::isnan(none.area.ks));
  EXPECT_TRUE(std::isnan(none.area.intersection));
}

TEST(ComparisonTables, PerBlockRowsFollowThePapersTable) {
  BlockComparison b;
  b.blockId = 7;
  b.blockArea = 1234;
  b.comparison = compareSets({parcel(100, 10, 2, 0, 1, true)},
                             {parcel(100, 10, 2, 0, 1, true), parcel(300, 20, 2, 0, 1, true)}, 5, 1.0);
  const Table t = blockComparisonTable({b});
  ASSERT_EQ(t.rows.size(), 1u);
  ASSERT_EQ(t.rows[0].size(), t.columns.size());
  EXPECT_EQ(std::get<std::int64_t>(t.rows[0][t.column("block_id")]), 7);
  EXPECT_EQ(std::get<std::int64_t>(t.rows[0][t.column("observed_parcels")]), 1);
  EXPECT_EQ(std::get<std::int64_t>(t.rows[0][t.column("generated_parcels")]), 2);
  EXPECT_DOUBLE_EQ(std::get<double>(t.rows[0][t.column("generated_mean_area")]), 200);
  EXPECT_DOUBLE_EQ(std::get<double>(t.rows[0][t.column("ks_area")]), 0.5);
  EXPECT_DOUBLE_EQ(std::get<double>(t.rows[0][t.column("wasserstein_area")]), 100);
  const Table d = distanceTable(b.comparison);
  EXPECT_EQ(d.rows.size(), 3u);
  EXPECT_EQ(std::get<std::string>(d.rows[2][0]), "aspect_ratio");
  const Table s = summaryTable(b.comparison);
  EXPECT_EQ(std::get<std::string>(s.rows[0][0]), "parcels");
  EXPECT_DOUBLE_EQ(std::get<double>(s.rows[0][s.column("generated")]), 2.0);
}

TEST(ParcelQuantity, NamesValuesAndFiniteSamples) {
  ParcelMetrics m;
  m.area = 420;
  m.width = 12;
  m.aspectRatio = std::numeric_limits<double>::infinity();
  m.neighbours = 3;
  m.streetAccess = true;
  m.pAngle = 4;
  m.pArea = 1.1;
  EXPECT_EQ(parcelQuantities().front().name, "aspect_ratio");
  EXPECT_EQ(parcelQuantity("area").value(m), 420);
  EXPECT_EQ(parcelQuantity("width").value(m), 12);
  EXPECT_EQ(parcelQuantity("neighbours").value(m), 3);
  EXPECT_EQ(parcelQuantity("street_access").value(m), 1);
  EXPECT_EQ(parcelQuantity("p_angle").value(m), 4);
  EXPECT_EQ(parcelQuantity("p_area").value(m), 1.1);
  ParcelMetrics n = m;
  n.aspectRatio = 2;
  EXPECT_EQ(quantitySample({m, n}, parcelQuantity("aspect_ratio")), std::vector<double>{2});
  try {
    parcelQuantity("colour");
    FAIL() << "expected Error(Usage)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Usage);
    EXPECT_NE(std::string(e.what()).find("p_area"), std::string::npos) << "lists the names";
  }
}

}  // namespace
}  // namespace parcelscope::analysis
