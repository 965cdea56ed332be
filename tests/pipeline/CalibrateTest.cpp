// calibrate: each block gets the style closest to its observed parcels, the
// session file reproduces exactly what was measured, and the cross-validated
// rule is measured on blocks it was not fitted on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <numeric>
#include <random>
#include <set>

#include "SampleRequest.h"
#include "TestUtil.h"
#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/pipeline/Calibrate.h"
#include "parcelscope/pipeline/CompareSession.h"

namespace parcelscope::pipeline {
namespace {

CompareRequest sampleRequest() { return test::sampleCompareRequest("auto"); }

TEST(Calibrate, CalibratedStylesLowerTheCityObjectiveAndTheSessionReproducesThem) {
  const CompareRequest request = sampleRequest();
  const Calibration c = calibrate(request);
  const std::size_t n = c.board.observed->analysis.blocks.size();
  ASSERT_EQ(c.blocks.size(), n);
  std::int64_t chosen = 0;
  for (const auto& [style, blocks] : c.stylesChosen) {
    EXPECT_FALSE(generation::choosesPerBlock(generation::style(style))) << style;
    chosen += blocks;
  }
  EXPECT_EQ(chosen, static_cast<std::int64_t>(n));
  std::set<std::string> concrete;
  for (const generation::Style* s : generation::styles()) {
    if (!generation::choosesPerBlock(*s)) concrete.insert(s->name());
  }
  std::vector<std::size_t> after(n), all(n);
  for (std::size_t b = 0; b < n; ++b) {
    const BlockCalibration& bc = c.blocks[b];
    all[b] = b;
    EXPECT_TRUE(concrete.count(bc.styleAfter)) << bc.styleAfter;
    EXPECT_TRUE(concrete.count(bc.stylePredicted)) << bc.stylePredicted;
    EXPECT_TRUE(bc.styleBefore == "obb" || bc.styleBefore == "skeleton") << bc.styleBefore;
    for (std::size_t e = 0; e < c.board.entries.size(); ++e) {
      if (c.board.entries[e].style == bc.styleAfter) after[b] = e;
    }
  }
  // Never worse than the paper's rule city-wide, and no single block's style
  // change would lower the objective further (the refinement's fixed point,
  // or its last pass).
  const double objective = calibrationObjective(c.after, c.before);
  EXPECT_NEAR(cityObjective(c.after), cityObjective(fitMeasures(c.board, all, after)), 1e-12);
  EXPECT_LE(objective, cityObjective(c.before) + 1e-12);
  int improvable = 0;
  for (std::size_t b = 0; b < n; ++b) {
    for (std::size_t e = 0; e < c.board.entries.size(); ++e) {
      if (generation::choosesPerBlock(generation::style(c.board.entries[e].style))) continue;
      std::vector<std::size_t> changed = after;
      changed[b] = e;
      improvable += calibrationObjective(fitMeasures(c.board, all, changed), c.before) < objective - 1e-9;
    }
  }
  EXPECT_EQ(improvable, 0);
  // The total count error: every generated parcel against every observed one.
  std::size_t observedParcels = 0;
  for (const auto& block : c.board.observed->analysis.blocks) observedParcels += block.parcels.size();
  const auto generatedParcels = static_cast<double>(generatedMetrics(c.board, after).size());
  EXPECT_NEAR(c.after.totalCountError, std::fabs(generatedParcels / static_cast<double>(observedParcels) - 1), 1e-12);
  EXPECT_LE(c.after.totalCountError, c.before.totalCountError + 0.05);
  for (const FitMeasures& f : {c.before, c.after}) {
    EXPECT_NEAR(cityObjective(f), f.ksArea + f.ksWidth + f.ksAspectRatio + f.medianCountError + f.totalCountError,
                1e-12);
  }
  // No worse than any of its starts: each block's style of least distance, of
  // least count error, and the paper's rule.
  std::vector<std::size_t> nearest(n), counted(n);
  for (std::size_t b = 0; b < n; ++b) {
    auto cmp = [&](std::size_t e) -> const analysis::Comparison& {
      return c.board.entries[e].result.blocks[b].comparison;
    };
    auto count = [&](std::size_t e) {
      return std::fabs(static_cast<double>(cmp(e).generated.parcels) /
                           static_cast<double>(std::max<std::int64_t>(1, cmp(e).observed.parcels)) -
                       1);
    };
    std::vector<std::size_t> concreteEntries;
    for (std::size_t e = 0; e < c.board.entries.size(); ++e) {
      if (!generation::choosesPerBlock(generation::style(c.board.entries[e].style))) concreteEntries.push_back(e);
    }
    nearest[b] = concreteEntries.front();
    for (std::size_t e : concreteEntries) {
      if (calibrationDistance(cmp(e)) < calibrationDistance(cmp(nearest[b]))) nearest[b] = e;
    }
    counted[b] = nearest[b];  // ties in count: least distance
    for (std::size_t e : concreteEntries) {
      if (count(e) < count(counted[b]) ||
          (count(e) == count(counted[b]) && calibrationDistance(cmp(e)) < calibrationDistance(cmp(counted[b])))) {
        counted[b] = e;
      }
    }
  }
  EXPECT_LE(objective, calibrationObjective(fitMeasures(c.board, all, nearest), c.before) + 1e-12);
  EXPECT_LE(objective, calibrationObjective(fitMeasures(c.board, all, counted), c.before) + 1e-12);
  EXPECT_LE(objective, calibrationObjective(fitMeasures(c.board, all, c.entryBefore), c.before) + 1e-12);
  // The session file gives, through compare, the measures calibrate reports.
  test::TempDir dir;
  const std::string out = dir.file("calibrated");
  runCalibrate(request, out);
  for (const char* f : {"session.json", "calibration.csv", "leaderboard.csv", "run.json"}) {
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
  }
  CompareRequest session = readSession(out + "/session.json");
  session.parameters["figures"] = 0;
  EXPECT_EQ(session.overrides.size(), n);
  const CompareResult r = compare(session);
  EXPECT_NEAR(r.city.area.ks, c.after.ksArea, 1e-12);
  EXPECT_NEAR(r.city.width.ks, c.after.ksWidth, 1e-12);
  EXPECT_NEAR(r.city.aspectRatio.ks, c.after.ksAspectRatio, 1e-12);
  EXPECT_EQ(calibrationTable(c).rows.size(), n);
}

// The search's KS of a swap is ksStatistic of the swapped sample, to the
// bit: random samples on a coarse grid of values (many ties, within and
// across the samples), values swapped out and in, and swaps that empty the
// pooled sample.
TEST(Calibrate, TheSearchsSwappedKsIsTheKsOfTheSwappedSample) {
  std::mt19937_64 rng(20261128);
  int compared = 0;
  for (int t = 0; t < 400; ++t) {
    const int levels = 2 + static_cast<int>(rng() % 40);
    auto draw = [&](std::size_t n) {
      std::vector<double> v(n);
      for (double& x : v) x = 0.25 * static_cast<double>(rng() % static_cast<unsigned>(levels));
      std::sort(v.begin(), v.end());
      return v;
    };
    const std::vector<double> observed = draw(rng() % 60), pooled = draw(1 + rng() % 80);
    std::vector<double> out, in = draw(rng() % 12);
    for (double x : pooled) {
      if (rng() % 4 == 0 || t % 50 == 0) out.push_back(x);  // every 50th: all swapped out
    }
    std::vector<double> swapped;
    std::set_difference(pooled.begin(), pooled.end(), out.begin(), out.end(), std::back_inserter(swapped));
    swapped.insert(swapped.end(), in.begin(), in.end());
    std::sort(swapped.begin(), swapped.end());
    const double expected = observed.empty() || swapped.empty() ? NAN : analysis::ksStatistic(observed, swapped);
    const double got = detail::SwappedKs(observed, pooled)(out, in);
    if (std::isnan(expected)) {
      EXPECT_TRUE(std::isnan(got)) << "case " << t;
    } else {
      EXPECT_EQ(got, expected) << "case " << t;
      ++compared;
    }
  }
  EXPECT_GT(compared, 300);
}

TEST(Calibrate, TheCrossValidatedRuleIsMeasuredOnTheHalfItWasNotFittedOn) {
  // On the sample, the halves differ: a rule that only memorised each block's
  // best style would score as `after`; the predicted styles are those of
  // nearest neighbours in the other half.
  const Calibration c = calibrate(sampleRequest());
  int halves[2] = {0, 0};
  for (const BlockCalibration& b : c.blocks) ++halves[b.half];
  EXPECT_GT(halves[0], 0);
  EXPECT_GT(halves[1], 0);
  EXPECT_EQ(c.crossFitted.blocks, static_cast<std::int64_t>(c.blocks.size()));
  EXPECT_EQ(c.crossPaper.ksArea, c.before.ksArea);
  // Every predicted style is the style some block of the other half got from
  // that half's own calibration.
  for (const BlockCalibration& b : c.blocks) {
    bool seen = false;
    for (const BlockCalibration& o : c.blocks) seen = seen || (o.half != b.half && o.styleHalf == b.stylePredicted);
    EXPECT_TRUE(seen) << b.blockId;
  }
}

TEST(Calibrate, TheAutoRuleReadsTheFeaturesCalibrationWritesAndPicksWhatCompareRuns) {
  const Calibration c = calibrate(sampleRequest());
  // A rule trained on this calibration's own labels picks, for each block,
  // the style of the nearest training blocks; measured through the board it
  // is what compare gives for those styles.
  std::vector<generation::AutoRule::Row> rows;
  for (const BlockCalibration& b : c.blocks) rows.push_back({b.features, b.styleAfter});
  const generation::AutoRule oneNeighbour(rows, 1);
  std::vector<std::size_t> all(c.blocks.size());
  std::iota(all.begin(), all.end(), 0);
  const std::vector<std::size_t> picked = entriesOf(c, oneNeighbour);
  for (std::size_t b = 0; b < c.blocks.size(); ++b) {
    EXPECT_EQ(c.board.entries[picked[b]].style, c.blocks[b].styleAfter) << "block " << c.blocks[b].blockId;
  }
  EXPECT_NEAR(cityObjective(fitMeasures(c.board, all, picked)), cityObjective(c.after), 1e-12);
  // The auto entry is the bundled rule's choice on every block.
  for (const BlockCalibration& b : c.blocks) {
    EXPECT_EQ(b.styleAuto, generation::AutoRule::bundled().predict(b.features)) << "block " << b.blockId;
  }
  // calibration.csv holds the features under the names the rule's table reads.
  const Table t = calibrationTable(c);
  for (const char* name : generation::autoFeatureNames()) EXPECT_NO_THROW(t.column(name)) << name;
}

}  // namespace
}  // namespace parcelscope::pipeline
