#include "BackgroundTask.h"

#include "parcelscope/core/Error.h"

namespace parcelscope::gui {

BackgroundTask::BackgroundTask(std::function<void(const ProgressFn&)> work, QObject* parent) : QObject(parent) {
  thread_ = QThread::create([this, work = std::move(work)] {
    QString error;
    try {
      work([this](double fraction, const std::string& stage) {
        emit progress(fraction, QString::fromStdString(stage));  // queued to the window's thread
        return !cancelled_.load();
      });
    } catch (const Error& e) {
      error = e.kind() == Error::Kind::Cancelled ? QString("cancelled") : QString::fromStdString(e.what());
    } catch (const std::exception& e) {
      error = QString::fromStdString(e.what());
    }
    QMetaObject::invokeMethod(
        this, [this, error] { emit finished(error); }, Qt::QueuedConnection);
  });
  thread_->start();
}

BackgroundTask::~BackgroundTask() {
  cancelled_ = true;
  thread_->wait();
  delete thread_;
}

}  // namespace parcelscope::gui
