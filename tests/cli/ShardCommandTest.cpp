// `compare --shard I/N` and `merge`, and `mpirun -n 2 parcelscope compare`,
// write the tables and layers one process writes.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include "CliRun.h"
#include "OgrTestUtil.h"

namespace parcelscope::test {
namespace {

namespace fs = std::filesystem;

const std::string kSample = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
const char* kTables[] = {"observed_parcels.csv", "generated_parcels.csv", "blocks.csv", "summary.csv", "distances.csv"};

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("parcelscope-shard-cli-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Every feature of the first layer of `path`: its fields and its geometry's WKB, in order.
std::string layerDump(const std::string& path) {
  const GDALDatasetUniquePtr ds = openVectorFile(path);
  if (!ds) return "cannot open " + path;
  OGRLayer* layer = ds->GetLayer(0);
  std::string dump = std::string(layer->GetName()) + "\n";
  for (const auto& feature : *layer) {
    for (int i = 0; i < feature->GetFieldCount(); ++i) dump += std::string(feature->GetFieldAsString(i)) + "|";
    if (const OGRGeometry* g = feature->GetGeometryRef()) {
      std::string wkb(static_cast<std::size_t>(g->WkbSize()), '\0');
      g->exportToWkb(wkbNDR, reinterpret_cast<unsigned char*>(wkb.data()), wkbVariantIso);
      dump += wkb;
    }
    dump += "\n";
  }
  return dump;
}

// The same files, and the same features in both layers (read back with GDAL).
void expectSameRun(const fs::path& one, const fs::path& other) {
  for (const char* table : kTables) {
    ASSERT_TRUE(fs::exists(other / table)) << table;
    EXPECT_EQ(slurp((one / table).string()), slurp((other / table).string())) << table;
  }
  for (const char* layer : {"parcels.gpkg", "blocks.gpkg"}) {
    EXPECT_EQ(layerDump((one / layer).string()), layerDump((other / layer).string())) << layer;
  }
}

const std::string kOptions = " --style obb --seed 3 --figures 0 --quiet";

TEST(ShardCommand, ThreeShardsMergedWriteWhatOneProcessWrites) {
  const fs::path dir = scratch("merge");
  ASSERT_EQ(0, runCli("compare '" + kSample + "'" + kOptions + " --out '" + (dir / "one").string() + "'").code);
  // The outputs' forms travel with the shards.
  const std::string forms = " --parcels-format geojson --metric area";
  ASSERT_EQ(
      0, runCli("compare '" + kSample + "'" + kOptions + forms + " --out '" + (dir / "one-forms").string() + "'").code);
  std::string shards, shardsWithForms;
  for (int i = 0; i < 2; ++i) {
    const fs::path out = dir / ("forms" + std::to_string(i));
    ASSERT_EQ(0, runCli("compare '" + kSample + "'" + kOptions + forms + " --shard " + std::to_string(i) +
                        "/2 --out '" + out.string() + "'")
                     .code);
    shardsWithForms += " '" + out.string() + "'";
  }
  ASSERT_EQ(0, runCli("merge" + shardsWithForms + " --quiet --out '" + (dir / "merged-forms").string() + "'").code);
  EXPECT_TRUE(fs::exists(dir / "merged-forms" / "parcels.geojson"));
  EXPECT_EQ(slurp((dir / "one-forms" / "parcels.geojson").string()),
            slurp((dir / "merged-forms" / "parcels.geojson").string()));
  for (int i = 0; i < 3; ++i) {
    const fs::path out = dir / ("shard" + std::to_string(i));
    const CliRun r = runCli("compare '" + kSample + "'" + kOptions + " --shard " + std::to_string(i) + "/3 --out '" +
                            out.string() + "'");
    ASSERT_EQ(0, r.code) << r.output;
    EXPECT_TRUE(fs::exists(out / "shard.bin"));
    shards += " '" + out.string() + "'";
  }
  // Any order of the folders.
  const CliRun merged = runCli("merge" + shards + " --quiet --out '" + (dir / "merged").string() + "'");
  ASSERT_EQ(0, merged.code) << merged.output;
  expectSameRun(dir / "one", dir / "merged");
  const std::string run = slurp((dir / "merged" / "run.json").string());
  EXPECT_NE(run.find("\"ranks\": 3"), std::string::npos) << run.substr(0, 400);

  // A shard left out, or one of another run, is refused and nothing is written.
  const CliRun missing = runCli("merge '" + (dir / "shard0").string() + "' '" + (dir / "shard2").string() +
                                "' --quiet --out '" + (dir / "partial").string() + "'");
  EXPECT_EQ(1, missing.code);
  EXPECT_NE(missing.output.find("missing: 1"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(dir / "partial"));
  ASSERT_EQ(0, runCli("compare '" + kSample + "' --style obb --seed 4 --figures 0 --quiet --shard 1/3 --out '" +
                      (dir / "other").string() + "'")
                   .code);
  const CliRun other = runCli("merge '" + (dir / "shard0").string() + "' '" + (dir / "other").string() + "' '" +
                              (dir / "shard2").string() + "' --quiet --out '" + (dir / "partial").string() + "'");
  EXPECT_EQ(1, other.code);
  EXPECT_NE(other.output.find("another request"), std::string::npos) << other.output;
  EXPECT_FALSE(fs::exists(dir / "partial"));
  EXPECT_EQ(2, runCli("compare '" + kSample + "' --shard 3/3 --out '" + (dir / "bad").string() + "'").code);
  // Bug: a merge into one of its shard folders replaced the shard (exit 0).
  const std::string shard0 = slurp((dir / "shard0" / "shard.bin").string());
  for (const fs::path& into : {dir / "shard0", dir / "shard1" / "inner"}) {
    const CliRun r = runCli("merge" + shards + " --quiet --out '" + into.string() + "'");
    EXPECT_EQ(2, r.code) << r.output;
    EXPECT_NE(r.output.find("input"), std::string::npos) << r.output;
  }
  EXPECT_EQ(slurp((dir / "shard0" / "shard.bin").string()), shard0);
  EXPECT_FALSE(fs::exists(dir / "shard1" / "inner"));
  // Nor may a run replace the session file it was given.
  const std::string session = slurp((dir / "merged" / "run.json").string());
  const CliRun again = runCli("compare --session '" + (dir / "merged" / "run.json").string() +
                              "' --figures 0 --quiet --out '" + (dir / "merged").string() + "'");
  EXPECT_EQ(2, again.code) << again.output;
  EXPECT_EQ(slurp((dir / "merged" / "run.json").string()), session);
  fs::remove_all(dir);
}

TEST(ShardCommand, TwoMpiRanksWriteWhatOneProcessWrites) {
  if (runShell("command -v mpirun").code != 0)
    GTEST_SKIP() << "mpirun not found (OpenMPI: apt-get install openmpi-bin)";
  // Root may run ranks here (CI containers run as root).
  const std::string mpirun = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -n 2 --oversubscribe";
  if (const CliRun probe = runShell(mpirun + " true"); probe.code != 0) {
    GTEST_SKIP() << "mpirun cannot start two processes here: " << probe.output;
  }
  const fs::path dir = scratch("mpi");
  ASSERT_EQ(0, runCli("compare '" + kSample + "'" + kOptions + " --out '" + (dir / "one").string() + "'").code);
  const CliRun r = runCli("compare '" + kSample + "'" + kOptions + " --out '" + (dir / "ranks").string() + "'", mpirun);
  ASSERT_EQ(0, r.code) << r.output;
  expectSameRun(dir / "one", dir / "ranks");
  const std::string run = slurp((dir / "ranks" / "run.json").string());
  EXPECT_NE(run.find("\"ranks\": 2"), std::string::npos) << run.substr(0, 400);
  // The ranks subdivided every block (obb reads no street widths).
  auto number = [&](const std::string& key) {
    std::smatch m;
    return std::regex_search(run, m, std::regex("\"" + key + "\": ([0-9]+)")) ? std::stoll(m[1]) : -1LL;
  };
  EXPECT_GT(number("blocks_subdivided"), 0);
  EXPECT_EQ(number("block_entries_generated_in_shards"), number("blocks_subdivided"));

  // A rank that fails stops them all, and nothing is written.
  const CliRun bad = runCli(
      "compare '" + kSample + "'" + kOptions + " --where 'no_such_field = 1' --out '" + (dir / "failed").string() + "'",
      mpirun);
  EXPECT_NE(0, bad.code);
  EXPECT_NE(bad.output.find("no_such_field"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir / "failed"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace parcelscope::test
