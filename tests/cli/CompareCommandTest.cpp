// `parcelscope compare` as a user runs it, end to end: every output exists and
// parses, generated parcels tile their blocks, the distances lie in their
// ranges, the figures have the requested size and ink, one figure matches its
// baseline image; without a display the figures render on a private Xvfb that
// is gone afterwards; a bad style and Ctrl-C leave nothing behind.
// Runs under scripts/with-xvfb.sh (its own Xvfb).
#include <cpl_json.h>
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <thread>

#include "OgrTestUtil.h"
#include "TestUtil.h"
#include "cli/CliRun.h"
#include "parcelscope/io/FileHash.h"
#include "viz/ImageCheck.h"

extern char** environ;

namespace parcelscope {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::runCli;
using test::TempDir;

const std::string kSample = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
const std::string kSampleArgs = "'" + kSample + "' --where \"use <> 'ROW'\"";

// A CSV file as rows of fields (our outputs quote nothing that holds a comma).
std::vector<std::vector<std::string>> readCsv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(test::slurp(path));
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> fields;
    std::stringstream s(line);
    for (std::string f; std::getline(s, f, ',');) fields.push_back(f);
    rows.push_back(fields);
  }
  return rows;
}

std::size_t columnOf(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return i;
  }
  ADD_FAILURE() << "no column " << name;
  return 0;
}

GDALDatasetUniquePtr openVector(const std::string& path) {
  GDALAllRegister();
  return GDALDatasetUniquePtr(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
}

// Generated parcels tile their block: parcel areas sum to the block's area (no
// gap), to the area of their union (no overlap), and the union lies in the block.
void expectTiling(const std::string& out) {
  auto parcels = openVector(out + "/parcels.gpkg");
  auto blocks = openVector(out + "/blocks.gpkg");
  ASSERT_TRUE(parcels && blocks);
  std::map<std::int64_t, std::unique_ptr<OGRMultiPolygon>> members;
  std::map<std::int64_t, double> sums;
  for (auto& f : *parcels->GetLayerByName("parcels")) {
    const std::int64_t id = f->GetFieldAsInteger64("block_id");
    auto& m = members[id];
    if (!m) m = std::make_unique<OGRMultiPolygon>();
    const auto* g = f->GetGeometryRef()->toMultiPolygon();
    for (const auto* part : *g) m->addGeometry(part);
    sums[id] += g->get_Area();
  }
  int checked = 0;
  for (auto& f : *blocks->GetLayerByName("blocks")) {
    const std::int64_t id = f->GetFieldAsInteger64("block_id");
    const OGRGeometry* block = f->GetGeometryRef();
    const double blockArea = block->toMultiPolygon()->get_Area();
    ASSERT_TRUE(members.count(id)) << "block " << id << " has no generated parcel";
    EXPECT_NEAR(sums[id] / blockArea, 1.0, 1e-6) << "block " << id << ": parcels do not cover it";
    std::unique_ptr<OGRGeometry> together(members[id]->UnionCascaded());
    ASSERT_TRUE(together) << "block " << id;
    const double unionArea =
        together->toSurface() ? together->toSurface()->get_Area() : together->toMultiPolygon()->get_Area();
    EXPECT_NEAR(unionArea / sums[id], 1.0, 1e-6) << "block " << id << ": parcels overlap";
    std::unique_ptr<OGRGeometry> inside(together->Intersection(block));
    ASSERT_TRUE(inside) << "block " << id;
    const double insideArea =
        inside->toSurface() ? inside->toSurface()->get_Area() : inside->toGeometryCollection()->get_Area();
    EXPECT_NEAR(insideArea / unionArea, 1.0, 1e-6) << "block " << id << ": parcels leave the block";
    ++checked;
  }
  EXPECT_EQ(checked, static_cast<int>(sums.size()));
}

struct Expected {
  std::string input;
  int epsg;  ///< CRS given with --crs, which the outputs must carry; 0: the input's CRS
  int width, height;
};

// Every file of a compare run exists and parses, and holds consistent numbers.
void expectCompareOutputs(const std::string& out, const Expected& e) {
  for (const char* f : {"parcels.gpkg", "blocks.gpkg", "observed_parcels.csv", "generated_parcels.csv", "blocks.csv",
                        "summary.csv", "distances.csv", "summary.json", "run.json"}) {
    ASSERT_TRUE(fs::exists(out + "/" + f)) << f;
  }
  CPLJSONDocument summaryDoc, runDoc;
  ASSERT_TRUE(summaryDoc.Load(out + "/summary.json"));
  ASSERT_TRUE(runDoc.Load(out + "/run.json"));
  const CPLJSONObject summary = summaryDoc.GetRoot(), run = runDoc.GetRoot();
  const auto blocks = summary.GetLong("blocks", -1);
  const auto observed = summary.GetLong("observed/parcels", -1);
  const auto generated = summary.GetLong("generated/parcels", -1);
  EXPECT_GT(blocks, 0);
  EXPECT_GT(observed, 0);
  EXPECT_GT(generated, 0);
  for (const char* m : {"area", "width", "aspect_ratio"}) {
    const double ks = summary.GetDouble(std::string("ks/") + m, -1);
    EXPECT_GE(ks, 0.0) << m;
    EXPECT_LE(ks, 1.0) << m;
    EXPECT_GE(summary.GetDouble(std::string("wasserstein/") + m, -1), 0.0) << m;
    const double hi = summary.GetDouble(std::string("histogram_intersection/") + m, -1);
    EXPECT_GE(hi, 0.0) << m;
    EXPECT_LE(hi, 1.0) << m;
  }
  EXPECT_GT(summary.GetDouble("timing_s/generate", -1), 0.0);
  EXPECT_GE(summary.GetDouble("timing_s/total", -1), summary.GetDouble("timing_s/generate", 0));
  EXPECT_EQ(run.GetString("command"), "compare");
  EXPECT_EQ(run.GetString("input_file/sha256"), io::sha256File(e.input));
  EXPECT_EQ(run.GetDouble("parameters/k", -1), 2.0);
  EXPECT_FALSE(run.GetString("version").empty());

  // Tables: rectangular, and their counts agree with summary.json.
  for (const char* f :
       {"observed_parcels.csv", "generated_parcels.csv", "blocks.csv", "summary.csv", "distances.csv"}) {
    const auto rows = readCsv(out + "/" + f);
    ASSERT_GE(rows.size(), 2u) << f;
    for (const auto& row : rows) ASSERT_EQ(row.size(), rows[0].size()) << f;
  }
  const auto blockRows = readCsv(out + "/blocks.csv");
  EXPECT_EQ(static_cast<long>(blockRows.size()) - 1, blocks);
  EXPECT_EQ(static_cast<long>(readCsv(out + "/generated_parcels.csv").size()) - 1, generated);
  std::int64_t observedInBlocks = 0, generatedInBlocks = 0;
  for (std::size_t r = 1; r < blockRows.size(); ++r) {
    observedInBlocks += std::stoll(blockRows[r][columnOf(blockRows[0], "observed_parcels")]);
    generatedInBlocks += std::stoll(blockRows[r][columnOf(blockRows[0], "generated_parcels")]);
    for (const char* m : {"ks_area", "ks_width", "ks_aspect_ratio"}) {
      const double ks = std::stod(blockRows[r][columnOf(blockRows[0], m)]);
      EXPECT_TRUE(ks >= 0 && ks <= 1) << m << " = " << ks << " in block row " << r;
    }
  }
  EXPECT_EQ(observedInBlocks, observed);
  EXPECT_EQ(generatedInBlocks, generated);

  // The input's own CRS, or the one given with --crs.
  OGRSpatialReference expected;
  if (e.epsg > 0) {
    expected.importFromEPSG(e.epsg);
  } else {
    auto input = openVector(e.input);
    ASSERT_TRUE(input && input->GetLayer(0)->GetSpatialRef());
    expected = *input->GetLayer(0)->GetSpatialRef();
  }
  // The written layers read back with GDAL: as many features as the tables
  // count, each a valid polygon of positive area in the file as written, with
  // the documented fields, in that CRS.
  const test::ReadLayer parcels = test::expectValidPolygonLayer(
      out + "/parcels.gpkg", generated,
      {"parcels", {"parcel_id", "parcel_key", "block_id", "block_key", "area", "width", "aspect_ratio"}, &expected});
  test::expectValidPolygonLayer(
      out + "/blocks.gpkg", blocks,
      {"blocks", {"block_id", "block_key", "block_area", "observed_parcels", "generated_parcels"}, &expected});
  // Every generated parcel belongs to a compared block.
  std::set<std::int64_t> blockIds;
  for (std::size_t r = 1; r < blockRows.size(); ++r) {
    blockIds.insert(std::stoll(blockRows[r][columnOf(blockRows[0], "block_id")]));
  }
  for (const auto& f : parcels.features) {
    EXPECT_EQ(blockIds.count(f->GetFieldAsInteger64("block_id")), 1u) << "parcel feature " << f->GetFID();
  }
  auto gpkg = openVector(out + "/parcels.gpkg");
  ASSERT_TRUE(gpkg);
  OGRLayer* layer = gpkg->GetLayerByName("parcels");
  ASSERT_NE(layer, nullptr);
  EXPECT_TRUE(layer->TestCapability(OLCFastSpatialFilter)) << "no spatial index";
  expectTiling(out);

  // Figures: requested size, not blank; the charts also as SVG.
  for (const char* name : {"map_aspect_ratio", "hist_area", "hist_width", "hist_aspect_ratio", "map_blocks"}) {
    const std::string png = out + "/figures/" + name + ".png";
    const test::Image image = test::readPng(png);
    ASSERT_EQ(image.width, e.width) << png;
    ASSERT_EQ(image.height, e.height) << png;
    const test::Ink ink = test::ink(image);
    EXPECT_GT(ink.share, 0.03) << png << " looks blank";
    EXPECT_GT(ink.colours, 16u) << png << " has hardly any colour";
  }
  for (const char* name : {"hist_area", "hist_width", "hist_aspect_ratio"}) {
    EXPECT_NE(test::slurp(out + "/figures/" + name + ".svg").find("<svg"), std::string::npos) << name;
  }
}

// Runs compare on the bundled sample with `options`, writing to `out`.
CliRun compareSample(const std::string& out, const std::string& options) {
  return runCli("compare " + kSampleArgs + " " + options + " --out '" + out + "' --quiet");
}

TEST(CompareCommand, BundledSampleEndToEnd) {
  TempDir dir;
  const std::string out = dir.file("out");
  const CliRun r = compareSample(out, "--seed 3 --figure-width 1000 --figure-height 520");
  ASSERT_EQ(r.code, 0) << r.output;
  expectCompareOutputs(out, {kSample, 0, 1000, 520});
  // The sample's ten blocks (datasets/README.md), and its parcels, are all compared.
  CPLJSONDocument summary;
  ASSERT_TRUE(summary.Load(out + "/summary.json"));
  EXPECT_EQ(summary.GetRoot().GetLong("blocks"), 10);
  EXPECT_EQ(summary.GetRoot().GetLong("seed"), 3);
}

TEST(CompareCommand, SharedDatasetEndToEnd) {
  PARCELSCOPE_REQUIRE_SHARED_DATASETS();
  TempDir dir;
  const std::string input = test::sharedDataset("eatonville_wa/parcels.geojson");
  const std::string out = dir.file("out");
  const CliRun r = runCli("compare '" + input + "' --crs EPSG:2286 --figure-width 1200 --figure-height 600 --out '" +
                          out + "' --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  expectCompareOutputs(out, {input, 2286, 1200, 600});
}

// Figures of a fixed run compared with baseline images within a tolerance. On
// a mismatch the rendered image is kept in the build tree; with
// PARCELSCOPE_UPDATE_BASELINES=1 the rendered images become the baselines.
TEST(CompareCommand, FiguresMatchTheirBaselines) {
  TempDir dir;
  const std::string out = dir.file("out");
  const CliRun r = compareSample(out, "--seed 1 --figure-width 900 --figure-height 450");
  ASSERT_EQ(r.code, 0) << r.output;
  const bool update = std::getenv("PARCELSCOPE_UPDATE_BASELINES") != nullptr;
  for (const char* name : {"map_aspect_ratio", "hist_area"}) {
    const std::string rendered = out + "/figures/" + name + ".png";
    const std::string baseline = std::string(PARCELSCOPE_SOURCE_DIR) + "/tests/data/baseline/" + name + "_sample.png";
    if (update) {
      fs::create_directories(fs::path(baseline).parent_path());
      fs::copy_file(rendered, baseline, fs::copy_options::overwrite_existing);
      continue;
    }
    ASSERT_TRUE(fs::exists(baseline)) << baseline << " is missing (PARCELSCOPE_UPDATE_BASELINES=1 writes it)";
    const double share = test::differingShare(test::readPng(rendered), test::readPng(baseline));
    if (share > 0.01) {
      const fs::path kept = fs::path(PARCELSCOPE_RENDER_FAILURES) / (std::string(name) + "_sample.png");
      fs::create_directories(kept.parent_path());
      fs::copy_file(rendered, kept, fs::copy_options::overwrite_existing);
      ADD_FAILURE() << name << ": " << 100 * share << " % of the pixels differ from " << baseline
                    << "; the rendered image is kept at " << kept;
    }
  }
  if (update) GTEST_SKIP() << "baselines written to tests/data/baseline";
}

// Processes named `name` whose parent is this process (children, and orphans
// handed to it as their subreaper), zombies included.
std::vector<std::string> childrenNamed(const std::string& name) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string pid = entry.path().filename().string();
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = test::slurp(entry.path().string() + "/stat");  // pid (comm) state ppid ...
    const std::size_t open = stat.find('('), close = stat.rfind(')');
    if (open == std::string::npos || close == std::string::npos || close + 4 > stat.size()) continue;
    std::istringstream rest(stat.substr(close + 2));
    char state = '?';
    long ppid = 0;
    rest >> state >> ppid;
    if (stat.substr(open + 1, close - open - 1) == name && ppid == static_cast<long>(::getpid())) {
      found.push_back(pid + " (state " + state + ")");
    }
  }
  return found;
}

// X server lock files (/tmp/.X<n>-lock) that name no running process.
std::set<std::string> staleXLocks() {
  std::set<std::string> stale;
  for (const auto& entry : fs::directory_iterator("/tmp")) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(".X", 0) != 0 || name.size() < 8 || name.compare(name.size() - 5, 5, "-lock") != 0) continue;
    const long pid = std::atol(test::slurp(entry.path().string()).c_str());
    if (pid <= 0 || !fs::exists("/proc/" + std::to_string(pid))) stale.insert(name);
  }
  return stale;
}

// Without a display (DISPLAY unset, or naming no server), compare starts a
// private Xvfb, draws every figure on it and stops it: no Xvfb of the run is
// left, running or as a zombie (this process is made their subreaper, so an
// Xvfb orphaned by the run would become its child), and no stale lock file.
// Without Xvfb either, it fails in one line naming the package to install.
TEST(CompareCommand, WithoutDisplayFiguresRenderOnAPrivateXvfbAndFiguresZeroSkipsThem) {
  TempDir dir;
  ASSERT_EQ(::prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const std::set<std::string> staleBefore = staleXLocks();
  const CliRun r = runCli("compare " + kSampleArgs + " --out '" + dir.file("a") + "' --quiet", "env -u DISPLAY");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::vector<std::string> left = childrenNamed("Xvfb");
  std::set<std::string> staleAfter = staleXLocks();
  for (const std::string& lock : staleBefore) staleAfter.erase(lock);
  ::prctl(PR_SET_CHILD_SUBREAPER, 0);
  for (const std::string& pid : left) ADD_FAILURE() << "an Xvfb of the run is left: " << pid;
  for (const std::string& lock : staleAfter) ADD_FAILURE() << "stale X lock file left: /tmp/" << lock;
  std::set<std::string> pngs;
  for (const auto& entry : fs::directory_iterator(dir.file("a") + "/figures")) {
    if (entry.path().extension() == ".png") pngs.insert(entry.path().filename().string());
  }
  for (const char* name : {"map_aspect_ratio", "hist_area", "hist_width", "hist_aspect_ratio", "map_blocks"}) {
    EXPECT_EQ(pngs.count(std::string(name) + ".png"), 1u) << name << " was not written";
  }
  for (const std::string& name : pngs) {
    const std::string png = dir.file("a") + "/figures/" + name;
    EXPECT_GT(fs::file_size(png), 0u) << png;
    const test::Image image = test::readPng(png);
    EXPECT_EQ(image.width, 1800) << png << " does not decode at the default size";
    EXPECT_EQ(image.height, 900) << png;
    EXPECT_GT(test::ink(image).share, 0.03) << png << " looks blank";
  }

  // DISPLAY naming a server that is not there: the same.
  const CliRun elsewhere =
      runCli("compare " + kSampleArgs + " --figure-width 400 --figure-height 200 --out '" + dir.file("c") + "' --quiet",
             "env DISPLAY=:65432");
  ASSERT_EQ(elsewhere.code, 0) << elsewhere.output;
  EXPECT_EQ(test::readPng(dir.file("c") + "/figures/map_blocks.png").width, 400);

  // No Xvfb either (PATH leads to none): one line naming the package, nothing written.
  const CliRun noXvfb =
      runCli("compare " + kSampleArgs + " --out '" + dir.file("d") + "' --quiet", "env -u DISPLAY PATH=/nonexistent");
  EXPECT_EQ(noXvfb.code, 1) << noXvfb.output;
  EXPECT_NE(noXvfb.output.find("Debian package xvfb"), std::string::npos) << noXvfb.output;
  EXPECT_NE(noXvfb.output.find("--figures 0"), std::string::npos) << noXvfb.output;
  EXPECT_EQ(std::count(noXvfb.output.begin(), noXvfb.output.end(), '\n'), 1) << noXvfb.output;
  EXPECT_FALSE(fs::exists(dir.file("d")));

  const CliRun tablesOnly =
      runCli("compare " + kSampleArgs + " --figures 0 --spatial-index 0 --out '" + dir.file("b") + "' --quiet",
             "env -u DISPLAY");
  ASSERT_EQ(tablesOnly.code, 0) << tablesOnly.output;
  EXPECT_TRUE(fs::exists(dir.file("b") + "/summary.json"));
  EXPECT_FALSE(fs::exists(dir.file("b") + "/figures"));
  // --spatial-index 0: the same layers without their R-tree.
  for (const char* name : {"parcels", "blocks"}) {
    auto gpkg = openVector(dir.file("b") + "/" + name + ".gpkg");
    ASSERT_TRUE(gpkg);
    OGRLayer* layer = gpkg->GetLayerByName(name);
    ASSERT_NE(layer, nullptr);
    EXPECT_GT(layer->GetFeatureCount(), 0);
    EXPECT_FALSE(layer->TestCapability(OLCFastSpatialFilter)) << name;
  }
}

TEST(CompareCommand, DrawsAProgressBarOnATerminal) {
  TempDir dir;
  // script(1) gives the command a pseudo-terminal, as a user's shell would.
  const std::string command =
      "'" + std::string(PARCELSCOPE_CLI) + "' compare " + kSampleArgs + " --figures 0 --out '" + dir.file("out") + "'";
  std::string quoted;
  for (char c : command) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  const CliRun r = test::runShell("script -qec '" + quoted + "' /dev/null");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("\r[###"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("] 100%"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("subdividing"), std::string::npos) << r.output;
}

// On one core (a Slurm task with one CPU, here taskset) every stage is still
// reported: parallel loops tick between items on the calling thread (they
// did not tick at all, so a stage such as subdividing went unreported and
// Ctrl-C waited for its end).
TEST(CompareCommand, ReportsEveryStageOnOneCore) {
  TempDir dir;
  const CliRun r = runCli("compare " + kSampleArgs + " --figures 0 --out '" + dir.file("out") + "'", "taskset -c 0");
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* stage : {"cleaning ...", "blocks ...", "subdividing ...", "measuring ...", "writing ..."}) {
    EXPECT_NE(r.output.find(stage), std::string::npos) << stage << " in:\n" << r.output;
  }
}

TEST(CompareCommand, UnknownStyleIsAUsageErrorAndWritesNothing) {
  TempDir dir;
  const CliRun r = runCli("compare " + kSampleArgs + " --style voronoi --out '" + dir.file("x") + "' --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("voronoi"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir.file("x")));
  EXPECT_EQ(runCli("compare " + kSampleArgs + " --bins 1 --out '" + dir.file("x") + "'").code, 2);
  EXPECT_EQ(runCli("compare --help").code, 0);
  // Told before the input is read (it was after reading it): an input that
  // does not exist is not reached.
  const CliRun early =
      runCli("compare '" + dir.file("absent.geojson") + "' --style voronoi --out '" + dir.file("x") + "' --quiet");
  EXPECT_EQ(early.code, 2) << early.output;
  EXPECT_NE(early.output.find("voronoi is not available"), std::string::npos) << early.output;
  // Bug: 10000 x 10000 figures (each side in its range) took 8.9 GB and 6 minutes.
  const CliRun huge = runCli("compare " + kSampleArgs + " --figure-width 10000 --figure-height 10000 --out '" +
                             dir.file("x") + "' --quiet");
  EXPECT_EQ(huge.code, 2) << huge.output;
  EXPECT_NE(huge.output.find("16 million pixels"), std::string::npos) << huge.output;
  EXPECT_FALSE(fs::exists(dir.file("x")));
}

TEST(CompareCommand, CtrlCLeavesNoOutputAndNoStagingFolder) {
  PARCELSCOPE_REQUIRE_SHARED_DATASETS();
  TempDir dir;
  const std::string input = test::sharedDataset("cambridge_ma/ASSESSING_ParcelsFY2014.topojson");
  const std::string out = dir.file("out");
  std::vector<std::string> args = {PARCELSCOPE_CLI, "compare", input,   "--where", "ML <> 'ROAD'",
                                   "--figures",     "0",       "--out", out};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, PARCELSCOPE_CLI, &files, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&files);
  // Interrupt as soon as the job has made its staging folder: it is then
  // reading or computing, well before it could finish (about a second).
  for (int waited = 0; waited < 10000 && fs::is_empty(dir.path()); waited += 5) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_FALSE(fs::is_empty(dir.path())) << "the job made no staging folder within 10 s";
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal instead of stopping";
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 0)
      << "a staging folder was left behind";
}

}  // namespace
}  // namespace parcelscope

namespace parcelscope {
namespace {

// What the GUI does to data, the command line does too: a saved session (or a
// compare run.json) reruns with its overrides, and --metric draws the quantity
// the GUI colours by.
TEST(CompareCommand, SessionFileRerunsWithItsOverrides) {
  TempDir dir;
  const std::string session =
      dir.write("session.json", R"({"parcelscope_session": 1, "input": {"path": ")" + kSample +
                                    R"(", "where": "use <> 'ROW'"}, "style": "obb", "parameters": {"seed": 5},
      "overrides": [{"block_id": 3, "style": "skeleton", "parameters": {"w-max": 14}}]})");
  const std::string a = dir.file("a"), b = dir.file("b");
  CliRun r = runCli("compare --session '" + session + "' --figures 0 --out '" + a + "' --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  CPLJSONDocument run;
  ASSERT_TRUE(run.Load(a + "/run.json"));
  EXPECT_EQ(run.GetRoot().GetLong("seed"), 5);
  EXPECT_EQ(run.GetRoot().GetObj("session").GetArray("overrides").Size(), 1);
  // The run record is itself a session: the same parcels again, vertex for vertex.
  r = runCli("compare --session '" + a + "/run.json' --figures 0 --out '" + b + "' --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(test::slurp(a + "/generated_parcels.csv"), test::slurp(b + "/generated_parcels.csv"));
  auto written = [](const std::string& out) {
    CPLJSONDocument summary;
    EXPECT_TRUE(summary.Load(out + "/summary.json")) << out;
    return test::expectValidPolygonLayer(out + "/parcels.gpkg", summary.GetRoot().GetLong("generated/parcels", -1),
                                         {"parcels", {"block_id"}, nullptr});
  };
  const test::ReadLayer withOverride = written(a);
  ASSERT_FALSE(withOverride.geometries.empty());
  EXPECT_TRUE(test::sameGeometries(withOverride, written(b)));
  // Without the override, block 3 differs.
  const std::string c = dir.file("c");
  r = compareSample(c, "--seed 5 --figures 0");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(test::slurp(a + "/generated_parcels.csv"), test::slurp(c + "/generated_parcels.csv"));
  EXPECT_FALSE(test::sameGeometries(withOverride, written(c)));
}

// Bug: a run given a relative INPUT recorded it as given, and `compare
// --session OUT/run.json` looked for it beside run.json. The record holds the
// input's absolute path: the rerun works from any folder.
TEST(CompareCommand, ARunGivenARelativeInputRerunsFromItsRecordAnywhere) {
  TempDir dir;
  fs::copy_file(kSample, dir.file("town.geojson"));
  const std::string a = dir.file("a"), b = dir.file("b");
  CliRun r = test::runShell("cd '" + dir.path().string() + "' && '" + PARCELSCOPE_CLI +
                            "' compare town.geojson --figures 0 --out a --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  CPLJSONDocument run;
  ASSERT_TRUE(run.Load(a + "/run.json"));
  EXPECT_EQ(run.GetRoot().GetString("session/input/path"), dir.file("town.geojson"));
  r = runCli("compare --session '" + a + "/run.json' --figures 0 --out '" + b + "' --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(test::slurp(a + "/generated_parcels.csv"), test::slurp(b + "/generated_parcels.csv"));
}

// calibrate: its session file through compare gives the calibrated measures,
// and its figures (per-block fit map, histograms before and after) are drawn.
TEST(CalibrateCommand, SessionReproducesTheCalibratedCityAndFiguresAreDrawn) {
  TempDir dir;
  const std::string out = dir.file("cal"), again = dir.file("again");
  CliRun r = runCli("calibrate " + kSampleArgs + " --out '" + out + "' --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  CPLJSONDocument run;
  ASSERT_TRUE(run.Load(out + "/run.json"));
  const double ksArea = run.GetRoot().GetDouble("calibration/after/ks_area", -1);
  ASSERT_GE(ksArea, 0);
  EXPECT_LE(ksArea, run.GetRoot().GetDouble("calibration/before/ks_area", -1) + 1e-12);
  for (const char* name :
       {"map_fit", "hist_calibration_area", "hist_calibration_width", "hist_calibration_aspect_ratio"}) {
    const test::Image image = test::readPng(out + "/figures/" + name + ".png");
    EXPECT_GT(test::ink(image).share, 0.03) << name << " looks blank";
    EXPECT_NE(test::slurp(out + "/figures/" + name + ".svg").find("<svg"), std::string::npos) << name;
  }
  r = runCli("compare --session '" + out + "/session.json' --figures 0 --out '" + again + "' --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  CPLJSONDocument summary;
  ASSERT_TRUE(summary.Load(again + "/summary.json"));
  EXPECT_NEAR(summary.GetRoot().GetDouble("ks/area", -1), ksArea, 1e-9) << summary.SaveAsString();
}

TEST(CompareCommand, MetricDrawsItsMapAndHistogram) {
  TempDir dir;
  const std::string out = dir.file("out");
  const CliRun r = compareSample(out, "--metric p_angle --figure-width 800 --figure-height 400");
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* name : {"map_p_angle.png", "hist_p_angle.png", "hist_p_angle.svg"}) {
    const test::Image image = test::readPng(out + "/figures/" + name);
    if (std::string(name).find(".png") != std::string::npos) {
      EXPECT_EQ(image.width, 800) << name;
      EXPECT_GT(test::ink(image).share, 0.02) << name;
    } else {
      EXPECT_NE(test::slurp(out + "/figures/" + name).find("<svg"), std::string::npos) << name;
    }
  }
  const CliRun bad = compareSample(dir.file("bad"), "--metric colour --figures 0");
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_NE(bad.output.find("no parcel quantity 'colour'"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir.file("bad")));
}

}  // namespace
}  // namespace parcelscope

namespace parcelscope {
namespace {

// The application exports histograms as PDF and parcels as GeoJSON; so does compare.
TEST(CompareCommand, PdfHistogramsAndGeoJsonParcels) {
  TempDir dir;
  const std::string out = dir.file("out");
  const CliRun r = compareSample(out, "--vector pdf --parcels-format geojson --figure-width 600 --figure-height 300");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(test::slurp(out + "/figures/hist_area.pdf").rfind("%PDF", 0), 0u);
  EXPECT_FALSE(fs::exists(out + "/figures/hist_area.svg"));
  EXPECT_NE(test::slurp(out + "/parcels.geojson").find("\"FeatureCollection\""), std::string::npos);
  EXPECT_FALSE(fs::exists(out + "/parcels.gpkg"));
  // The GeoJSON read back: every generated parcel, valid, in the input's CRS.
  CPLJSONDocument summary;
  ASSERT_TRUE(summary.Load(out + "/summary.json"));
  const OGRSpatialReference crs = test::layerCrs(kSample);
  test::expectValidPolygonLayer(out + "/parcels.geojson", summary.GetRoot().GetLong("generated/parcels", -1),
                                {"", {"parcel_id", "block_id", "aspect_ratio"}, &crs});
  const CliRun bad = compareSample(dir.file("bad"), "--parcels-format shp --figures 0");
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--parcels-format shp"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir.file("bad")));
}

}  // namespace
}  // namespace parcelscope
