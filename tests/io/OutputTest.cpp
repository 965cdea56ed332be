#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <GeographicLib/Geodesic.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <random>

#include "OgrTestUtil.h"
#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"

namespace parcelscope::io {
namespace {

using test::rect;
using test::TempDir;
namespace fs = std::filesystem;

// What a run writes: relative name -> content. A run.json of ParcelScope marks
// the folder as a run that the next may replace.
using RunFiles = std::map<std::string, std::string>;
const RunFiles kFirst = {{"run.json", R"({"tool": "parcelscope", "command": "compare", "n": 1})"},
                         {"parcels.csv", "parcel_id\n1\n"},
                         {"figures/map_area.png", "png of the first run"},
                         {"figures/hist_area.svg", "<svg/>"}};
const RunFiles kSecond = {{"run.json", R"({"tool": "parcelscope", "command": "compare", "n": 2})"},
                          {"parcels.csv", "parcel_id\n2\n"}};  // --figures 0
const RunFiles kThird = {{"run.json", R"({"tool": "parcelscope", "command": "stats", "n": 3})"},
                         {"blocks.csv", "block_id\n3\n"}};

// Every file and folder under `root` by relative path, with the bytes of each
// file ("/" for a folder); empty when `root` does not exist.
std::map<std::string, std::string> snapshot(const fs::path& root) {
  std::map<std::string, std::string> s;
  if (!fs::exists(root)) return s;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    s[fs::relative(e.path(), root).generic_string()] = e.is_directory() ? "/" : test::slurpFile(e.path().string());
  }
  return s;
}

// What snapshot() gives for a folder holding exactly `run`.
std::map<std::string, std::string> snapshotOf(const RunFiles& run) {
  std::map<std::string, std::string> s;
  for (const auto& [name, text] : run) {
    s[name] = text;
    for (fs::path folder = fs::path(name).parent_path(); !folder.empty(); folder = folder.parent_path()) {
      s[folder.generic_string()] = "/";
    }
  }
  return s;
}

// The names in `folder`, sorted.
std::vector<std::string> entries(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(folder)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void stageRun(OutputDirectory& out, const RunFiles& run) {
  for (const auto& [name, text] : run) std::ofstream(out.stage(name), std::ios::binary) << text;
}

void commitRun(const std::string& target, const RunFiles& run) {
  OutputDirectory out(target, {});
  stageRun(out, run);
  out.commit();
}

// The three ways commit() swaps runs: one RENAME_EXCHANGE, two renames, and the
// swap of contents used for a mount point. Selected for a scope.
struct Swap {
  enum Kind { Exchange, TwoRenames, Contents };
  explicit Swap(Kind k) {
    OutputDirectoryTesting::noExchange = k == TwoRenames;
    OutputDirectoryTesting::stageInside = k == Contents;
  }
  ~Swap() {
    OutputDirectoryTesting::noExchange = false;
    OutputDirectoryTesting::stageInside = false;
    OutputDirectoryTesting::step = nullptr;
  }
  static const char* name(Kind k) { return k == Exchange ? "exchange" : k == TwoRenames ? "two renames" : "contents"; }
};
constexpr Swap::Kind kSwaps[] = {Swap::Exchange, Swap::TwoRenames, Swap::Contents};

// Fault injection: commit() fails (throws, or the process ends) at the
// `count`-th call of step `name`.
struct Fault {
  static inline std::string name;
  static inline int count = 0;
  static inline int seen = 0;
  static inline bool exitProcess = false;
  static void at(const char* step) {
    if (step != name || ++seen != count) return;
    if (exitProcess) ::_exit(0);  // as if killed here
    throw ioError("injected failure at " + name);
  }
  static void arm(const std::string& step, int n, bool exit) {
    name = step, count = n, seen = 0, exitProcess = exit;
    OutputDirectoryTesting::step = &Fault::at;
  }
};

// Runs `body` in a child process, in a private mount namespace where each folder
// of `mounts` (path, read-only) is an empty tmpfs. Returns what went wrong ("" when
// nothing did), or nullopt when this process may not make mount namespaces.
std::optional<std::string> withMounts(const std::vector<std::pair<std::string, bool>>& mounts,
                                      const std::function<std::string()>& body) {
  int fds[2];
  if (::pipe(fds) != 0) return "pipe failed";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    if (::unshare(CLONE_NEWNS) != 0 || ::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) ::_exit(77);
    for (const auto& [path, readOnly] : mounts) {
      if (::mount("tmpfs", path.c_str(), "tmpfs", readOnly ? MS_RDONLY : 0, "size=4m") != 0) ::_exit(77);
    }
    std::string result;
    try {
      result = body();
    } catch (const std::exception& e) {
      result = std::string("threw: ") + e.what();
    }
    const ssize_t written = ::write(fds[1], result.data(), result.size());
    ::_exit(written == static_cast<ssize_t>(result.size()) ? 0 : 1);
  }
  ::close(fds[1]);
  std::string result;
  char buffer[4096];
  for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;) result.append(buffer, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 77) return std::nullopt;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return "the child process failed: " + result;
  return result;
}

TEST(OutputDirectory, FilesAppearOnlyOnCommit) {
  TempDir dir;
  const std::string target = dir.file("out");
  {
    OutputDirectory out(target, {});
    std::ofstream(out.stage("a.csv")) << "x\n";
    EXPECT_FALSE(fs::exists(target));
  }  // no commit: nothing appears, staging removed
  EXPECT_FALSE(fs::exists(target));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 0);
  commitRun(target, {{"a.csv", "x\n"}, {"run.json", R"({"tool": "parcelscope"})"}});
  EXPECT_TRUE(fs::exists(target + "/a.csv"));
  commitRun(target, {{"b.csv", "y\n"}, {"run.json", R"({"tool": "parcelscope"})"}});
  EXPECT_FALSE(fs::exists(target + "/a.csv"));  // the previous run is replaced whole
  EXPECT_TRUE(fs::exists(target + "/b.csv"));
}

TEST(OutputDirectory, FilesInSubfoldersMoveIntoNewAndExistingTargets) {
  TempDir dir;
  const std::string target = dir.file("out");
  for (const char* name : {"figures/a.png", "figures/b.png"}) {
    commitRun(target, {{name, name}, {"run.json", R"({"tool": "parcelscope"})"}});
    EXPECT_TRUE(fs::exists(target + "/" + name));
  }
  EXPECT_FALSE(fs::exists(target + "/figures/a.png"));
}

TEST(OutputDirectory, StagingOfAKilledRunIsRemovedByTheNext) {
  TempDir dir;
  const fs::path stale = dir.path() / ".out.partial-999999999";  // no such process
  fs::create_directories(stale);
  std::ofstream((stale / "parcels.csv").string()) << "x\n";
  {
    OutputDirectory out(dir.file("out"), {});
    out.commit();
  }
  EXPECT_FALSE(fs::exists(stale));
}

TEST(OutputDirectory, NeverOverwritesAnInput) {
  TempDir dir;
  const auto input = dir.write("parcels.csv", "x\n");
  EXPECT_THROW(OutputDirectory(input, {input}), Error);
  EXPECT_THROW(OutputDirectory(dir.path().string(), {input}), Error);  // --out holds the input
}

// Bug: a list or VRT naming a file inside --out (a previous run's
// parcels.gpkg) let the run replace the folder, and the file with it.
TEST(OutputDirectory, NeverOverwritesAFileThatAListOrAVrtNames) {
  TempDir dir;
  const std::string target = dir.file("run");
  commitRun(target, kFirst);
  const std::string named = (fs::path(target) / "parcels.csv").string();
  const auto list = dir.write("communes.txt", "# one per line\nrun/parcels.csv\n");
  const auto vrt = dir.write("communes.vrt",
                             "<OGRVRTDataSource><OGRVRTUnionLayer name=\"p\"><OGRVRTLayer name=\"a\">"
                             "<SrcDataSource relativeToVRT=\"1\">run/parcels.csv</SrcDataSource>"
                             "</OGRVRTLayer></OGRVRTUnionLayer></OGRVRTDataSource>\n");
  const auto nested = dir.write("lists.txt", "communes.vrt\n");
  for (const std::string& input : {list, vrt, nested}) {
    SCOPED_TRACE(input);
    try {
      OutputDirectory out(target, {input});
      FAIL() << "a run may replace " << named;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), Error::Kind::Usage);
      EXPECT_NE(std::string(e.what()).find("holds the input"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(snapshot(target), snapshotOf(kFirst));
  // The same list with --out elsewhere runs.
  EXPECT_NO_THROW(OutputDirectory(dir.file("other"), {list}));
}

// Bug: a second run into the same --out left the first run's files beside its
// own (figures/ of a run with figures beside the tables of a run without).
TEST(OutputDirectory, ASecondRunWithFewerFilesLeavesNoFileOfTheFirst) {
  for (Swap::Kind kind : kSwaps) {
    SCOPED_TRACE(Swap::name(kind));
    Swap swap(kind);
    TempDir dir;
    const std::string target = dir.file("out");
    commitRun(target, kFirst);
    EXPECT_EQ(snapshot(target), snapshotOf(kFirst));
    commitRun(target, kSecond);
    EXPECT_EQ(snapshot(target), snapshotOf(kSecond));
    EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"out"});  // nothing hidden left beside it
  }
}

// Bug: commit() renamed file after file into an existing --out; a rename that
// failed part-way (here a file of the new run where the old run has a folder)
// left files of both runs.
TEST(OutputDirectory, ARenameErrorDuringCommitLeavesOneWholeRun) {
  TempDir dir;
  const std::string target = dir.file("out");
  commitRun(target, kFirst);
  const RunFiles second = {
      {"parcels.csv", "parcel_id\n2\n"}, {"figures", "a file now"}, {"run.json", kSecond.at("run.json")}};
  OutputDirectory out(target, {});
  for (const char* name : {"parcels.csv", "figures", "run.json"}) {
    std::ofstream(out.stage(name), std::ios::binary) << second.at(name);
  }
  bool failed = false;
  try {
    out.commit();
  } catch (const Error&) {
    failed = true;
  }
  EXPECT_EQ(snapshot(target), snapshotOf(failed ? kFirst : second)) << (failed ? "commit failed" : "commit succeeded");
}

// A failure at any step of the swap (a rename that fails) leaves the previous run
// byte for byte, and no staging folder once the OutputDirectory is gone.
TEST(OutputDirectory, AFailureDuringTheSwapLeavesThePreviousRunByteForByte) {
  const std::vector<std::pair<Swap::Kind, std::pair<const char*, int>>> faults = {
      {Swap::Exchange, {"swap", 1}},  {Swap::TwoRenames, {"swap", 1}}, {Swap::TwoRenames, {"aside", 1}},
      {Swap::Contents, {"swap", 1}},  {Swap::Contents, {"entry", 1}},  {Swap::Contents, {"entry", 2}},
      {Swap::Contents, {"aside", 1}}, {Swap::Contents, {"entry", 5}}};
  for (const auto& [kind, fault] : faults) {
    SCOPED_TRACE(std::string(Swap::name(kind)) + ", failing at " + fault.first + " " + std::to_string(fault.second));
    Swap swap(kind);
    TempDir dir;
    const std::string target = dir.file("out");
    commitRun(target, kFirst);
    {
      OutputDirectory out(target, {});
      stageRun(out, kSecond);
      Fault::arm(fault.first, fault.second, false);
      EXPECT_THROW(out.commit(), Error);
      OutputDirectoryTesting::step = nullptr;
    }
    EXPECT_EQ(snapshot(target), snapshotOf(kFirst));
    EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"out"});
    commitRun(target, kThird);  // and the next run goes through
    EXPECT_EQ(snapshot(target), snapshotOf(kThird));
    EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"out"});
  }
}

// A run killed at any step of the swap leaves what the next run turns back into
// one whole run: the previous one when it was not yet wholly out of the way, the
// new one after; no staging or set-aside folder remains.
TEST(OutputDirectory, ASwapKilledAtAnyStepIsUndoneOrCompletedByTheNextRun) {
  struct Case {
    Swap::Kind kind;
    const char* step;
    int count;
    bool nextRunFindsTheNew;  // the previous run was wholly out of the way: the swap is completed
  };
  const Case cases[] = {{Swap::Exchange, "swap", 1, false},    {Swap::Exchange, "placed", 1, true},
                        {Swap::TwoRenames, "swap", 1, false},  {Swap::TwoRenames, "aside", 1, false},
                        {Swap::TwoRenames, "placed", 1, true}, {Swap::Contents, "swap", 1, false},
                        {Swap::Contents, "entry", 2, false},   {Swap::Contents, "aside", 1, true},
                        {Swap::Contents, "entry", 4, true},    {Swap::Contents, "entry", 5, true},
                        {Swap::Contents, "placed", 1, true}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(Swap::name(c.kind)) + ", killed at " + c.step + " " + std::to_string(c.count));
    Swap swap(c.kind);
    TempDir dir;
    const std::string target = dir.file("out");
    commitRun(target, kFirst);
    const pid_t pid = ::fork();
    if (pid == 0) {
      OutputDirectory out(target, {});
      stageRun(out, kSecond);
      Fault::arm(c.step, c.count, true);
      out.commit();
      ::_exit(1);  // the step was never reached
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "commit() finished without reaching the step";
    { OutputDirectory next(target, {}); }  // cleans up, then writes nothing
    EXPECT_EQ(snapshot(target), snapshotOf(c.nextRunFindsTheNew ? kSecond : kFirst));
    EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"out"});
    commitRun(target, kThird);
    EXPECT_EQ(snapshot(target), snapshotOf(kThird));
  }
}

// Bug: `generate --out` into any folder replaced or mixed with what it held.
TEST(OutputDirectory, AFolderOfUnknownFilesIsRefusedAndLeftAsItWas) {
  for (Swap::Kind kind : kSwaps) {
    SCOPED_TRACE(Swap::name(kind));
    Swap swap(kind);
    for (const char* runJson : {"", R"({"tool": "other"})", "{ not json"}) {
      TempDir dir;
      const std::string target = dir.file("out");
      fs::create_directories(target + "/data");
      std::ofstream(target + "/notes.txt") << "mine";
      std::ofstream(target + "/data/x.csv") << "a,b\n";
      if (*runJson) std::ofstream(target + "/run.json") << runJson;
      const auto before = snapshot(target);
      try {
        OutputDirectory out(target, {});
        ADD_FAILURE() << "a folder of unknown files was accepted (run.json: " << runJson << ")";
        stageRun(out, kSecond);
        out.commit();
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), Error::Kind::Usage) << e.what();
        EXPECT_NE(std::string(e.what()).find(target), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("not a ParcelScope run"), std::string::npos) << e.what();
      }
      EXPECT_EQ(snapshot(target), before);
      EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"out"});
    }
    TempDir dir;  // an empty folder is taken
    fs::create_directories(dir.file("out"));
    commitRun(dir.file("out"), kSecond);
    EXPECT_EQ(snapshot(dir.file("out")), snapshotOf(kSecond));
  }
}

// Bug: a folder holding a previous run and the user's own files (notes beside
// the outputs, a file put in its figures folder) was replaced whole, deleting
// them. A run's record lists its outputs: anything else there is refused and
// kept. A shard's folder (shard.json) is a run too: an array job can be run
// again into it.
TEST(OutputDirectory, FilesBesideAPreviousRunsOutputsAreRefusedAndKept) {
  const RunFiles listed = {{"run.json", R"({"tool": "parcelscope", "outputs": ["parcels.csv", "figures/map.png"]})"},
                           {"parcels.csv", "parcel_id\n1\n"},
                           {"figures/map.png", "png"}};
  for (const char* mine : {"notes.txt", "figures/mine.txt", "data/x.csv"}) {
    TempDir dir;
    const std::string target = dir.file("out");
    commitRun(target, listed);
    fs::create_directories(fs::path(target + "/" + mine).parent_path());
    std::ofstream(target + "/" + mine) << "mine";
    const auto before = snapshot(target);
    try {
      OutputDirectory out(target, {});
      ADD_FAILURE() << mine << " beside a previous run was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), Error::Kind::Usage) << e.what();
      const std::string named = fs::path(mine).begin()->string() == "data" ? "data" : mine;
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
    EXPECT_EQ(snapshot(target), before);
  }
  TempDir dir;  // the run's own files only: replaced
  commitRun(dir.file("out"), listed);
  commitRun(dir.file("out"), kSecond);
  EXPECT_EQ(snapshot(dir.file("out")), snapshotOf(kSecond));
  const RunFiles shard = {{"shard.json", R"({"tool": "parcelscope", "outputs": ["shard.bin", "shard.json"]})"},
                          {"shard.bin", "bytes"}};
  commitRun(dir.file("shard"), shard);
  commitRun(dir.file("shard"), shard);
  EXPECT_EQ(snapshot(dir.file("shard")), snapshotOf(shard));
}

// Bug: an --out holding an input (e.g. `generate s/blocks.gpkg --out s`) was
// accepted; replacing it whole would delete the input.
TEST(OutputDirectory, AnOutContainingAnInputIsRefused) {
  TempDir dir;
  const std::string target = dir.file("out");
  commitRun(target, kFirst);
  const std::string direct = dir.write("out/blocks.gpkg", "gpkg");
  fs::create_directories(target + "/inputs");
  const std::string deeper = dir.write("out/inputs/parcels.geojson", "{}");
  fs::create_directory_symlink(target, dir.file("link"));
  const auto before = snapshot(target);
  for (const std::string& input : {direct, deeper, dir.file("link") + "/inputs/parcels.geojson"}) {
    for (const std::string& out : {target, target + "/", dir.file("link")}) {
      try {
        OutputDirectory o(out, {dir.file("other.geojson"), input});
        ADD_FAILURE() << out << " holding " << input << " was accepted";
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), Error::Kind::Usage) << e.what();
        EXPECT_NE(std::string(e.what()).find(out), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("input"), std::string::npos) << e.what();
      }
    }
  }
  EXPECT_EQ(snapshot(target), before);
  // Nor inside a folder that is an input (a folder dataset).
  EXPECT_THROW(OutputDirectory(target + "/inputs/out", {target + "/inputs"}), Error);
  EXPECT_FALSE(fs::exists(target + "/inputs/out"));
  EXPECT_EQ(entries(dir.path()), (std::vector<std::string>{"link", "out"}));
}

// Bug: with --out on another filesystem the staging folder was made in the
// parent and every rename failed with "Invalid cross-device link".
TEST(OutputDirectory, AMountPointIsFilledInPlace) {
  TempDir dir;
  const std::string mount = dir.file("mnt");
  fs::create_directories(mount);
  const auto result = withMounts({{mount, false}}, [&]() -> std::string {
    commitRun(mount, kFirst);
    if (snapshot(mount) != snapshotOf(kFirst)) return "the first run is not whole in the mount point";
    commitRun(mount, kSecond);
    if (snapshot(mount) != snapshotOf(kSecond)) return "the second run is not alone in the mount point";
    if (entries(dir.path()) != std::vector<std::string>{"mnt"}) return "something was left beside the mount point";
    std::ofstream(mount + "/notes.txt") << "mine";
    std::filesystem::remove(mount + "/run.json");
    try {
      OutputDirectory out(mount, {});
      return "a mount point holding unknown files was accepted";
    } catch (const Error&) {
    }
    return "";
  });
  if (!result) GTEST_SKIP() << "no permission to make a mount namespace with a tmpfs";
  EXPECT_EQ(*result, "");
}

// Bug: errors named the hidden staging folder, or said "Invalid cross-device
// link" for a read-only mount, instead of --out and the real cause.
TEST(OutputDirectory, ErrorsNameTheOutputFolderAndTheCause) {
  auto message = [](const std::string& target) -> std::string {
    try {
      OutputDirectory out(target, {});
      std::ofstream(out.stage("parcels.csv")) << "x\n";
      out.commit();
    } catch (const Error& e) {
      return e.kind() == Error::Kind::IO ? e.what() : std::string("not an I/O error: ") + e.what();
    }
    return "no error";
  };
  auto check = [&](const std::string& target, const std::string& cause) -> std::string {
    const std::string m = message(target);
    if (m.rfind(target + ":", 0) != 0 || m.find(cause) == std::string::npos ||
        m.find(".partial") != std::string::npos) {
      return "for " + target + " expected an error naming it and \"" + cause + "\", got: " + m + "\n";
    }
    return "";
  };
  TempDir dir;
  const std::string readOnly = dir.file("ro");
  fs::create_directories(readOnly);
  const auto result = withMounts({{readOnly, true}}, [&]() -> std::string {
    return check(readOnly + "/out", "Read-only file system") +  // parent on a read-only mount
           check(readOnly, "Read-only file system");            // --out a read-only mount point
  });
  if (result) {
    EXPECT_EQ(*result, "");
  } else if (::geteuid() != 0) {  // no mount namespace: a folder without write permission
    fs::permissions(readOnly, fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_EQ(check(readOnly + "/out", "Permission denied"), "");
    fs::permissions(readOnly, fs::perms::owner_all);
  } else {
    GTEST_SKIP() << "root without permission to make a mount namespace";
  }
}

// Bug: a full disk failed with a message of the writer naming the hidden
// staging folder (and, for a GeoPackage, "no such table: gpkg_geometry_columns").
TEST(OutputDirectory, AWriteErrorIsToldAsTheOutputFoldersWithItsCause) {
  TempDir dir;
  const std::string small = dir.file("small");
  fs::create_directories(small);
  const auto result = withMounts({{small, false}}, [&]() -> std::string {
    const std::string target = small + "/out";
    OutputDirectory out(target, {});
    const std::string staged = out.stage("parcels.csv");
    std::ofstream file(staged, std::ios::binary);
    const std::string row(4096, 'x');
    for (int i = 0; i < 2048 && file; ++i) file << row << '\n';  // 8 MB into 4 MB
    file.close();
    if (file) return "the write did not fail";
    const std::string m = out.explain(ioError(staged + ": cannot write")).what();
    if (m != target + "/parcels.csv: cannot write (No space left on device: 0 KiB free)") return "explained as: " + m;
    return "";
  });
  if (!result) GTEST_SKIP() << "no permission to make a mount namespace with a tmpfs";
  EXPECT_EQ(*result, "");
}

// Bug: the staging folder's name (".NAME.partial-PID") was too long for a
// folder name of 250 characters.
TEST(OutputDirectory, ALongFolderNameStillStages) {
  TempDir dir;
  const std::string target = dir.file(std::string(250, 'x'));
  commitRun(target, kFirst);
  commitRun(target, kSecond);
  EXPECT_EQ(snapshot(target), snapshotOf(kSecond));
  EXPECT_EQ(entries(dir.path()).size(), 1u);
}

TEST(StagedFile, AppearsOnlyOnCommitAndNeverOverwritesAnInput) {
  TempDir dir;
  const std::string target = dir.file("figure.png");
  {
    StagedFile f(target, {});
    EXPECT_EQ(fs::path(f.path()).extension(), ".png");
    EXPECT_EQ(fs::path(f.path()).parent_path(), dir.path());
    std::ofstream(f.path()) << "half";
    EXPECT_FALSE(fs::exists(target));
  }  // not committed: nothing left behind
  EXPECT_FALSE(fs::exists(target));
  EXPECT_TRUE(fs::is_empty(dir.path()));
  {
    StagedFile f(target, {});
    std::ofstream(f.path()) << "whole";
    f.commit();
  }
  EXPECT_EQ(test::slurpFile(target), "whole");
  const std::string input = dir.write("input.geojson", "{}");
  EXPECT_THROW(StagedFile(input, {input}), Error);
  EXPECT_THROW(StagedFile(dir.path().string(), {}), Error);
  EXPECT_THROW(StagedFile(dir.file("missing/x.png"), {}), Error);
}

TEST(Writers, ReadJsonKeepsTypesAndOrderAndNamesTheFileOnError) {
  TempDir dir;
  const std::string path = dir.write("a.json", R"({"b": 1, "a": [2.5, "x", true, null], "c": {"d": -3}})");
  const Json j = readJson(path);
  const auto members = j.members();
  ASSERT_EQ(members.size(), 3u);
  EXPECT_EQ(members[0].first, "b");
  EXPECT_EQ(j.find("b")->number(), 1);
  const auto a = j.find("a")->elements();
  ASSERT_EQ(a.size(), 4u);
  EXPECT_EQ(a[0].number(), 2.5);
  EXPECT_EQ(a[1].string(), "x");
  EXPECT_TRUE(a[2].boolean());
  EXPECT_TRUE(a[3].isNull());
  EXPECT_EQ(j.find("c")->find("d")->number(), -3);
  EXPECT_EQ(j.find("z"), nullptr);
  const std::string bad = dir.write("bad.json", "{\"a\": ");
  try {
    readJson(bad);
    FAIL() << "expected Error(Input)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Input);
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos);
  }
  EXPECT_THROW(readJson(dir.file("none.json")), Error);
}

TEST(Writers, PolygonLayerAsGeoJson) {
  TempDir dir;
  const LocalFrame frame = LocalFrame::geographic(2.35, 48.85);
  CrsInfo crs;
  crs.assumedLonLat = true;
  Table attrs;
  attrs.columns = {{"block_id", Column::Type::Integer, ""}};
  attrs.rows = {{std::int64_t(3)}, {std::int64_t(4)}};
  const std::string path = dir.file("parcels.geojson");
  writePolygonLayer(path, "parcels", {{rect(0, 0, 10, 10)}, {rect(10, 0, 20, 10)}}, attrs, frame, crs);
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(ds);
  EXPECT_STREQ(ds->GetDriver()->GetDescription(), "GeoJSON");
  OGRLayer* layer = ds->GetLayer(0);
  ASSERT_EQ(layer->GetFeatureCount(), 2);
  auto f = std::unique_ptr<OGRFeature>(layer->GetNextFeature());
  EXPECT_EQ(f->GetFieldAsInteger64("block_id"), 3);
}

TEST(Writers, PolygonLayerGoesBackToTheInputCrs) {
  TempDir dir;
  const LocalFrame frame = LocalFrame::geographic(2.35, 48.85);
  CrsInfo crs;
  crs.assumedLonLat = true;  // no WKT: written as OGC:CRS84
  Table attrs;
  attrs.columns = {{"block_id", Column::Type::Integer, ""}, {"area", Column::Type::Real, "m2"}};
  attrs.rows = {{std::int64_t(7), 100.0}};
  const std::string path = dir.file("blocks.gpkg");
  writePolygonLayer(path, "blocks", {{rect(0, 0, 10, 10)}}, attrs, frame, crs);

  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(ds);
  OGRLayer* layer = ds->GetLayerByName("blocks");
  ASSERT_NE(layer, nullptr);
  ASSERT_EQ(layer->GetFeatureCount(), 1);
  auto f = std::unique_ptr<OGRFeature>(layer->GetNextFeature());
  EXPECT_EQ(f->GetFieldAsInteger64("block_id"), 7);
  OGREnvelope e;
  f->GetGeometryRef()->getEnvelope(&e);
  EXPECT_NEAR(e.MinX, 2.35, 1e-9);
  EXPECT_NEAR(e.MinY, 48.85, 1e-9);
  double lat2 = 0, lon2 = 0;  // 10 m east of the frame's centre along a geodesic
  GeographicLib::Geodesic::WGS84().Direct(48.85, 2.35, 90.0, 10.0, lat2, lon2);
  EXPECT_NEAR(e.MaxX - e.MinX, lon2 - 2.35, 1e-9);  // 0.07 mm
  ASSERT_NE(layer->GetSpatialRef(), nullptr);
  EXPECT_TRUE(layer->GetSpatialRef()->IsGeographic());
}

// Polygons valid in local metres that are not once mapped back to lon/lat:
// edges straight in metres are not straight in degrees (a 200 m east-west
// edge is off by about 0.7 mm in the middle), and points closer than about
// 1e-9 m merge in degrees. The file holds what users read: every feature
// valid there, with its area.
TEST(Writers, PolygonLayerIsValidInTheCrsWritten) {
  TempDir dir;
  const LocalFrame frame = LocalFrame::geographic(-71.1, 42.38);
  auto mapped = [&](Polygon p) {
    for (Point& q : p.outer) q = frame.toSource(q);
    for (Ring& h : p.holes)
      for (Point& q : h) q = frame.toSource(q);
    return p;
  };
  // A notch from below reaching 10 micrometres under a long east-west edge,
  // and the same mirrored: one of the two crosses that edge once mapped.
  auto notched = [](double side) {
    Polygon p{{{-100, 0},
               {-100, -50 * side},
               {-1, -50 * side},
               {0, -1e-5 * side},
               {1, -50 * side},
               {100, -50 * side},
               {100, 0}},
              {}};
    normalise(p);
    return p;
  };
  // A ring that comes back 1e-11 m from one of its vertices (a lobe in the
  // notch): apart in metres, the same point in degrees.
  Polygon pinched{{{0, 0}, {40, 0}, {40, 30}, {20, 10}, {25, 30}, {15, 30}, {20, 10 + 1e-11}, {0, 30}}, {}};
  normalise(pinched);
  const std::vector<std::vector<Polygon>> geometries = {{notched(1)}, {notched(-1)}, {pinched}};
  int invalidOnceMapped = 0;
  for (const auto& g : geometries) {
    ASSERT_TRUE(geos::isValid(g.front()));
    invalidOnceMapped += !geos::isValid(mapped(g.front()));
  }
  ASSERT_EQ(invalidOnceMapped, 2) << "the cases no longer test what they should";

  Table attrs;
  attrs.columns = {{"id", Column::Type::Integer, ""}};
  attrs.rows = {{std::int64_t(0)}, {std::int64_t(1)}, {std::int64_t(2)}};
  CrsInfo crs;
  crs.assumedLonLat = true;
  const std::string path = dir.file("parcels.gpkg");
  const LayerWrite written = writePolygonLayer(path, "parcels", geometries, attrs, frame, crs);
  EXPECT_EQ(written.features, 3);
  EXPECT_EQ(written.repaired, 2);
  EXPECT_EQ(written.emptied, 0);

  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(ds);
  OGRLayer* layer = ds->GetLayer(0);
  ASSERT_EQ(layer->GetFeatureCount(), 3);
  for (auto& f : *layer) {
    const OGRGeometry* g = f->GetGeometryRef();
    ASSERT_NE(g, nullptr);
    EXPECT_TRUE(g->IsValid()) << "feature " << f->GetFieldAsInteger64("id");
    // The area is that of the polygon mapped as it is (both in square
    // degrees): the repair moved nothing of substance.
    const Polygon original = mapped(geometries[static_cast<std::size_t>(f->GetFieldAsInteger64("id"))].front());
    const double expected = std::fabs(signedArea(original.outer));
    EXPECT_NEAR(g->toMultiPolygon()->get_Area(), expected, 1e-6 * expected)
        << "feature " << f->GetFieldAsInteger64("id");
  }
}

}  // namespace
}  // namespace parcelscope::io
