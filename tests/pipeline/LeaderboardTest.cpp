// compare --style all: every style on the same blocks, each entry what a
// compare of that style alone gives, the best style of each block the one of
// least fit, and the tables and run record written whole.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "SampleRequest.h"
#include "TestUtil.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/pipeline/Leaderboard.h"

namespace parcelscope::pipeline {
namespace {

CompareRequest sampleRequest() { return test::sampleCompareRequest("all"); }

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
      const analysis::ParcelMetrics &m = e.result.generated.metrics[i], &f = fresh.generated.metrics[i];
      EXPECT_TRUE(m.area == f.area && m.width == f.width && m.aspectRatio == f.aspectRatio &&
                  m.frontage == f.frontage && m.neighbours == f.neighbours && m.streetAccess == f.streetAccess)
          << e.style << " " << i;
    }
    // The styles that choose per block take the concrete styles' outcomes
    // where their plans are the same: auto's plans are theirs on every block.
    EXPECT_EQ(fresh.generated.reusedBlocks, 0) << e.style;
    if (e.style == "auto") {
      EXPECT_EQ(e.result.generated.reusedBlocks, static_cast<std::int64_t>(e.result.generated.blocks.size()));
    } else if (!generation::choosesPerBlock(generation::style(e.style))) {
      EXPECT_EQ(e.result.generated.reusedBlocks, 0) << e.style;
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
    } else if (board.entries[e].style == "auto") {  // parish on the blocks it picks parish for
      EXPECT_GE(share, 0.0);
      EXPECT_LT(share, 1.0);
    } else {
      EXPECT_EQ(share, 0.0) << board.entries[e].style;
    }
  }
}

// Yang et al. 2013's section 7 measures: the land shares add up, densities
// are counts over the study area, and the street measures come with streets.
TEST(Leaderboard, LayoutMeasuresAddUpOverTheStudyArea) {
  CompareRequest request = sampleRequest();
  request.streets = io::StreetReadOptions{};
  request.streets->path = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_streets.geojson";
  request.streets->widthField = "width";
  const Leaderboard board = leaderboard(request);
  const std::vector<LayoutMeasures> rows = layoutRows(board);
  ASSERT_EQ(rows.size(), board.entries.size() + 1);
  const LayoutContext c = layoutContext(*board.observed);
  ASSERT_GT(c.streetArea, 0);
  EXPECT_NEAR(c.studyArea, c.blockArea + c.streetArea, 1e-6 * c.studyArea);
  EXPECT_GT(c.intersections, 0);
  for (const LayoutMeasures& m : rows) {
    EXPECT_NEAR(m.streetShare + m.parcelShare + m.otherShare, 100.0, 1e-6) << m.layout;
    EXPECT_GT(m.streetShare, 0) << m.layout;
    EXPECT_NEAR(m.blocksPerKm2, static_cast<double>(board.observed->analysis.blocks.size()) / (c.studyArea / 1e6),
                1e-9 * m.blocksPerKm2);
    EXPECT_LE(m.boundaryMin, m.boundaryAvg);
    EXPECT_LE(m.boundaryAvg, m.boundaryMax);
    EXPECT_GT(m.streetLengthPerKm2, 0) << m.layout;
    EXPECT_GE(m.meanPArea, 1.0) << m.layout;  // a parcel never fills more than its box
  }
  const auto& blockOf = board.observed->analysis.blockOf;
  const auto lots = static_cast<double>(std::count_if(blockOf.begin(), blockOf.end(), [](int b) { return b >= 0; }));
  EXPECT_NEAR(rows[0].parcelsPerKm2 * c.studyArea / 1e6, lots, 1e-6 * lots);
  for (std::size_t e = 0; e < board.entries.size(); ++e) {
    const GeneratedParcels& g = board.entries[e].result.generated;
    const double assigned = static_cast<double>(g.parcels.size()) - static_cast<double>(g.unassignedParcels);
    EXPECT_NEAR(rows[e + 1].parcelsPerKm2 * c.studyArea / 1e6, assigned, 1e-6 * assigned) << board.entries[e].style;
    // Generated parcels tile the blocks: only parish leaves block land to no
    // parcel (also where access or auto picks it for a block).
    EXPECT_NEAR(rows[e + 1].otherShare, 100 * g.unassignedArea / c.studyArea, 1e-6) << board.entries[e].style;
    if (board.entries[e].style == "parish") {
      EXPECT_GT(rows[e + 1].otherShare, 1.0);
    } else if (!generation::choosesPerBlock(generation::style(board.entries[e].style))) {
      EXPECT_LT(rows[e + 1].otherShare, 1e-6) << board.entries[e].style;
    }
  }
}

TEST(Leaderboard, WritesItsTablesAndRunRecordWhole) {
  test::TempDir dir;
  const std::string out = dir.file("board");
  runLeaderboard(sampleRequest(), out);
  for (const char* f : {"leaderboard.csv", "leaderboard_blocks.csv", "layout.csv", "run.json"}) {
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
