#pragma once
// An output directory that is never left half-written. Files are written into a
// hidden staging folder beside the target; commit() moves them into the target
// (each move an atomic rename) and removes the staging folder. Without commit(),
// the destructor removes the staging folder and the target is untouched. The
// staging folder of a run that was killed is removed by the next run.
#include <string>
#include <vector>

namespace parcelscope::io {

class OutputDirectory {
public:
  /// Throws Error(Usage) when `target` is an existing file, or when it holds or
  /// is one of `inputs` (outputs must never overwrite an input); Error(IO) when
  /// the staging folder cannot be created.
  OutputDirectory(std::string target, const std::vector<std::string>& inputs);
  ~OutputDirectory();
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  /// Where to write the output file `name` before commit(). `name` may name a
  /// file in a subfolder ("figures/map.png"); the folder is created.
  std::string stage(const std::string& name);
  /// Moves every staged file into the target. Throws Error(IO) on failure.
  void commit();
  const std::string& target() const { return target_; }

private:
  std::string target_;
  std::string staging_;
  std::vector<std::string> inputs_;
  std::vector<std::string> names_;
  bool committed_ = false;
};

/// One output file that appears complete or not at all: written under a hidden
/// temporary name in the same folder (same extension, so format detection by
/// name still works), renamed onto `target` by commit(), removed otherwise.
class StagedFile {
public:
  /// Throws Error(Usage) when `target` is one of `inputs` or an existing folder.
  StagedFile(std::string target, const std::vector<std::string>& inputs);
  ~StagedFile();
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;
  /// The temporary name to write to.
  const std::string& path() const { return staging_; }
  /// Renames the written file onto the target. Throws Error(IO) on failure.
  void commit();

private:
  std::string target_;
  std::string staging_;
  bool committed_ = false;
};

}  // namespace parcelscope::io
