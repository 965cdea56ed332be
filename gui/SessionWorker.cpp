#include "SessionWorker.h"

#include <QMetaObject>

#include <chrono>

#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"

namespace parcelscope::gui {

SessionWorker::SessionWorker() { qRegisterMetaType<parcelscope::pipeline::UpdateReport>(); }
SessionWorker::~SessionWorker() = default;

qint64 SessionWorker::submit(const pipeline::CompareRequest& request) {
  qint64 serial;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = request;
    serial = ++latest_;
  }
  QMetaObject::invokeMethod(this, "process", Qt::QueuedConnection);
  return serial;
}

void SessionWorker::cancel() {
  std::lock_guard<std::mutex> lock(mutex_);
  pending_.reset();
  ++latest_;
}

void SessionWorker::process() {
  for (;;) {
    pipeline::CompareRequest request;
    qint64 serial;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!pending_) break;
      request = std::move(*pending_);
      pending_.reset();
      serial = latest_.load();
    }
    auto last = std::chrono::steady_clock::now() - std::chrono::seconds(1);
    const ProgressFn progress = [&](double fraction, const std::string& stage) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last > std::chrono::milliseconds(50)) {
        last = now;
        emit this->progress(fraction, QString::fromStdString(stage));
      }
      return latest_.load() == serial;
    };
    try {
      const auto partial = [&](std::shared_ptr<const pipeline::CompareResult> result, std::size_t done,
                               std::size_t total) {
        if (latest_.load() != serial) return;  // a newer request is waiting: no point drawing this one
        UpdateReport report;
        report.result = std::move(result);
        report.request = request;
        report.serial = serial;
        report.blocksRegenerated = static_cast<int>(done);
        report.blocksTotal = static_cast<int>(total);
        report.partial = true;
        emit updated(report);
      };
      const pipeline::CompareSession::Update u =
          session_.update(request, progress, partial, 0.5, /*deferContext=*/true);
      UpdateReport report;
      report.result = u.result;
      report.request = request;
      report.serial = serial;
      report.reloaded = u.reloaded;
      report.blocksRegenerated = static_cast<int>(u.blocksRegenerated);
      report.blocksTotal = static_cast<int>(u.blocksTotal);
      report.seconds = u.seconds;
      report.contextPending = !u.result->generated.contextPending.empty();
      emit updated(report);
      if (report.contextPending) {
        awaiting_ = std::move(report);
        finishAwaited();
      }
    } catch (const Error& e) {
      if (e.kind() == Error::Kind::Cancelled) {
        emit cancelled(serial);
      } else {
        emit failed(QString::fromStdString(e.what()), serial);
      }
    } catch (const std::exception& e) {
      emit failed(QString("internal error: ") + e.what(), serial);
    }
  }
  // Nothing queued. A result whose completion a newer request stopped, and
  // that request then failed or was cancelled, is still on screen: complete it.
  finishAwaited();
}

void SessionWorker::finishAwaited() {
  if (!awaiting_) return;
  UpdateReport report = std::move(*awaiting_);
  awaiting_.reset();
  if (session_.current() != report.result) return;  // replaced by a newer result, which reports itself
  // Stopped by any newer request (or cancel()); no progress bar for this step.
  const qint64 at = latest_.load();
  const ProgressFn stillWanted = [&](double, const std::string&) { return latest_.load() == at; };
  try {
    runAtLowestPriority([&] { session_.completeContext(stillWanted); });
  } catch (const Error& e) {
    if (e.kind() != Error::Kind::Cancelled) {
      emit failed(QString::fromStdString(e.what()), report.serial);
      return;
    }
    bool newer;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      newer = pending_.has_value();
    }
    const qint64 serial = report.serial;
    awaiting_ = std::move(report);  // should the newer request fail, this one is completed after it
    if (!newer) emit cancelled(serial);
    return;
  } catch (const std::exception& e) {
    emit failed(QString("internal error: ") + e.what(), report.serial);
    return;
  }
  // Still pending when the session's last update was cancelled: the next update measures it.
  if (!session_.current()->generated.contextPending.empty()) return;
  report.result = session_.current();
  report.contextPending = false;
  report.completesContext = true;
  emit updated(report);
}

}  // namespace parcelscope::gui
