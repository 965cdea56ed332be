// compare --style all: every style on the same blocks, each entry what a
// compare of that style alone gives, the best style of each block the one of
// least fit, and the tables and run record written whole.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "TestUtil.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/pipeline/Leaderboard.h"

namespace parcelscope::pipeline {
namespace {

CompareRequest sampleRequest() {
  CompareRequest r;
  r.input.path = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
  r.input.where = "use <> 'ROW'";
  r.style = "all";
  r.parameters = defaultValues(compareParameters());
  r.parameters["figures"] = 0;
  return r;
}

TEST(Leaderboard, EachStyleIsWhatItsOwnCompareGivesAndEachBlockGetsItsBestFit) {
  const CompareRequest request = sampleRequest();
  const Leaderboard board = leaderboard(request);
  ASSERT_EQ(board.entries.size(), generation::styles().size());
  for (const LeaderboardEntry& e : board.entries) {
    CompareRequest alone = request;
    alone.style = e.style;
    const CompareResult fresh = compare(alone);
    ASSERT_EQ(e.result.generated.parcels.size(), fresh.generated.parcels.size()) << e.style;
    for (std::size_t i = 0; i < fresh.generated.parcels.size(); ++i) {
      ASSERT_TRUE(sameVertices(e.result.generated.parcels[i], fresh.generated.parcels[i])) << e.style << " " << i;
    }
    EXPECT_EQ(e.result.city.area.ks, fresh.city.area.ks) << e.style;
    EXPECT_EQ(fitScore(e.result.city), fresh.city.area.ks + fresh.city.width.ks + fresh.city.aspectRatio.ks) << e.style;
  }
  const std::size_t blocks = board.observed->analysis.blocks.size();
  ASSERT_EQ(board.blockFit.size(), blocks);
  for (std::size_t b = 0; b < blocks; ++b) {
    const auto& fit = board.blockFit[b];
    const auto best = static_cast<std::size_t>(board.bestEntry[b]);
    EXPECT_EQ(fit[best], *std::min_element(fit.begin(), fit.end())) << "block " << b;
    EXPECT_EQ(best, static_cast<std::size_t>(std::min_element(fit.begin(), fit.end()) - fit.begin()));
  }
  const Table t = leaderboardTable(board);
  ASSERT_EQ(t.rows.size(), board.entries.size());
  std::int64_t bestTotal = 0;
  for (const auto& row : t.rows) bestTotal += std::get<std::int64_t>(row[t.column("blocks_best")]);
  EXPECT_EQ(bestTotal, static_cast<std::int64_t>(blocks));
  EXPECT_EQ(leaderboardBlockTable(board).rows.size(), blocks);
}

// parish leaves lots without street access unassigned: they are written with
// their role, counted in the leaderboard, and kept out of every comparison.
TEST(Leaderboard, UnassignedLandIsCountedAndWrittenButNotCompared) {
  CompareRequest request = sampleRequest();
  request.style = "parish";
  const CompareResult r = compare(request);
  const GeneratedParcels& g = r.generated;
  ASSERT_GT(g.unassignedParcels, 0);
  ASSERT_EQ(g.unassigned.size(), g.parcels.size());
  std::int64_t flagged = 0;
  double flaggedArea = 0;
  for (std::size_t i = 0; i < g.parcels.size(); ++i) {
    flagged += g.unassigned[i];
    if (g.unassigned[i]) flaggedArea += area(g.parcels[i]);
    if (g.unassigned[i]) EXPECT_FALSE(g.metrics[i].streetAccess) << i;  // no access is why it was left
  }
  EXPECT_EQ(flagged, g.unassignedParcels);
  EXPECT_NEAR(flaggedArea, g.unassignedArea, 1e-6 * flaggedArea);
  EXPECT_EQ(r.city.generated.parcels, static_cast<std::int64_t>(g.parcels.size()) - g.unassignedParcels);
  EXPECT_EQ(r.city.generated.streetAccessShare, 1.0);
  std::int64_t compared = 0;
  for (const auto& b : r.blocks) compared += b.comparison.generated.parcels;
  EXPECT_EQ(compared, r.city.generated.parcels);
  const Table t = generatedParcelTable(g);
  std::int64_t written = 0;
  for (const auto& row : t.rows) written += std::get<std::string>(row[t.column("role")]) == "unassigned";
  EXPECT_EQ(written, g.unassignedParcels);

  request.style = "all";
  const Leaderboard board = leaderboard(request);
  const Table lt = leaderboardTable(board);
  for (std::size_t e = 0; e < board.entries.size(); ++e) {
    const double share = std::get<double>(lt.rows[e][lt.column("unassigned_share")]);
    if (board.entries[e].style == "parish") {
      EXPECT_GT(share, 0.0);
      EXPECT_LT(share, 1.0);
    } else {
      EXPECT_EQ(share, 0.0) << board.entries[e].style;
    }
  }
}

TEST(Leaderboard, WritesItsTablesAndRunRecordWhole) {
  test::TempDir dir;
  const std::string out = dir.file("board");
  runLeaderboard(sampleRequest(), out);
  for (const char* f : {"leaderboard.csv", "leaderboard_blocks.csv", "run.json"}) {
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
  }
  const std::string csv = test::slurpFile(out + "/leaderboard.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), static_cast<long>(generation::styles().size()) + 1);
  EXPECT_EQ(csv.rfind("style,parcels,count_ratio,ks_area,ks_width,ks_aspect_ratio", 0), 0u);
  const std::string record = test::slurpFile(out + "/run.json");
  EXPECT_NE(record.find("\"style\": \"all\""), std::string::npos);
  EXPECT_NE(record.find("\"seconds_per_style\""), std::string::npos);
}

}  // namespace
}  // namespace parcelscope::pipeline
