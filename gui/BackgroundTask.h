#pragma once
// Library work the window starts and the user may cancel (a leaderboard, a
// calibration): run on a thread of its own, reporting progress and its end on
// the window's thread. Cancel makes the work's ProgressFn return false, so the
// library stops at its next report (Error(Cancelled)).
#include <QObject>
#include <QString>
#include <QThread>

#include <atomic>
#include <functional>

#include "parcelscope/core/Progress.h"

namespace parcelscope::gui {

class BackgroundTask : public QObject {
  Q_OBJECT
public:
  /// Starts `work` at once. It receives the progress callback to pass to the library.
  BackgroundTask(std::function<void(const ProgressFn&)> work, QObject* parent = nullptr);
  /// Cancels and waits for the work to end.
  ~BackgroundTask() override;

  void cancel() { cancelled_ = true; }
  bool running() const { return thread_->isRunning(); }

signals:
  void progress(double fraction, const QString& stage);
  /// The work ended: `error` is empty when it succeeded, "cancelled" when
  /// cancelled, else the error's message.
  void finished(const QString& error);

private:
  std::atomic<bool> cancelled_{false};
  QThread* thread_;
};

}  // namespace parcelscope::gui
