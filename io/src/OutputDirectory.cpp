#include "parcelscope/io/OutputDirectory.h"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>  // renameat2 and RENAME_EXCHANGE (glibc 2.28, Linux 3.15)
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include "VectorInput.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Json.h"
#include "parcelscope/io/Writers.h"

namespace fs = std::filesystem;

namespace parcelscope::io {

namespace {

// Hidden folders inside a target whose contents are swapped (mount point):
// ".parcelscope-partial-U" (the run being written), ".parcelscope-old-U" (the
// previous run being moved aside), ".parcelscope-replaced-U" (the previous run,
// wholly aside: from here the swap is completed, never undone). U is "PID-N".
const std::string kInside = ".parcelscope-";

std::string causeOf(int error) { return std::generic_category().message(error); }

bool sameFile(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  return fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec);
}

void step(const char* name) {
  if (OutputDirectoryTesting::step) OutputDirectoryTesting::step(name);
}

// Whether `p` is `folder` or lies inside it. Each ancestor is compared by
// identity, so symbolic links and different spellings of a path count.
bool within(fs::path p, const fs::path& folder) {
  for (;;) {
    if (sameFile(p, folder)) return true;
    fs::path up = p.parent_path();
    if (up.empty() || up == p) return false;
    p = std::move(up);
  }
}

// Where an input lies on disk: its path, or for a GDAL virtual path
// ("/vsizip//data/a.zip/x.shp") the longest part of it that exists; nothing for
// what is not a file (a database connection string).
std::optional<fs::path> locationOf(const std::string& input) {
  std::error_code ec;
  if (input.rfind("/vsi", 0) != 0) {
    if (fs::exists(fs::symlink_status(input, ec))) return fs::absolute(input, ec).lexically_normal();
    return std::nullopt;
  }
  const auto slash = input.find('/', 1);
  if (slash == std::string::npos) return std::nullopt;
  for (fs::path p = fs::path(input.substr(slash + 1)).lexically_normal(); !p.empty(); p = p.parent_path()) {
    if (p.has_relative_path() && fs::exists(p, ec)) return fs::absolute(p, ec);
    if (p == p.parent_path()) break;
  }
  return std::nullopt;
}

// The input (of `inputs`) that is `folder` or lies inside it, if any.
std::optional<std::string> inputWithin(const std::vector<std::string>& inputs, const fs::path& folder) {
  std::error_code ec;
  for (const auto& in : inputs) {
    const auto where = locationOf(in);
    if (!where) continue;
    if (within(*where, folder) || within(fs::weakly_canonical(*where, ec), folder)) return in;
  }
  return std::nullopt;
}

// A ParcelScope run's record in `folder`: its run.json (or a shard's
// shard.json) whose "tool" is "parcelscope".
std::optional<std::pair<std::string, Json>> runRecord(const fs::path& folder) {
  for (const char* name : {"run.json", "shard.json"}) {
    std::error_code ec;
    const fs::path record = folder / name;
    if (!fs::is_regular_file(record, ec)) continue;
    try {
      Json run = readJson(record.string());
      const Json* tool = run.find("tool");
      if (tool && tool->isString() && tool->string() == "parcelscope") return std::make_pair(std::string(name), run);
    } catch (const Error&) {
    }
  }
  return std::nullopt;
}

// The first file or folder in `folder` (a previous run) that its record does
// not list among its outputs: something of the user's, which replacing the
// folder would delete (the staging folders, and lost+found at a mount point,
// are not). Empty when there is none (or the record lists no
// outputs, as runs before the list did).
std::string foreignEntry(const fs::path& folder, bool inside, const std::string& recordName, const Json& record) {
  const Json* outputs = record.find("outputs");
  if (!outputs || !outputs->isArray()) return "";
  std::set<std::string> files{recordName}, folders;
  for (const Json& output : outputs->elements()) {
    if (!output.isString()) continue;
    const fs::path p = fs::path(output.string()).lexically_normal();
    files.insert(p.generic_string());
    for (fs::path up = p.parent_path(); !up.empty(); up = up.parent_path()) folders.insert(up.generic_string());
  }
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(folder, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    const std::string relative = fs::relative(it->path(), folder, ec).generic_string();
    if (relative.rfind(kInside, 0) == 0 || (inside && relative == "lost+found")) {
      it.disable_recursion_pending();
      continue;
    }
    const bool listed = it->is_directory(ec) ? folders.count(relative) > 0 : files.count(relative) > 0;
    if (!listed) return relative;
  }
  return "";
}

// Whether `dir` (existing, absolute, canonical) is the root of a mount: renames
// into or out of it from its parent fail (EXDEV, EBUSY).
bool isMountPoint(const fs::path& dir) {
  const fs::path parent = dir.parent_path();
  struct stat a = {};
  struct stat b = {};
  if (::stat(dir.c_str(), &a) != 0 || ::stat(parent.c_str(), &b) != 0) return false;
  if (a.st_dev != b.st_dev || a.st_ino == b.st_ino) return true;  // another filesystem, or "/"
#if defined(__linux__) && defined(STATX_MNT_ID)
  struct statx x = {};  // a bind mount of the same filesystem
  struct statx y = {};
  if (::statx(AT_FDCWD, dir.c_str(), 0, STATX_MNT_ID, &x) == 0 &&
      ::statx(AT_FDCWD, parent.c_str(), 0, STATX_MNT_ID, &y) == 0 && (x.stx_mask & STATX_MNT_ID) &&
      (y.stx_mask & STATX_MNT_ID)) {
    return x.stx_mnt_id != y.stx_mnt_id;
  }
#endif
  return false;
}

// The name of the target as it appears in the hidden folders beside it: the
// name itself, or a shortened name and a hash when the suffixes would make a
// folder name longer than filesystems allow (255 bytes).
std::string hiddenKey(const std::string& name) {
  if (name.size() <= 96) return name;
  std::uint64_t hash = 14695981039346656037ull;  // FNV-1a
  for (unsigned char c : name) hash = (hash ^ c) * 1099511628211ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return name.substr(0, 64) + "~" + hex;
}

// The process that wrote a hidden folder named "...-PID-N" (or "...-PID", as
// before N was added) has ended.
bool writerEnded(const std::string& unique) {
  const auto digits = [](const std::string& t) {
    return !t.empty() && t.size() <= 9 && t.find_first_not_of("0123456789") == std::string::npos;
  };
  const auto dash = unique.find('-');
  const std::string pid = unique.substr(0, dash);
  if (!digits(pid) || (dash != std::string::npos && !digits(unique.substr(dash + 1)))) return false;
  const long value = std::stol(pid);
  return value > 0 && ::kill(static_cast<pid_t>(value), 0) != 0 && errno == ESRCH;
}

// rename(2), or Error(IO) "`failure` (cause)".
void renameOr(const fs::path& from, const fs::path& to, const std::string& failure) {
  if (::rename(from.c_str(), to.c_str()) == 0) return;
  const int error = errno;
  throw ioError(failure + " (" + causeOf(error) + ")");
}

// Moves every entry of `from` into `to` (an existing entry of the same name
// is replaced when it is a file or an empty folder); true when all moved.
bool moveEntries(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  bool all = true;
  std::vector<fs::path> names;
  for (const auto& e : fs::directory_iterator(from, ec)) names.push_back(e.path().filename());
  if (ec) return false;
  for (const auto& name : names) all = ::rename((from / name).c_str(), (to / name).c_str()) == 0 && all;
  return all;
}

// The entries of a run in `folder`: all but the hidden folders of swaps (and a
// filesystem's lost+found when the run is swapped inside a mount point).
std::vector<fs::path> runEntries(const fs::path& folder, bool inside, std::error_code& ec) {
  std::vector<fs::path> names;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(kInside, 0) == 0 || (inside && name == "lost+found")) continue;
    names.push_back(e.path().filename());
  }
  return names;
}

}  // namespace

OutputDirectory::OutputDirectory(std::string target, const std::vector<std::string>& inputs)
    : target_(std::move(target)), inputs_(inputs) {
  // The files a folder, list or VRT input names are inputs too.
  for (const std::string& in : inputs) {
    for (std::string& f : detail::filesReadWith(in)) inputs_.push_back(std::move(f));
  }
  static std::atomic<unsigned> count{0};
  unique_ = std::to_string(::getpid()) + "-" + std::to_string(count++);
  std::error_code ec;
  if (target_.empty()) throw usageError("--out: an output directory is required");
  if (fs::exists(target_, ec) && !fs::is_directory(target_, ec)) {
    throw usageError(target_ + ": --out names an existing file, not a directory");
  }
  fs::path d = fs::absolute(fs::path(target_), ec).lexically_normal();
  if (d.filename().empty()) d = d.parent_path();  // "out/"
  const fs::path resolved = fs::weakly_canonical(d, ec);
  if (!ec) d = resolved;
  destination_ = d.string();
  const fs::path parent = d.parent_path();
  // Refused before anything is touched: an --out inside an input folder (a
  // folder dataset); --out holding an input is refused by checkTarget().
  for (const auto& in : inputs_) {
    const auto where = locationOf(in);
    if (!where || !fs::is_directory(*where, ec)) continue;
    fs::path existing = d;
    while (!fs::exists(existing, ec) && existing.has_relative_path()) existing = existing.parent_path();
    if (within(existing, *where)) throw usageError(target_ + ": --out lies inside the input " + in);
  }
  const bool exists = fs::is_directory(d, ec);
  // Renames between the target and its parent fail across filesystems (EXDEV),
  // for a mount point (EBUSY) and in a parent that cannot be written: stage
  // inside the target then.
  inside_ =
      exists && (OutputDirectoryTesting::stageInside || isMountPoint(d) || ::access(parent.c_str(), W_OK | X_OK) != 0);
  recoverLeftovers();
  checkTarget();
  if (inside_) {
    staging_ = (d / (kInside + "partial-" + unique_)).string();
    if (!fs::create_directory(staging_, ec))
      throw ioError(target_ + ": cannot write into --out (" + ec.message() + ")");
    return;
  }
  if (!fs::exists(parent, ec)) {
    fs::create_directories(parent, ec);
    if (ec) throw ioError(target_ + ": cannot create the folder " + parent.string() + " (" + ec.message() + ")");
  }
  staging_ = (parent / ("." + hiddenKey(d.filename().string()) + ".partial-" + unique_)).string();
  if (!fs::create_directory(staging_, ec)) {
    throw ioError(target_ + ": cannot create the output folder (" + ec.message() + ")");
  }
}

OutputDirectory::~OutputDirectory() {
  std::error_code ec;
  if (!staging_.empty()) fs::remove_all(staging_, ec);  // after commit() gone, or the previous run's remains
}

void OutputDirectory::recoverLeftovers() const {
  std::error_code ec;
  const fs::path d(destination_);
  // Beside the target: ".KEY.partial-U" (a staging folder, or a previous run
  // being deleted) is removed; ".KEY.old-U" (the previous run, renamed aside by
  // a swap with two renames) goes back when the new run never arrived.
  const std::string prefix = "." + hiddenKey(d.filename().string()) + ".";
  std::vector<fs::path> old, partial;
  for (const auto& e : fs::directory_iterator(d.parent_path(), ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    for (auto [kind, list] : {std::pair{std::string("old-"), &old}, std::pair{std::string("partial-"), &partial}}) {
      if (rest.rfind(kind, 0) == 0 && writerEnded(rest.substr(kind.size()))) list->push_back(e.path());
    }
  }
  for (const auto& p : old) {
    if (inputWithin(inputs_, p)) continue;
    if (!fs::exists(d, ec) && ::rename(p.c_str(), d.c_str()) == 0) continue;
    fs::remove_all(p, ec);
  }
  for (const auto& p : partial) {
    if (!inputWithin(inputs_, p)) fs::remove_all(p, ec);
  }
  if (!fs::is_directory(d, ec)) return;
  // Inside the target (a swap of contents): a swap killed while the previous
  // run was moving aside is undone, one killed after it is completed.
  std::map<std::string, std::map<std::string, fs::path>> swaps;  // U -> kind -> folder
  for (const auto& e : fs::directory_iterator(d, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(kInside, 0) != 0) continue;
    const std::string rest = name.substr(kInside.size());
    const auto dash = rest.find('-');
    if (dash == std::string::npos || !writerEnded(rest.substr(dash + 1))) continue;
    swaps[rest.substr(dash + 1)][rest.substr(0, dash)] = e.path();
  }
  for (auto& [unique, folders] : swaps) {
    bool touchesInput = false;
    for (const auto& [kind, p] : folders) touchesInput = touchesInput || inputWithin(inputs_, p).has_value();
    if (touchesInput) continue;
    const auto has = [&](const char* kind) { return folders.count(kind) > 0; };
    if (has("old")) {
      if (moveEntries(folders["old"], d)) fs::remove(folders["old"], ec);
      if (has("partial")) fs::remove_all(folders["partial"], ec);
    } else if (has("replaced")) {
      if (has("partial") && !moveEntries(folders["partial"], d)) continue;  // not all in place: keep both
      if (has("partial")) fs::remove(folders["partial"], ec);
      fs::remove_all(folders["replaced"], ec);
    } else if (has("partial")) {
      fs::remove_all(folders["partial"], ec);
    }
  }
}

void OutputDirectory::checkTarget() const {
  const fs::path d(destination_);
  std::error_code ec;
  if (!fs::exists(d, ec)) return;
  if (const auto in = inputWithin(inputs_, d)) {
    throw usageError(target_ + ": --out holds the input " + *in + " (a run replaces its folder whole)");
  }
  const auto entries = runEntries(d, inside_, ec);
  if (ec) throw ioError(target_ + ": cannot read --out (" + ec.message() + ")");
  if (entries.empty()) return;
  const auto record = runRecord(d);
  if (!record) {
    throw usageError(target_ +
                     ": --out holds files that are not a ParcelScope run (no run.json written by parcelscope); "
                     "a run replaces its folder whole, so name a new or empty folder");
  }
  if (const std::string foreign = foreignEntry(d, inside_, record->first, record->second); !foreign.empty()) {
    throw usageError(target_ + ": --out holds " + foreign + ", which is not an output of the run there (" +
                     record->first + "); a run replaces its folder whole, so move it or name another folder");
  }
}

std::string OutputDirectory::stage(const std::string& name) {
  const fs::path relative = fs::path(name).lexically_normal();
  if (name.empty() || relative.is_absolute() || *relative.begin() == "..") {
    throw usageError(target_ + ": " + name + " is not a name inside --out");
  }
  const fs::path staged = fs::path(staging_) / relative;
  std::error_code ec;
  fs::create_directories(staged.parent_path(), ec);  // names may hold folders, e.g. figures/map.png
  if (ec) throw ioError(target_ + ": cannot write " + name + " (" + ec.message() + ")");
  return staged.string();
}

Error OutputDirectory::explain(const Error& e) const {
  std::string message = e.what();
  std::string shown = target_;
  while (shown.size() > 1 && shown.back() == '/') shown.pop_back();
  for (std::size_t at; !staging_.empty() && (at = message.find(staging_)) != std::string::npos;) {
    message.replace(at, staging_.size(), shown);
  }
  struct statvfs filesystem {};
  if (e.kind() == Error::Kind::IO && ::statvfs(staging_.c_str(), &filesystem) == 0) {
    const unsigned long long free = static_cast<unsigned long long>(filesystem.f_bavail) * filesystem.f_frsize;
    if ((filesystem.f_flag & ST_RDONLY) && message.find(causeOf(EROFS)) == std::string::npos) {
      message += " (" + causeOf(EROFS) + ")";
    } else if (free < (1ull << 20) && message.find(causeOf(ENOSPC)) == std::string::npos) {
      message += " (" + causeOf(ENOSPC) + ": " + std::to_string(free / 1024) + " KiB free)";
    }
  }
  return Error(e.kind(), message);
}

void OutputDirectory::commit() {
  if (committed_) return;
  step("swap");
  checkTarget();  // nothing unknown was put there in the meantime
  if (inside_) {
    commitInside();
  } else {
    commitBeside();
  }
}

void OutputDirectory::commitBeside() {
  const char* d = destination_.c_str();
  std::error_code ec;
  if (!fs::exists(destination_, ec)) {
    if (::rename(staging_.c_str(), d) == 0) {  // the whole folder appears at once
      step("placed");
      committed_ = true;
      return;
    }
    const int error = errno;
    if (error != EEXIST && error != ENOTEMPTY) {  // else it appeared meanwhile: swap
      throw ioError(target_ + ": cannot move the run into place (" + causeOf(error) + ")");
    }
  }
#if defined(__linux__) && defined(RENAME_EXCHANGE)
  if (!OutputDirectoryTesting::noExchange) {
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, d, RENAME_EXCHANGE) == 0) {
      step("placed");
      committed_ = true;
      fs::remove_all(staging_, ec);  // the previous run, under the staging name
      return;
    }
    const int error = errno;
    if (error != EINVAL && error != ENOSYS && error != ENOTSUP && error != EOPNOTSUPP) {
      throw ioError(target_ + ": cannot replace the previous run (" + causeOf(error) + ")");
    }  // else this filesystem cannot exchange: two renames
  }
#endif
  // Two renames: a kill between them leaves no target, and the next run renames
  // the previous run back (recoverLeftovers).
  const fs::path old = fs::path(destination_).parent_path() /
                       ("." + hiddenKey(fs::path(destination_).filename().string()) + ".old-" + unique_);
  renameOr(d, old, target_ + ": cannot move the previous run aside");
  try {
    step("aside");
    renameOr(staging_, d, target_ + ": cannot move the run into place");
  } catch (...) {
    ::rename(old.c_str(), d);
    throw;
  }
  step("placed");
  committed_ = true;
  // Deleted under the staging name, so that what a kill leaves is removed, never put back.
  if (::rename(old.c_str(), staging_.c_str()) == 0) {
    fs::remove_all(staging_, ec);
  } else {
    fs::remove_all(old, ec);
  }
}

void OutputDirectory::commitInside() {
  const fs::path d(destination_), staging(staging_);
  const fs::path old = d / (kInside + "old-" + unique_), replaced = d / (kInside + "replaced-" + unique_);
  std::error_code ec;
  const auto previous = runEntries(d, true, ec);
  if (ec) throw ioError(target_ + ": cannot read --out (" + ec.message() + ")");
  if (!fs::create_directory(old, ec)) throw ioError(target_ + ": cannot write into --out (" + ec.message() + ")");
  fs::path aside = old;  // where the previous run's entries are
  std::vector<fs::path> moved, placed;
  try {
    for (const auto& name : previous) {
      step("entry");
      renameOr(d / name, old / name, target_ + ": cannot move " + name.string() + " of the previous run aside");
      moved.push_back(name);
    }
    renameOr(old, replaced, target_ + ": cannot move the previous run aside");
    aside = replaced;
    step("aside");
    const auto entries = runEntries(staging, false, ec);
    if (ec) throw ioError(target_ + ": cannot read the staged run (" + ec.message() + ")");
    for (const auto& name : entries) {
      step("entry");
      renameOr(staging / name, d / name, target_ + ": cannot move " + name.string() + " into place");
      placed.push_back(name);
    }
  } catch (...) {  // the previous run goes back
    for (const auto& name : placed) ::rename((d / name).c_str(), (staging / name).c_str());
    // Named "old" again first: what cannot be moved back now is restored by the next run, not deleted.
    if (aside == replaced && ::rename(replaced.c_str(), old.c_str()) == 0) aside = old;
    for (const auto& name : moved) ::rename((aside / name).c_str(), (d / name).c_str());
    fs::remove(aside, ec);  // when empty
    throw;
  }
  step("placed");
  committed_ = true;
  fs::remove(staging, ec);
  fs::remove_all(replaced, ec);
}

StagedFile::StagedFile(std::string target, const std::vector<std::string>& inputs) : target_(std::move(target)) {
  std::error_code ec;
  if (target_.empty()) throw usageError("an output file name is required");
  if (fs::is_directory(target_, ec)) throw usageError(target_ + ": is a folder, not a file");
  for (const auto& in : inputs) {
    if (sameFile(target_, in)) throw usageError(target_ + ": output would overwrite an input");
  }
  const fs::path t(target_);
  const fs::path folder = t.parent_path().empty() ? fs::path(".") : t.parent_path();
  if (!fs::is_directory(folder, ec)) throw ioError(target_ + ": folder " + folder.string() + " does not exist");
  staging_ =
      (folder / ("." + t.stem().string() + ".partial-" + std::to_string(::getpid()) + t.extension().string())).string();
  fs::remove(staging_, ec);
}

StagedFile::~StagedFile() {
  std::error_code ec;
  if (!committed_) fs::remove(staging_, ec);
}

void StagedFile::commit() {
  std::error_code ec;
  if (!fs::exists(staging_, ec)) throw ioError(target_ + ": nothing was written");
  fs::rename(staging_, target_, ec);
  if (ec) throw ioError(target_ + ": cannot move into place (" + ec.message() + ")");
  committed_ = true;
}

}  // namespace parcelscope::io
