#pragma once
// An output directory that holds exactly one run, whole: the run being written
// or, until it is complete, the previous one untouched.
//
// The whole run is written into a hidden staging folder beside the target, on the
// same filesystem (".NAME.partial-PID-N"); commit() then swaps folders: the
// staging folder is renamed to the target when there is none, or exchanged with
// it in one step (Linux renameat2 RENAME_EXCHANGE), or, where that is not
// supported, the previous run is renamed aside (".NAME.old-PID-N") and the
// staging folder renamed into its place; the previous run is deleted last. When
// the target is an existing mount point (or its parent cannot be written), the
// run is staged inside it (".parcelscope-partial-PID-N") and commit() swaps the
// folder's contents entry by entry instead. Without commit(), the destructor
// removes the staging folder and the target is untouched. The next run for the
// same target cleans up what a killed run left: its staging folder is removed,
// a swap interrupted before the new run was complete is undone (the previous run
// is put back) and one interrupted after it is completed.
#include <string>
#include <vector>

#include "parcelscope/core/Error.h"

namespace parcelscope::io {

class OutputDirectory {
public:
  /// Prepares the staging folder for `target` (created with its parents when it
  /// does not exist). Throws Error(Usage) when `target` is an existing file, when
  /// it is, holds or lies inside one of `inputs` (outputs never overwrite or
  /// delete an input), or when it is an existing folder that holds files but no
  /// ParcelScope run (a run.json whose "tool" is "parcelscope"): such files are
  /// never deleted. Throws Error(IO) naming `target` and the cause (read-only file
  /// system, permission denied, no space left) when the staging folder cannot be
  /// created.
  OutputDirectory(std::string target, const std::vector<std::string>& inputs);
  ~OutputDirectory();
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  /// Where to write the output file `name` before commit(). `name` is relative
  /// and may name a file in a subfolder ("figures/map.png"); the folder is
  /// created. Throws Error(IO) naming the target when it cannot be.
  std::string stage(const std::string& name);
  /// Replaces the target's previous run, if any, with the staged files, whole.
  /// Throws Error(Usage) when the target now holds an input or files that are not
  /// a ParcelScope run, Error(IO) naming the target and the cause when the swap
  /// fails; the previous run is then left as it was.
  void commit();
  /// An error of a writer that wrote a staged file, told as the target's: the
  /// staging folder in its message replaced by the target, and the cause added
  /// when the target's filesystem is read-only or full (less than 1 MiB free).
  /// For the jobs: `catch (const Error& e) { throw out.explain(e); }`.
  Error explain(const Error& e) const;
  const std::string& target() const { return target_; }

private:
  void recoverLeftovers() const;
  void checkTarget() const;
  void commitBeside();
  void commitInside();

  std::string target_;       // as given, for messages
  std::string destination_;  // absolute, symbolic links resolved
  std::string staging_;
  std::string unique_;  // "PID-N", unique to this object
  std::vector<std::string> inputs_;
  bool inside_ = false;  // staged inside the target (mount point), contents swapped
  bool committed_ = false;
};

/// Fault injection for tests/io/OutputTest.cpp. Production code leaves these as
/// they are.
struct OutputDirectoryTesting {
  /// Called by commit() with the name of each step: "swap" before anything
  /// moves; "aside" once the previous run is out of the target (two-rename swap
  /// and contents swap); "entry" before each entry a contents swap moves;
  /// "placed" once the new run is in place, before the previous one is deleted.
  static inline void (*step)(const char* name) = nullptr;
  /// Swap with two renames even where RENAME_EXCHANGE works.
  static inline bool noExchange = false;
  /// Stage inside an existing target and swap contents, as for a mount point.
  static inline bool stageInside = false;
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
