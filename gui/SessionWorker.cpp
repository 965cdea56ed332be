#include "SessionWorker.h"

#include <QMetaObject>

#include <chrono>

#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"

namespace parcelscope::gui {

SessionWorker::SessionWorker() { qRegisterMetaType<parcelscope::gui::UpdateReport>(); }
SessionWorker::~SessionWorker() = default;

qint64 SessionWorker::submit(const viz::CompareRequest& request) {
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
    viz::CompareRequest request;
    qint64 serial;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!pending_) return;
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
      const auto partial = [&](std::shared_ptr<const viz::CompareResult> result, std::size_t done,
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
      const viz::CompareSession::Update u =
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
      if (report.contextPending && completeContext(serial)) {
        report.result = session_.current();
        report.contextPending = false;
        report.completesContext = true;
        emit updated(report);
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
}

bool SessionWorker::completeContext(qint64 serial) {
  // Only asks whether a newer request is waiting: no progress bar for this step.
  const ProgressFn stillWanted = [&](double, const std::string&) { return latest_.load() == serial; };
  try {
    runAtLowestPriority([&] { session_.completeContext(stillWanted); });
    return true;
  } catch (const Error& e) {
    if (e.kind() != Error::Kind::Cancelled) throw;
    // A newer request measures it; without one (cancel()), the window hears of it.
    bool newer;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      newer = pending_.has_value();
    }
    if (!newer) emit cancelled(serial);
    return false;
  }
}

}  // namespace parcelscope::gui
