#pragma once
// The application's state without its widgets: the compare request being
// edited, and which update of it was submitted, is shown, is pending, failed
// or was cancelled. The window forwards each user action here, asks what to
// submit, and asks what to do with each report of its update worker (which
// runs a CompareSession on its own thread). The controller runs nothing and
// holds no thread (one thread, the window's, uses it); it includes neither Qt
// nor VTK, so that tests, and the editing operations and undo to come, use the
// window's rules without a window.
//
// Sequencing. Each submission has a serial number, greater than the last; the
// newest one wins. An update reports up to three times: results in between
// (partial, only while it is the newest), its final result (possibly with the
// regenerated parcels' neighbours and street access still to measure:
// contextPending), and that result completed (completesContext). A failed or
// cancelled update leaves the result shown as it is. After a failed open or
// a failed update the request being edited is the last good one again (the
// request of the last update that succeeded, or before any, the request as it
// was before the first submission), so that the next edit builds on it rather
// than on the edit that failed.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "parcelscope/core/Parcel.h"
#include "parcelscope/io/ParcelReader.h"
#include "parcelscope/pipeline/CompareJob.h"

namespace parcelscope::pipeline {

/// One report of an update (see CompareSession::update and completeContext),
/// as the worker that runs the session hands it to the window.
struct UpdateReport {
  std::shared_ptr<const CompareResult> result;  ///< never null
  CompareRequest request;                       ///< the request submitted as `serial`
  std::int64_t serial = 0;
  bool reloaded = false;  ///< the input was read and analysed again
  int blocksRegenerated = 0;
  int blocksTotal = 0;
  double seconds = 0;  ///< CompareSession::Update::seconds
  /// A result in between: `blocksRegenerated` of `blocksTotal` block parts are
  /// new, the others as before; the final report follows.
  bool partial = false;
  /// The regenerated blocks' neighbours, frontage and street access are still
  /// being measured (CompareSession::update with deferContext): views and
  /// histograms of shape quantities are final, and a report with
  /// `completesContext` and the same serial follows unless a newer request
  /// supersedes this one.
  bool contextPending = false;
  /// The same result as the last report of this serial, with its context measured.
  bool completesContext = false;
};

class Controller {
public:
  /// Every compare parameter at its default, figures off (the window draws
  /// them itself), only the seed explicit; no input open.
  Controller();

  // ---- The request being edited --------------------------------------------

  const CompareRequest& request() const { return request_; }
  /// An input is open: every edit but setMetric() needs an update (submitted()).
  bool loaded() const { return loaded_; }

  /// Opens `input`: the overrides of the former input go (its blocks do not
  /// carry over), style, parameters and colouring stay.
  void openInput(const io::ReadOptions& input);
  /// Blocks from the street network `streets` (none: grouped from the
  /// parcels again); the overrides go, as the blocks change.
  void setStreets(std::optional<io::StreetReadOptions> streets);
  /// Makes session file `path` the request (readSession), with figures off.
  /// Throws as readSession (Error(Input) naming the file), leaving the request
  /// as it was.
  void openSession(const std::string& path);
  /// Writes the request being edited into session file `path`, atomically
  /// (exportSession). Throws Error(Io).
  void saveSession(const std::string& path) const;

  /// Sets compare parameter `name` (see compareParameters()) and marks it
  /// explicit. Setting one of the four generator bounds (a-min, a-max, w-min,
  /// w-max) while they are per block makes all four explicit: each then holds
  /// for every block.
  void setParameter(const std::string& name, double value);
  /// Per block: the four bounds come from each block's observed parcels
  /// (none explicit); otherwise all four are explicit.
  void setPerBlockBounds(bool perBlock);
  /// No bound is explicit.
  bool perBlockBounds() const;
  /// A style of generation's list; an unknown one fails in the update.
  void setStyle(const std::string& style);
  /// The colouring quantity (analysis::parcelQuantities()). Needs no update:
  /// the shown result is coloured again.
  void setMetric(const std::string& metric);
  /// Gives observed block `block` its own style (empty: the run's) and
  /// parameters, by its key; an override of the same block by id (from a
  /// version 1 session file) goes.
  void overrideBlock(const Block& block, const BlockOverride& blockOverride);
  /// Replaces every override by `overrides` (by key), as a calibration gives them.
  void setOverrides(const BlockOverrides& overrides);
  /// Removes the override of `block`, by key and by id.
  void clearOverride(const Block& block);
  bool overridden(const Block& block) const;

  // ---- Updates ---------------------------------------------------------------

  /// request() was handed to the worker as `serial` (greater than every
  /// earlier serial); it is the newest from now on.
  void submitted(std::int64_t serial);

  /// What the window does with a report.
  enum class Action {
    Ignore,   ///< superseded, or waiting for the completed result: nothing changes on screen
    Numbers,  ///< the views show this result's parcels already: numbers and block text only
    Draw,     ///< views, histogram and numbers from shownResult()
  };
  struct Decision {
    Action action = Action::Ignore;
    /// Draw: the input was read again since the views were last drawn (fit
    /// the views, forget the selection).
    bool newInput = false;
  };
  /// Takes a report of the worker: records what it shows and decides how.
  /// Dropped: results in between of an older serial; a result whose
  /// neighbours and street access are pending while they colour the views
  /// (the completed report follows); any report older than the views drawn.
  Decision receive(const UpdateReport& report);
  /// The update of `serial` failed. Returns whether it was the newest; then
  /// nothing is pending, and the request being edited is the last good one
  /// again (with the colouring chosen since).
  bool failed(std::int64_t serial);
  /// The update of `serial` was cancelled. Returns whether it was the newest;
  /// then nothing is pending, and the request keeps its edits.
  bool cancelled(std::int64_t serial);

  /// The newest serial submitted (0: none).
  std::int64_t pendingSerial() const { return pendingSerial_; }
  /// The request submitted as pendingSerial().
  const CompareRequest& submittedRequest() const { return submitted_; }
  /// The newest submitted request when its update failed, else null (e.g. to
  /// read the same file again with another CRS).
  const CompareRequest* failedRequest() const { return failed_ ? &submitted_ : nullptr; }
  /// The serial whose final views were drawn last.
  std::int64_t drawnSerial() const { return drawnSerial_; }
  /// The serial whose final, complete result (numbers included) is shown.
  std::int64_t completeSerial() const { return completeSerial_; }
  /// The newest update is queued or under way: neither complete, nor failed, nor cancelled.
  bool busy() const { return pendingSerial_ != completeSerial_ && !failedOrCancelled_; }
  bool failedOrCancelled() const { return failedOrCancelled_; }
  /// Update `serial` is the newest and nothing of it is on screen yet (no
  /// result in between, no final views).
  bool awaitingViews(std::int64_t serial) const;

  // ---- Results ---------------------------------------------------------------

  /// The result on screen, possibly one in between (null before the first).
  const std::shared_ptr<const CompareResult>& shownResult() const { return shown_; }
  /// The request of shownResult(), with the colouring chosen now.
  CompareRequest shownRequest() const;
  /// The last complete result (what exports write) and its request; they
  /// stay through failed and cancelled updates.
  const std::shared_ptr<const CompareResult>& finalResult() const { return final_; }
  const CompareRequest& finalRequest() const { return finalRequest_; }
  /// The request a failure returns to (see failed()).
  const CompareRequest& lastGoodRequest() const { return good_.request; }

private:
  struct State {
    CompareRequest request;
    bool loaded = false;
  };
  /// After each edit: with no input open nothing is submitted, so nothing can fail.
  void edited();

  CompareRequest request_;
  bool loaded_ = false;
  State good_;
  std::int64_t goodSerial_ = 0;

  CompareRequest submitted_;
  std::int64_t pendingSerial_ = 0, drawnSerial_ = 0, completeSerial_ = 0, partialSerial_ = 0;
  bool failedOrCancelled_ = false, failed_ = false;

  std::shared_ptr<const CompareResult> shown_, final_;
  CompareRequest shownRequest_, finalRequest_;
};

}  // namespace parcelscope::pipeline
