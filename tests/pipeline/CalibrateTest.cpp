// calibrate: each block gets the style closest to its observed parcels, the
// session file reproduces exactly what was measured, and the cross-validated
// rule is measured on blocks it was not fitted on.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "SampleRequest.h"
#include "TestUtil.h"
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
    EXPECT_NE(style, "auto");
    chosen += blocks;
  }
  EXPECT_EQ(chosen, static_cast<std::int64_t>(n));
  std::set<std::string> concrete;
  for (const generation::Style* s : generation::styles()) {
    if (s != &generation::autoStyle()) concrete.insert(s->name());
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
  const double objective = cityObjective(c.after);
  EXPECT_NEAR(objective, cityObjective(fitMeasures(c.board, all, after)), 1e-12);
  EXPECT_LE(objective, cityObjective(c.before) + 1e-12);
  int improvable = 0;
  for (std::size_t b = 0; b < n; ++b) {
    for (std::size_t e = 0; e < c.board.entries.size(); ++e) {
      if (c.board.entries[e].style == "auto") continue;
      std::vector<std::size_t> changed = after;
      changed[b] = e;
      improvable += cityObjective(fitMeasures(c.board, all, changed)) < objective - 1e-9;
    }
  }
  EXPECT_EQ(improvable, 0);
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

}  // namespace
}  // namespace parcelscope::pipeline
