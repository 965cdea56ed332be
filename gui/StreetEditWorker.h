#pragma once
// Runs a pipeline::StreetEditor off the UI thread: the window's street
// editing mode hands it edits, undo and redo, and draws each state it reports.
// A drag is one gesture: each move of it replaces the edit of the move before
// (the editor undoes that one first), so that the gesture is one step of undo
// and its parcels are matched to those before the drag began. Moves that
// arrive while one is being applied are merged: only the newest is applied.
#include <QObject>
#include <QString>

#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "parcelscope/pipeline/StreetEditor.h"

namespace parcelscope::gui {

/// One state of the editor as the window draws it (Qt-free).
struct StreetEditState {
  std::optional<pipeline::StreetEditor::Snapshot> snapshot;  ///< set once the editor is built
  /// The edit that led here (none for the first state, an undo or a redo).
  std::optional<pipeline::EditReport> report;
  /// The edits that make this state from the first, in order (what undo would take back).
  std::vector<pipeline::StreetEdit> history;
  std::size_t undo = 0, redo = 0;
  qint64 serial = 0;   ///< of the last command this state answers
  double seconds = 0;  ///< the editor's time for that command
};

class StreetEditWorker : public QObject {
  Q_OBJECT
public:
  StreetEditWorker();
  ~StreetEditWorker() override;

  struct Command {
    enum class Kind { Apply, Undo, Redo };
    Kind kind = Kind::Apply;
    pipeline::StreetEdit edit;
    /// Non-zero: a move of drag `gesture`, replacing the edit of its move before.
    qint64 gesture = 0;
  };
  /// Builds the editor of the comparison of `request` on `observed` (thread-safe).
  void start(const pipeline::CompareRequest& request, std::shared_ptr<const pipeline::ObservedData> observed);
  /// Queues `command` (thread-safe) and returns its serial number.
  qint64 submit(const Command& command);
  /// Drops the editor and every queued command.
  void stop();

signals:
  void updated(const parcelscope::gui::StreetEditState& state);
  /// A command failed (the state is as before it); `serial` is its number.
  void failed(const QString& message, qint64 serial);

private slots:
  void process();

private:
  std::mutex mutex_;
  struct Start {
    pipeline::CompareRequest request;
    std::shared_ptr<const pipeline::ObservedData> observed;
  };
  std::optional<Start> start_;
  std::deque<std::pair<qint64, Command>> queue_;
  qint64 serial_ = 0;
  bool stopping_ = false;  ///< stop() was called: the editor goes
  // Worker thread only.
  std::unique_ptr<pipeline::StreetEditor> editor_;
  std::vector<pipeline::StreetEdit> history_, undone_;
  qint64 gestureApplied_ = 0;  ///< the gesture whose edit is the last applied (0: none)
};

}  // namespace parcelscope::gui

Q_DECLARE_METATYPE(parcelscope::gui::StreetEditState)
