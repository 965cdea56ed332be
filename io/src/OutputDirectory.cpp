#include "parcelscope/io/OutputDirectory.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>

#include <filesystem>

#include "parcelscope/core/Error.h"

namespace fs = std::filesystem;

namespace parcelscope::io {

namespace {
bool sameFile(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  return fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec);
}
}  // namespace

OutputDirectory::OutputDirectory(std::string target, const std::vector<std::string>& inputs)
    : target_(std::move(target)), inputs_(inputs) {
  std::error_code ec;
  if (target_.empty()) throw usageError("--out: an output directory is required");
  if (fs::exists(target_, ec) && !fs::is_directory(target_, ec)) {
    throw usageError(target_ + ": --out names an existing file, not a directory");
  }
  for (const auto& in : inputs_) {
    if (sameFile(target_, in)) throw usageError(target_ + ": --out is an input");
  }
  fs::path t = fs::absolute(fs::path(target_)).lexically_normal();
  if (t.filename().empty()) t = t.parent_path();
  const fs::path parent = t.parent_path();
  if (!fs::exists(parent, ec)) {
    fs::create_directories(parent, ec);
    if (ec) throw ioError(target_ + ": cannot create parent directory (" + ec.message() + ")");
  }
  const std::string prefix = "." + t.filename().string() + ".partial-";
  // Staging folders of runs that were killed (their process is gone) are removed.
  for (const auto& entry : fs::directory_iterator(parent, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string pid = name.substr(prefix.size());
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (::kill(static_cast<pid_t>(std::stol(pid)), 0) != 0 && errno == ESRCH) fs::remove_all(entry.path(), ec);
  }
  staging_ = (parent / (prefix + std::to_string(::getpid()))).string();
  fs::remove_all(staging_, ec);
  if (!fs::create_directory(staging_, ec)) {
    throw ioError(target_ + ": cannot create staging directory " + staging_ + " (" + ec.message() + ")");
  }
}

OutputDirectory::~OutputDirectory() {
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

std::string OutputDirectory::stage(const std::string& name) {
  const fs::path final = fs::path(target_) / name;
  for (const auto& in : inputs_) {
    if (sameFile(final, in)) throw usageError(final.string() + ": output would overwrite an input");
  }
  names_.push_back(name);
  const fs::path staged = fs::path(staging_) / name;
  std::error_code ec;
  fs::create_directories(staged.parent_path(), ec);  // names may hold folders, e.g. figures/map.png
  if (ec) throw ioError(staged.parent_path().string() + ": cannot create staging folder (" + ec.message() + ")");
  return staged.string();
}

void OutputDirectory::commit() {
  std::error_code ec;
  if (!fs::exists(target_, ec)) {
    fs::rename(staging_, target_, ec);  // the whole folder appears at once
    if (!ec) {
      committed_ = true;
      return;
    }
    fs::create_directories(target_, ec);
    if (ec) throw ioError(target_ + ": cannot create output directory (" + ec.message() + ")");
  }
  for (const auto& name : names_) {
    const fs::path from = fs::path(staging_) / name;
    if (!fs::exists(from, ec)) continue;
    fs::create_directories((fs::path(target_) / name).parent_path(), ec);
    fs::rename(from, fs::path(target_) / name, ec);
    if (ec) throw ioError((fs::path(target_) / name).string() + ": cannot move into place (" + ec.message() + ")");
  }
  committed_ = true;
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
  staging_ = (folder / ("." + t.stem().string() + ".partial-" + std::to_string(::getpid()) + t.extension().string()))
                 .string();
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
