// The command line as a user runs it: exit codes, one-line errors, and outputs
// that appear whole or not at all.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "OgrTestUtil.h"
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

// Rows of a CSV table, its header left out.
std::int64_t csvRows(const std::string& path) {
  const std::string csv = slurp(path);
  const auto lines = std::count(csv.begin(), csv.end(), '\n');
  return lines > 0 ? lines - 1 : 0;
}

// The parcels a generate run wrote to `out`, read back with GDAL: one feature
// per row of parcels.csv, each a valid polygon of positive area, with the
// documented fields, in the input's CRS.
test::ReadLayer writtenParcels(const std::string& out) {
  const OGRSpatialReference crs = test::layerCrs(kSample);
  EXPECT_FALSE(crs.IsEmpty());
  return test::expectValidPolygonLayer(
      out + "/parcels.gpkg", csvRows(out + "/parcels.csv"),
      {"parcels", {"parcel_id", "parcel_key", "block_id", "block_key", "area", "width", "aspect_ratio"}, &crs});
}

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
  EXPECT_EQ(header.rfind("block_id,block_key,parcel_count,block_area", 0), 0u) << header;
  int rows = 0;
  while (std::getline(blocks, line)) ++rows;
  EXPECT_EQ(rows, 10);  // the sample town has ten blocks (datasets/README.md)
  // The block outlines read back: one valid polygon of positive area per row,
  // in the input's CRS, each of the area blocks.csv gives it (in m2, the
  // layer's degrees are not comparable: compared by share of the total).
  const OGRSpatialReference crs = test::layerCrs(kSample);
  const test::ReadLayer layer = test::expectValidPolygonLayer(
      out + "/blocks.gpkg", rows, {"blocks", {"block_id", "block_key", "parcel_count", "block_area"}, &crs});
  double total = 0;
  for (const auto& f : layer.features) total += f->GetFieldAsDouble("block_area");
  double totalDeg = 0;
  std::vector<double> deg;
  for (const auto& parts : layer.geometries) {
    double a = 0;
    for (const Polygon& p : parts) a += area(p);
    deg.push_back(a);
    totalDeg += a;
  }
  for (std::size_t i = 0; i < deg.size(); ++i) {
    EXPECT_NEAR(deg[i] / totalDeg, layer.features[i]->GetFieldAsDouble("block_area") / total, 1e-3)
        << "block feature " << layer.features[i]->GetFID();
  }
  std::stringstream json;
  json << std::ifstream(out + "/run.json").rdbuf();
  for (const char* key : {"\"version\"", "\"duplicates_collapsed\": 3", "\"invalid_repaired\": 1",
                          "\"null_or_empty_skipped\": 1", "\"block-tolerance\""}) {
    EXPECT_NE(json.str().find(key), std::string::npos) << key << " in " << json.str();
  }
}

// Lon/lat parcels 500 km apart are measured in one transverse Mercator (centred
// on the median parcel): the summary warns that areas far from its centre line
// are too large, by how much; a town's parcels get no such warning.
TEST(StatsCommand, AWideLonLatLayerIsWarnedOfItsAreaError) {
  TempDir dir;
  const std::string wide = dir.file("wide.geojson");
  std::ofstream(wide) << R"({"type": "FeatureCollection", "features": [
    {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates":
      [[[2.35, 48.85], [2.3505, 48.85], [2.3505, 48.8505], [2.35, 48.8505], [2.35, 48.85]]]}},
    {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates":
      [[[2.3505, 48.8505], [2.351, 48.8505], [2.351, 48.851], [2.3505, 48.851], [2.3505, 48.8505]]]}},
    {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates":
      [[[-4.48, 48.39], [-4.4795, 48.39], [-4.4795, 48.3905], [-4.48, 48.3905], [-4.48, 48.39]]]}}]})";
  const CliRun r = run("stats '" + wide + "' --out '" + dir.file("w") + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  // Brest lies about 505 km west of Paris's meridian: areas (505 / 6371)^2 = 0.63 % too large.
  EXPECT_NE(r.output.find("areas up to 0.63 % too large 506 km from its centre line"), std::string::npos) << r.output;
  const CliRun town = run("stats '" + kSample + "' --out '" + dir.file("t") + "'");
  ASSERT_EQ(town.code, 0) << town.output;
  EXPECT_EQ(town.output.find("transverse Mercator"), std::string::npos) << town.output;
}

TEST(StatsCommand, UsageErrorsExitTwo) {
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("frobnicate").code, 2);
  EXPECT_EQ(run("stats '" + kSample + "'").code, 2);  // no --out
  TempDir dir;
  const CliRun r = run("stats '" + kSample + "' --out '" + dir.file("x") + "' --k -1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--k"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir.file("x")));
  EXPECT_EQ(run("stats --help").code, 0);
  // Bug: `version extra` printed the version and exited 0.
  EXPECT_EQ(run("version").code, 0);
  EXPECT_EQ(run("version --help").code, 0);
  const CliRun v = run("version extra");
  EXPECT_EQ(v.code, 2);
  EXPECT_NE(v.output.find("'extra'"), std::string::npos) << v.output;
}

// The first line of the output (the error; a usage error adds a second line
// pointing to --help).
std::string firstLine(const std::string& output) { return output.substr(0, output.find('\n')); }

TEST(StatsCommand, NumbersOtherThanDecimalAreUsageErrors) {
  TempDir dir;
  for (const char* value : {"0x2", "0X2", "inf", "-infinity", "nan", "0x1p1"}) {
    const CliRun r = run("stats '" + kSample + "' --out '" + dir.file("x") + "' --quiet --k " + value);
    EXPECT_EQ(r.code, 2) << value << ": " << r.output;
    EXPECT_NE(firstLine(r.output).find("--k " + std::string(value) + " is not a decimal number"), std::string::npos)
        << r.output;
  }
  EXPECT_FALSE(fs::exists(dir.file("x")));
  // Decimal numbers in every written form are still taken.
  for (const char* value : {"2", "+2", "2.", "2.0", ".5", "1e-1", "1.5E+0"}) {
    const CliRun r =
        run("stats '" + kSample + "' --out '" + dir.file(std::string("k") + value) + "' --quiet --k " + value);
    EXPECT_EQ(r.code, 0) << value << ": " << r.output;
  }
}

TEST(StatsCommand, ARepeatedFlagIsAUsageErrorNamingIt) {
  TempDir dir;
  const std::string base = "stats '" + kSample + "' --out '" + dir.file("x") + "'";
  const std::vector<std::pair<std::string, std::string>> cases = {{" --k 2 --k 3", "--k"},
                                                                  {" --k=2 --k 2", "--k"},
                                                                  {" --quiet --quiet", "--quiet"},
                                                                  {" --where \"1=1\" --where \"1=0\"", "--where"},
                                                                  {" --out '" + dir.file("y") + "'", "--out"}};
  for (const auto& [repeated, flag] : cases) {
    const CliRun r = run(base + repeated);
    EXPECT_EQ(r.code, 2) << repeated << ": " << r.output;
    EXPECT_NE(firstLine(r.output).find(flag + " is given more than once"), std::string::npos) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir.file("x")));
  EXPECT_FALSE(fs::exists(dir.file("y")));
}

TEST(GenerateCommand, AnOutOfRangeSeedIsPrintedExactly) {
  TempDir dir;
  const CliRun r =
      run("generate '" + kSample + "' --from-parcels --seed 5000000000 --out '" + dir.file("x") + "' --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--seed 5000000000 is outside [0, 4294967295]"), std::string::npos) << r.output;
  const CliRun just =
      run("generate '" + kSample + "' --from-parcels --seed 4294967296 --out '" + dir.file("x") + "' --quiet");
  EXPECT_NE(just.output.find("--seed 4294967296 is outside [0, 4294967295]"), std::string::npos) << just.output;
}

// A named pipe without a writer would block GDAL's open forever; it is refused
// at once. (`timeout` turns a hang into a failure of this test.)
TEST(StatsCommand, ANamedPipeIsRefusedInsteadOfBlocking) {
  TempDir dir;
  const std::string fifo = dir.file("parcels.geojson");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const CliRun r = test::runShell("timeout 30 '" + std::string(PARCELSCOPE_CLI) + "' stats '" + fifo + "' --out '" +
                                  dir.file("out") + "' --quiet");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find(fifo), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("is a named pipe"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir.file("out")));
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
  EXPECT_EQ(csv.rfind("parcel_id,parcel_key,block_id,block_key,role,area,perimeter,width", 0), 0u) << csv.substr(0, 80);
  EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 100);
  const std::string json = slurp(dir.file("a") + "/run.json");
  EXPECT_NE(json.find("\"blocks_failed\": 0"), std::string::npos) << json;
  EXPECT_NE(json.find("\"seed\": 7"), std::string::npos) << json;

  const test::ReadLayer a7 = writtenParcels(dir.file("a"));
  ASSERT_GT(a7.geometries.size(), 100u);

  // The same seed: the same parcels, vertex for vertex; another seed: others.
  ASSERT_EQ(run(base + " --seed 7 --out '" + dir.file("b") + "'").code, 0);
  EXPECT_EQ(slurp(dir.file("b") + "/parcels.csv"), csv);
  EXPECT_TRUE(test::sameGeometries(writtenParcels(dir.file("b")), a7));
  ASSERT_EQ(run(base + " --seed 8 --out '" + dir.file("c") + "'").code, 0);
  EXPECT_NE(slurp(dir.file("c") + "/parcels.csv"), csv);
  EXPECT_FALSE(test::sameGeometries(writtenParcels(dir.file("c")), a7));
}

TEST(GenerateCommand, SubdividesTheBlocksThatStatsWrote) {
  TempDir dir;
  ASSERT_EQ(run("stats '" + kSample + "' --where \"use <> 'ROW'\" --out '" + dir.file("s") + "' --quiet").code, 0);
  const CliRun g = run("generate '" + dir.file("s") + "/blocks.gpkg' --out '" + dir.file("g") + "' --quiet");
  ASSERT_EQ(g.code, 0) << g.output;
  const std::string json = slurp(dir.file("g") + "/run.json");
  EXPECT_NE(json.find("\"blocks\": 10"), std::string::npos) << json;
  EXPECT_GT(writtenParcels(dir.file("g")).features.size(), 10u);
}

TEST(GenerateCommand, SkeletonOffsetAndAutoStylesRunOnTheSample) {
  TempDir dir;
  const std::string base = "generate '" + kSample + "' --where \"use <> 'ROW'\" --from-parcels --quiet --seed 3";
  for (const char* style : {"skeleton", "offset", "access", "auto"}) {
    const std::string out = dir.file(style);
    const CliRun r = run(base + " --style " + style + " --out '" + out + "'");
    ASSERT_EQ(r.code, 0) << style << ": " << r.output;
    const std::string json = slurp(out + "/run.json");
    EXPECT_NE(json.find("\"style\": \"" + std::string(style) + "\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"blocks\": 10"), std::string::npos) << json;
    // auto may pick sexton, which makes interior parcels where the observed ones are.
    if (std::string(style) != "auto") {
      EXPECT_NE(json.find("\"parcels_without_street_access\": 0"), std::string::npos) << json;
    }
    EXPECT_NE(json.find("\"blocks_by_style\""), std::string::npos) << json;
    writtenParcels(out);
    if (std::string(style) == "offset") {
      EXPECT_EQ(json.find("\"patio_parcels\": 0,"), std::string::npos)
          << "the sample's big blocks get patios: " << json;
    } else if (std::string(style) != "auto") {  // auto may pick offset
      EXPECT_NE(json.find("\"patio_parcels\": 0"), std::string::npos) << json;
    }
  }
  // Reproducible from the seed, vertex for vertex.
  ASSERT_EQ(run(base + " --style skeleton --out '" + dir.file("again") + "'").code, 0);
  EXPECT_EQ(slurp(dir.file("again") + "/parcels.csv"), slurp(dir.file("skeleton") + "/parcels.csv"));
  const test::ReadLayer again = writtenParcels(dir.file("again"));
  ASSERT_FALSE(again.geometries.empty());
  EXPECT_TRUE(test::sameGeometries(again, writtenParcels(dir.file("skeleton"))));
}

TEST(GenerateCommand, BadStyleAndConflictingBoundsAreUsageErrors) {
  TempDir dir;
  EXPECT_EQ(run("generate '" + kSample + "' --style voronoi --out '" + dir.file("x") + "' --quiet").code, 2);
  const CliRun r = run("generate '" + kSample + "' --a-min 900 --a-max 100 --out '" + dir.file("x") + "' --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_EQ(run("generate '" + kSample + "' --a-max 0 --out '" + dir.file("x") + "' --quiet").code, 2);
  EXPECT_FALSE(fs::exists(dir.file("x")));
}

// Bounds out of order are told before the input is read (here, one that does
// not exist), by generate and by compare.
TEST(GenerateCommand, ConflictingBoundsAreToldBeforeTheInputIsRead) {
  TempDir dir;
  for (const char* command : {"generate", "compare"}) {
    const CliRun r = run(std::string(command) + " '" + dir.file("missing.geojson") +
                         "' --a-min 900 --a-max 100 --out '" + dir.file("x") + "' --quiet");
    EXPECT_EQ(r.code, 2) << command << ": " << r.output;
    EXPECT_NE(r.output.find("--a-min must not exceed --a-max"), std::string::npos) << command << ": " << r.output;
  }
}

// A block layer's bounds outside their parameters' ranges (a negative A_min, an
// A_max below 1 m2) are moved into them, and the summary says how many.
TEST(GenerateCommand, BoundsMovedIntoTheirRangesAreTold) {
  TempDir dir;
  const std::string blocks = dir.file("blocks.geojson");
  std::ofstream(blocks) << R"({"type": "FeatureCollection",
    "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32631"}},
    "features": [
      {"type": "Feature", "properties": {"block_id": 1, "a_min": -50, "a_max": 0.5, "w_min": 2, "w_max": 10},
       "geometry": {"type": "Polygon", "coordinates": [[[500000, 0], [500040, 0], [500040, 30], [500000, 30], [500000, 0]]]}},
      {"type": "Feature", "properties": {"block_id": 2, "a_min": 100, "a_max": 400, "w_min": 5, "w_max": 20},
       "geometry": {"type": "Polygon", "coordinates": [[[500100, 0], [500140, 0], [500140, 30], [500100, 30], [500100, 0]]]}}
    ]})";
  const CliRun r = run("generate '" + blocks + "' --out '" + dir.file("g") + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("2 per-block bounds outside their parameter's range"), std::string::npos) << r.output;
  EXPECT_NE(slurp(dir.file("g") + "/run.json").find("\"per_block_bounds_clamped\": 2"), std::string::npos);
  const CliRun inRange = run("generate '" + blocks + "' --a-min 10 --a-max 400 --out '" + dir.file("h") + "'");
  ASSERT_EQ(inRange.code, 0) << inRange.output;
  EXPECT_EQ(inRange.output.find("per-block bounds outside"), std::string::npos) << inRange.output;
}

TEST(GenerateCommand, EnumAndBooleanParametersTakeTheirLabelsAndRecordNumbers) {
  TempDir dir;
  const std::string base = "generate '" + kSample + "' --where \"use <> 'ROW'\" --from-parcels --quiet --seed 3" +
                           " --style skeleton --offset 20";
  const CliRun numbers =
      run(base + " --corner-rule 1 --patio-obb 1 --detect-right-of-way 0 --out '" + dir.file("numbers") + "'");
  ASSERT_EQ(numbers.code, 0) << numbers.output;
  const CliRun labels = run(base + " --corner-rule street-length --patio-obb yes --detect-right-of-way=false --out '" +
                            dir.file("labels") + "'");
  ASSERT_EQ(labels.code, 0) << labels.output;
  EXPECT_EQ(slurp(dir.file("labels") + "/parcels.csv"), slurp(dir.file("numbers") + "/parcels.csv"));
  const test::ReadLayer byLabels = writtenParcels(dir.file("labels"));
  ASSERT_FALSE(byLabels.geometries.empty());
  EXPECT_TRUE(test::sameGeometries(byLabels, writtenParcels(dir.file("numbers"))));
  const std::string json = slurp(dir.file("labels") + "/run.json");
  for (const char* value : {"\"corner-rule\": 1", "\"patio-obb\": 1", "\"detect-right-of-way\": 0"}) {
    EXPECT_NE(json.find(value), std::string::npos) << value << " in " << json;
  }
  // The defaults by label: the same parcels as without the flags.
  ASSERT_EQ(run(base + " --corner-rule street-width --patio-obb no --out '" + dir.file("defaults") + "'").code, 0);
  ASSERT_EQ(run(base + " --out '" + dir.file("plain") + "'").code, 0);
  EXPECT_EQ(slurp(dir.file("defaults") + "/parcels.csv"), slurp(dir.file("plain") + "/parcels.csv"));
  const test::ReadLayer plain = writtenParcels(dir.file("plain"));
  ASSERT_FALSE(plain.geometries.empty());
  EXPECT_TRUE(test::sameGeometries(writtenParcels(dir.file("defaults")), plain));
}

TEST(GenerateCommand, AnUnknownLabelIsAUsageErrorNamingTheLabels) {
  TempDir dir;
  const CliRun r = run("generate '" + kSample + "' --corner-rule widest --out '" + dir.file("x") + "' --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--corner-rule widest"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("street-width, street-length"), std::string::npos) << r.output;
  const CliRun b = run("generate '" + kSample + "' --patio-obb maybe --out '" + dir.file("x") + "' --quiet");
  EXPECT_EQ(b.code, 2) << b.output;
  EXPECT_NE(b.output.find("true, false, yes, no"), std::string::npos) << b.output;
  EXPECT_EQ(run("generate '" + kSample + "' --corner-rule 2 --out '" + dir.file("x") + "' --quiet").code, 2);
  EXPECT_EQ(run("generate '" + kSample + "' --seed yes --out '" + dir.file("x") + "' --quiet").code, 2);
  EXPECT_FALSE(fs::exists(dir.file("x")));
}

TEST(CommandHelp, ListsTheParametersByGroupWithRangesDefaultsAndLabels) {
  const CliRun g = run("generate --help");
  ASSERT_EQ(g.code, 0) << g.output;
  for (const char* line :
       {"\n  Skeleton\n", "\n    --corner-rule LABEL  0 street-width, 1 street-length; default street-width\n",
        "\n    --patio-obb yes|no  (or 1|0, true|false), default no\n",
        "\n    --a-min X  [0, 100000000] m2, default 200\n", "\n    --seed N  [0, 4294967295], default 1\n"}) {
    EXPECT_NE(g.output.find(line), std::string::npos) << line << " in\n" << g.output;
  }
  const CliRun c = run("compare --help");
  ASSERT_EQ(c.code, 0) << c.output;
  std::size_t at = 0;
  for (const char* group : {"Bounds", "Blocks", "Subdivision", "Skeleton", "Comparison", "Figures", "Output"}) {
    const std::size_t next = c.output.find("\n  " + std::string(group) + "\n", at);
    ASSERT_NE(next, std::string::npos) << group << " (in this order) in\n" << c.output;
    at = next;
  }
  EXPECT_NE(c.output.find("\n    --figures yes|no  (or 1|0, true|false), default yes\n"), std::string::npos)
      << c.output;
  // min-frontage is described once, with one help text.
  const std::string flag = "--min-frontage ";
  const std::size_t first = c.output.find(flag);
  ASSERT_NE(first, std::string::npos) << c.output;
  EXPECT_EQ(c.output.find(flag, first + 1), std::string::npos) << c.output;
  // The flag's two lines (values, help) read the same in stats and generate.
  auto described = [](const std::string& help) {
    const std::size_t start = help.find("\n    --min-frontage ");
    if (start == std::string::npos) return std::string();
    return help.substr(start, help.find('\n', help.find('\n', start + 1) + 1) - start);
  };
  const std::string stats = described(run("stats --help").output);
  EXPECT_NE(stats.find("street access"), std::string::npos) << stats;
  EXPECT_EQ(stats, described(g.output));
}

// The metric registry is the one description of the parcel metrics: every
// parcel table has its columns in its order, and docs/user/metrics.md holds
// the table `parcelscope metrics` prints from it.
TEST(MetricsCommand, PrintsTheRegistryAsTheDocumentedTableAndTheTablesFollowIt) {
  const CliRun m = test::runCli("metrics");
  ASSERT_EQ(m.code, 0) << m.output;
  EXPECT_NE(m.output.find("| `aspect_ratio` |"), std::string::npos) << m.output;
  const std::string doc = slurp(std::string(PARCELSCOPE_SOURCE_DIR) + "/docs/user/metrics.md");
  EXPECT_NE(doc.find(m.output), std::string::npos)
      << "docs/user/metrics.md does not hold the table `parcelscope metrics` prints; paste it in:\n"
      << m.output;
  // The metric columns of a parcel table, in the registry's order.
  TempDir dir;
  const CliRun r = test::runCli("stats '" + std::string(PARCELSCOPE_SOURCE_DIR) +
                                "/datasets/sample/sample_town.geojson' --quiet --out '" + dir.file("out") + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  std::string header = slurp(dir.file("out") + "/parcels.csv");
  header = header.substr(0, header.find('\n'));
  std::string names;
  std::istringstream lines(m.output);
  for (std::string line; std::getline(lines, line);) {
    const auto a = line.find("| `"), b = line.find("` |");
    if (a == 0 && b != std::string::npos) names += "," + line.substr(3, b - 3);
  }
  EXPECT_EQ(header.substr(header.size() - std::min(header.size(), names.size() - 1)), names.substr(1)) << header;
}

}  // namespace
}  // namespace parcelscope
