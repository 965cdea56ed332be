// The command line as a user runs it: exit codes, one-line errors, and outputs
// that appear whole or not at all.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "TestUtil.h"
#include "cli/CliRun.h"

namespace parcelscope {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

using test::CliRun;
using test::slurp;

CliRun run(const std::string& args) { return test::runCli(args); }

const std::string kSample = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";

TEST(StatsCommand, WritesAllOutputsForTheBundledSample) {
  TempDir dir;
  const std::string out = dir.file("out");
  const CliRun r = run("stats '" + kSample + "' --where \"use <> 'ROW'\" --out '" + out + "' --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* f : {"parcels.csv", "blocks.csv", "blocks.gpkg", "run.json"}) {
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  }
  std::ifstream blocks(out + "/blocks.csv");
  std::string header, line;
  std::getline(blocks, header);
  EXPECT_EQ(header.rfind("block_id,parcel_count,block_area", 0), 0u) << header;
  int rows = 0;
  while (std::getline(blocks, line)) ++rows;
  EXPECT_EQ(rows, 10);  // the sample town has ten blocks (datasets/README.md)
  std::stringstream json;
  json << std::ifstream(out + "/run.json").rdbuf();
  for (const char* key : {"\"version\"", "\"duplicates_collapsed\": 3", "\"invalid_repaired\": 1",
                          "\"null_or_empty_skipped\": 1", "\"block-tolerance\""}) {
    EXPECT_NE(json.str().find(key), std::string::npos) << key << " in " << json.str();
  }
}

TEST(StatsCommand, UsageErrorsExitTwo) {
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("frobnicate").code, 2);
  EXPECT_EQ(run("stats '" + kSample + "'").code, 2);  // no --out
  const CliRun r = run("stats '" + kSample + "' --out /tmp/x --k -1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--k"), std::string::npos) << r.output;
  EXPECT_EQ(run("stats --help").code, 0);
}

TEST(StatsCommand, BadInputFailsWithOneLineNamingTheFileAndLeavesNoOutput) {
  TempDir dir;
  const std::string out = dir.file("out");
  const CliRun missing = run("stats '" + dir.file("nope.geojson") + "' --out '" + out + "' --quiet");
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.output.find("nope.geojson"), std::string::npos) << missing.output;
  EXPECT_EQ(std::count(missing.output.begin(), missing.output.end(), '\n'), 1) << missing.output;
  EXPECT_FALSE(fs::exists(out));
  // Nothing else was left behind (no staging folder).
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 0);

  const auto garbage = dir.write("bad.json", "{ nope");
  const CliRun bad = run("stats '" + garbage + "' --out '" + out + "' --quiet");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.output.find("bad.json"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(out));

  const CliRun crs = run("stats '" + kSample + "' --crs EPSG:99999999 --out '" + out + "' --quiet");
  EXPECT_EQ(crs.code, 2) << crs.output;
  EXPECT_NE(crs.output.find("EPSG:99999999"), std::string::npos) << crs.output;
}

TEST(StatsCommand, RefusesToWriteOverTheInput) {
  TempDir dir;
  const auto input = dir.file("parcels.csv");
  fs::copy_file(kSample, input);
  const auto before = fs::file_size(input);
  // The input is named parcels.csv inside the output folder: it must not be replaced.
  const CliRun r = run("stats '" + input + "' --out '" + dir.path().string() + "' --quiet");
  EXPECT_NE(r.code, 0) << r.output;
  EXPECT_EQ(fs::file_size(input), before);
}

TEST(GenerateCommand, FromParcelsWritesParcelsAndIsReproducibleFromTheSeed) {
  TempDir dir;
  const std::string base = "generate '" + kSample + "' --where \"use <> 'ROW'\" --from-parcels --style obb --quiet";
  const CliRun a = run(base + " --seed 7 --out '" + dir.file("a") + "'");
  ASSERT_EQ(a.code, 0) << a.output;
  for (const char* f : {"parcels.gpkg", "parcels.csv", "run.json"}) {
    EXPECT_TRUE(fs::exists(dir.file("a") + "/" + f)) << f;
  }
  const std::string csv = slurp(dir.file("a") + "/parcels.csv");
  EXPECT_EQ(csv.rfind("parcel_id,block_id,area,perimeter,width", 0), 0u) << csv.substr(0, 80);
  EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 100);
  const std::string json = slurp(dir.file("a") + "/run.json");
  EXPECT_NE(json.find("\"blocks_failed\": 0"), std::string::npos) << json;
  EXPECT_NE(json.find("\"seed\": 7"), std::string::npos) << json;

  ASSERT_EQ(run(base + " --seed 7 --out '" + dir.file("b") + "'").code, 0);
  EXPECT_EQ(slurp(dir.file("b") + "/parcels.csv"), csv);
  ASSERT_EQ(run(base + " --seed 8 --out '" + dir.file("c") + "'").code, 0);
  EXPECT_NE(slurp(dir.file("c") + "/parcels.csv"), csv);
}

TEST(GenerateCommand, SubdividesTheBlocksThatStatsWrote) {
  TempDir dir;
  ASSERT_EQ(run("stats '" + kSample + "' --where \"use <> 'ROW'\" --out '" + dir.file("s") + "' --quiet").code, 0);
  const CliRun g = run("generate '" + dir.file("s") + "/blocks.gpkg' --out '" + dir.file("g") + "' --quiet");
  ASSERT_EQ(g.code, 0) << g.output;
  const std::string json = slurp(dir.file("g") + "/run.json");
  EXPECT_NE(json.find("\"blocks\": 10"), std::string::npos) << json;
}

TEST(GenerateCommand, SkeletonOffsetAndAutoStylesRunOnTheSample) {
  TempDir dir;
  const std::string base = "generate '" + kSample + "' --where \"use <> 'ROW'\" --from-parcels --quiet --seed 3";
  for (const char* style : {"skeleton", "offset", "auto"}) {
    const std::string out = dir.file(style);
    const CliRun r = run(base + " --style " + style + " --out '" + out + "'");
    ASSERT_EQ(r.code, 0) << style << ": " << r.output;
    const std::string json = slurp(out + "/run.json");
    EXPECT_NE(json.find("\"style\": \"" + std::string(style) + "\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"blocks\": 10"), std::string::npos) << json;
    EXPECT_NE(json.find("\"parcels_without_street_access\": 0"), std::string::npos) << json;
    EXPECT_NE(json.find("\"blocks_by_style\""), std::string::npos) << json;
    if (std::string(style) == "offset") {
      EXPECT_EQ(json.find("\"patio_parcels\": 0,"), std::string::npos) << "the sample's big blocks get patios: " << json;
    } else {
      EXPECT_NE(json.find("\"patio_parcels\": 0"), std::string::npos) << json;
    }
  }
  // Reproducible from the seed.
  ASSERT_EQ(run(base + " --style skeleton --out '" + dir.file("again") + "'").code, 0);
  EXPECT_EQ(slurp(dir.file("again") + "/parcels.csv"), slurp(dir.file("skeleton") + "/parcels.csv"));
}

TEST(GenerateCommand, BadStyleAndConflictingBoundsAreUsageErrors) {
  TempDir dir;
  EXPECT_EQ(run("generate '" + kSample + "' --style voronoi --out '" + dir.file("x") + "' --quiet").code, 2);
  const CliRun r = run("generate '" + kSample + "' --a-min 900 --a-max 100 --out '" + dir.file("x") + "' --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_EQ(run("generate '" + kSample + "' --a-max 0 --out '" + dir.file("x") + "' --quiet").code, 2);
  EXPECT_FALSE(fs::exists(dir.file("x")));
}

}  // namespace
}  // namespace parcelscope
