#pragma once
// `compare` kept up to date across edits: the state behind the GUI, usable from
// any program. The session holds the observed data and every block's plan and
// outcome; update() reads and analyses again only when the input or a
// block-building parameter changed, and regenerates only the blocks whose plan
// (style, bounds, parameters, seed) changed, as Vanegas et al. 2012 (section 5)
// regenerate only the blocks an edit touches. A request gives the same result
// through a session as through compare().
//
// Session files (JSON) hold a request: input, style, parameters the user set,
// per-block overrides, seed and figure quantity. `parcelscope compare --session
// FILE` runs one; the GUI saves and restores them.
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include "parcelscope/core/Json.h"
#include "parcelscope/pipeline/CompareJob.h"

namespace parcelscope::pipeline {

class CompareSession {
public:
  CompareSession();
  ~CompareSession();
  CompareSession(const CompareSession&) = delete;
  CompareSession& operator=(const CompareSession&) = delete;

  struct Update {
    std::shared_ptr<const CompareResult> result;
    bool reloaded = false;              ///< the input was read and analysed again
    std::size_t blocksRegenerated = 0;  ///< block entries subdivided by this update
    std::size_t blocksTotal = 0;
    double seconds = 0;
  };

  /// A result in between, while many blocks are regenerated: the blocks done
  /// so far with their new parcels, every other block as it was (each block a
  /// complete subdivision, so the whole still tiles every block), measured and
  /// compared. `done` of `total` block parts are new.
  using PartialFn =
      std::function<void(std::shared_ptr<const CompareResult> result, std::size_t done, std::size_t total)>;

  /// Brings the result up to date with `request`. Throws as compare(); on
  /// Error(Cancelled) (progress returned false) the blocks finished so far are
  /// kept for the next update and current() is unchanged. When `partial` is
  /// set and the update regenerates blocks that all had a result before, it is
  /// called (on this thread) with a result in between, the first after
  /// partialSeconds / 2, then at most every `partialSeconds`.
  ///
  /// With `deferContext`, and when the request's metric is a shape quantity
  /// (not neighbours or street access), the regenerated blocks' parcels are
  /// measured by shape only: maps, histograms and distances of area, width and
  /// aspect ratio are final, while neighbours, frontage and street access wait
  /// for completeContext() (result.generated.contextPending lists the entries).
  /// An interactive caller shows the result at once and then completes it.
  /// Without it, anything left pending by earlier updates is measured too.
  Update update(const CompareRequest& request, const ProgressFn& progress = {}, const PartialFn& partial = {},
                double partialSeconds = 0.5, bool deferContext = false);

  /// Measures the neighbours, frontage and street access an update deferred
  /// and returns the completed result (the current one, unchanged, when
  /// nothing is pending, or when the last update was cancelled: the next
  /// update measures what its result needs). On Error(Cancelled) the blocks
  /// measured so far are kept and current() stays as it was.
  Update completeContext(const ProgressFn& progress = {});

  /// The last result (null before the first update).
  std::shared_ptr<const CompareResult> current() const;

private:
  struct State;
  std::unique_ptr<State> state_;
};

/// The request as a session file holds it: {"parcelscope_session": 2, "input":
/// {path, layer, where, crs}, "style", "metric", "parameters": {the explicit
/// ones}, "overrides": [{"block_key", "style", "parameters"}]} (an override
/// read by block id from a version 1 file is written back by block_id).
Json sessionJson(const CompareRequest& request);
/// The street options as a session file holds them (member `streets`).
Json streetOptionsJson(const io::StreetReadOptions& streets);

/// `request` with its input's and streets' paths made absolute (a record
/// written in another folder than the one they were given from: a run's
/// run.json, a shard's session.json).
CompareRequest withAbsolutePaths(CompareRequest request);

/// Reads a session file (or the "session" member of a compare run.json), of
/// version 2 (overrides by block_key) or 1 (overrides by block_id, which
/// follow the order of the input's features: see BlockOverridesById).
/// Relative input paths are taken relative to the file's folder. Throws
/// Error(Input) naming the file and the member that is wrong.
CompareRequest readSession(const std::string& path);

}  // namespace parcelscope::pipeline
