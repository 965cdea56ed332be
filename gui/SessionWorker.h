#pragma once
// Runs pipeline::CompareSession::update off the UI thread. The newest request wins:
// submitting one cancels the update under way (through the progress callback),
// and the session keeps the blocks it had finished. Each update reports twice
// when it can: first with the parcels measured by shape (what the views and
// histograms need), then, measured on threads of the lowest priority so as not
// to slow the drawing of the first, with their neighbours and street access.
#include <QObject>
#include <QString>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>

#include "parcelscope/pipeline/CompareSession.h"
#include "parcelscope/pipeline/Controller.h"

namespace parcelscope::gui {

/// What one finished update brings to the window (Qt-free, so that
/// pipeline::Controller decides what the window does with it).
using UpdateReport = pipeline::UpdateReport;

class SessionWorker : public QObject {
  Q_OBJECT
public:
  SessionWorker();
  ~SessionWorker() override;
  /// Queues `request` (thread-safe) and returns its serial number.
  qint64 submit(const pipeline::CompareRequest& request);
  /// Cancels the update under way and drops any queued request.
  void cancel();

signals:
  void updated(const parcelscope::pipeline::UpdateReport& report);
  void failed(const QString& message, qint64 serial);
  void cancelled(qint64 serial);
  void progress(double fraction, const QString& stage);

private slots:
  void process();

private:
  /// Measures what the update of `awaiting_` deferred, at the lowest priority,
  /// and reports the completed result. A newer request stops it (awaiting_ is
  /// then kept, in case that request fails).
  void finishAwaited();

  std::mutex mutex_;
  std::optional<pipeline::CompareRequest> pending_;
  std::atomic<qint64> latest_{0};
  pipeline::CompareSession session_;
  /// The last report drawn with its context pending (worker thread only).
  std::optional<UpdateReport> awaiting_;
};

}  // namespace parcelscope::gui

Q_DECLARE_METATYPE(parcelscope::pipeline::UpdateReport)
