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

namespace parcelscope::gui {

/// What one finished update brings to the window.
struct UpdateReport {
  std::shared_ptr<const pipeline::CompareResult> result;
  pipeline::CompareRequest request;
  qint64 serial = 0;
  bool reloaded = false;
  int blocksRegenerated = 0;
  int blocksTotal = 0;
  double seconds = 0;
  /// A result in between: `blocksRegenerated` of `blocksTotal` block parts are
  /// new, the others as before; the final report follows.
  bool partial = false;
  /// The regenerated blocks' neighbours, frontage and street access are still
  /// being measured (pipeline::CompareSession::update with deferContext): views
  /// and histograms of shape quantities are final, and a report with
  /// `completesContext` and the same serial follows unless a newer request
  /// supersedes this one.
  bool contextPending = false;
  /// The same result as the last report of this serial, with its context measured.
  bool completesContext = false;
};

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
  void updated(const parcelscope::gui::UpdateReport& report);
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

Q_DECLARE_METATYPE(parcelscope::gui::UpdateReport)
