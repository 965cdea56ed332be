// `parcelscope inspect`: the parcel at a point, its metrics (every entry of the
// metric registry) and its block's statistics, as lines or JSON; one-line errors.
#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <string>

#include "cli/CliRun.h"
#include "parcelscope/analysis/Comparison.h"

namespace parcelscope {
namespace {

using test::CliRun;

const std::string kSample = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
// Inside the sample's first feature (S-0001, a rectangle of block 0).
const std::string kInside = "-71.10245,42.36849";

std::map<std::string, std::string> lines(const std::string& output) {
  std::map<std::string, std::string> out;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);) {
    const std::size_t colon = line.find(": ");
    if (colon != std::string::npos) out[line.substr(0, colon)] = line.substr(colon + 2);
  }
  return out;
}

TEST(InspectCommand, PrintsTheParcelItsMetricsAndItsBlock) {
  const CliRun r = test::runCli("inspect '" + kSample + "' --where \"use <> 'ROW'\" --at " + kInside);
  ASSERT_EQ(r.code, 0) << r.output;
  const auto values = lines(r.output);
  EXPECT_EQ(values.at("file"), kSample);
  EXPECT_EQ(values.at("source_fid"), "0");
  EXPECT_EQ(values.at("role"), "lot");
  EXPECT_EQ(values.at("parcel_key").size(), 16u);
  for (const auto& q : analysis::parcelMetrics()) EXPECT_TRUE(values.count(q.name)) << q.name << "\n" << r.output;
  // About 24.1 m by 40.2 m (0.000293 degrees of longitude, 0.000362 of latitude at 42.37 N).
  EXPECT_NEAR(std::stod(values.at("area")), 970, 25);
  EXPECT_EQ(values.at("block.block_id"), values.at("block_id"));
  for (const char* s : {"block.parcel_count", "block.mean_area", "block.w_max", "block.street_access_share"}) {
    EXPECT_TRUE(values.count(s)) << s;
  }
  EXPECT_GT(std::stoi(values.at("block.parcel_count")), 1);
}

TEST(InspectCommand, JsonHoldsTheSameValues) {
  const CliRun lined = test::runCli("inspect '" + kSample + "' --where \"use <> 'ROW'\" --at " + kInside);
  const CliRun json = test::runCli("inspect '" + kSample + "' --where \"use <> 'ROW'\" --at " + kInside + " --json");
  ASSERT_EQ(json.code, 0) << json.output;
  const auto values = lines(lined.output);
  EXPECT_NE(json.output.find("\"parcel_key\": \"" + values.at("parcel_key") + "\""), std::string::npos) << json.output;
  EXPECT_NE(json.output.find("\"metrics\""), std::string::npos);
  EXPECT_NE(json.output.find("\"mean_area\""), std::string::npos);
  EXPECT_EQ(json.output.front(), '{');
}

TEST(InspectCommand, NoParcelThereIsOneLineNamingTheFile) {
  const CliRun r = test::runCli("inspect '" + kSample + "' --at -71.5,42.0");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << r.output;
  EXPECT_NE(r.output.find("sample_town.geojson"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no parcel at -71.5,42"), std::string::npos) << r.output;
}

TEST(InspectCommand, UsageErrors) {
  EXPECT_EQ(test::runCli("inspect '" + kSample + "'").code, 2);  // no --at
  EXPECT_EQ(test::runCli("inspect --at 1,2").code, 2);           // no INPUT
  const CliRun r = test::runCli("inspect '" + kSample + "' --at '1;2'");
  EXPECT_EQ(r.code, 2) << r.output;
  const CliRun bad = test::runCli("inspect '" + kSample + "' --at 1,2x");
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--at 1,2x is not X,Y"), std::string::npos) << bad.output;
  EXPECT_EQ(test::runCli("inspect --help").code, 0);
}

TEST(InspectCommand, AMissingFileIsOneLineNamingIt) {
  const CliRun r = test::runCli("inspect /nonexistent/parcels.gpkg --at 1,2");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/parcels.gpkg"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace parcelscope
