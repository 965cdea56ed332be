#include "StreetEditWorker.h"

#include <QMetaObject>

#include <chrono>
#include <utility>

#include "parcelscope/core/Error.h"

namespace parcelscope::gui {

StreetEditWorker::StreetEditWorker() { qRegisterMetaType<parcelscope::gui::StreetEditState>(); }
StreetEditWorker::~StreetEditWorker() = default;

void StreetEditWorker::start(const pipeline::CompareRequest& request,
                             std::shared_ptr<const pipeline::ObservedData> observed) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    start_ = Start{request, std::move(observed)};
    queue_.clear();
    stopping_ = false;
  }
  QMetaObject::invokeMethod(this, "process", Qt::QueuedConnection);
}

qint64 StreetEditWorker::submit(const Command& command) {
  qint64 serial;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    serial = ++serial_;
    // A move of the drag under way replaces its move still waiting.
    if (command.gesture != 0 && !queue_.empty() && queue_.back().second.gesture == command.gesture) {
      queue_.back() = {serial, command};
      return serial;
    }
    queue_.emplace_back(serial, command);
  }
  QMetaObject::invokeMethod(this, "process", Qt::QueuedConnection);
  return serial;
}

void StreetEditWorker::stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  start_.reset();
  queue_.clear();
  stopping_ = true;
  // The editor itself goes on the worker thread, at the next process().
  QMetaObject::invokeMethod(this, "process", Qt::QueuedConnection);
}

void StreetEditWorker::process() {
  for (;;) {
    std::optional<Start> start;
    std::optional<std::pair<qint64, Command>> next;
    bool drop = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (start_) {
        start = std::move(start_);
        start_.reset();
      } else if (!queue_.empty()) {
        next = queue_.front();
        queue_.pop_front();
      } else {
        drop = std::exchange(stopping_, false);
      }
    }
    if (drop) {
      editor_.reset();
      history_.clear();
      undone_.clear();
      continue;
    }
    if (!start && !next) break;
    const auto began = std::chrono::steady_clock::now();
    StreetEditState state;
    try {
      if (start) {
        editor_.reset();
        history_.clear();
        undone_.clear();
        gestureApplied_ = 0;
        editor_ = std::make_unique<pipeline::StreetEditor>(start->request, start->observed);
      } else {
        if (!editor_) continue;
        const Command& c = next->second;
        state.serial = next->first;
        switch (c.kind) {
          case Command::Kind::Apply: {
            // The next move of a drag: undo its move before, apply from the state before the drag.
            const bool replaces = c.gesture != 0 && c.gesture == gestureApplied_ && editor_->undo();
            std::optional<pipeline::StreetEdit> replaced;
            if (replaces) {
              replaced = history_.back();
              history_.pop_back();
            }
            try {
              state.report = editor_->apply(c.edit);
            } catch (...) {
              // The drag's move before stays.
              if (replaced && editor_->redo()) history_.push_back(*replaced);
              throw;
            }
            history_.push_back(c.edit);
            undone_.clear();
            gestureApplied_ = c.gesture;
            break;
          }
          case Command::Kind::Undo:
            if (editor_->undo()) {
              undone_.push_back(history_.back());
              history_.pop_back();
            }
            gestureApplied_ = 0;
            break;
          case Command::Kind::Redo:
            if (editor_->redo()) {
              history_.push_back(undone_.back());
              undone_.pop_back();
            }
            gestureApplied_ = 0;
            break;
        }
      }
    } catch (const std::exception& e) {
      emit failed(QString::fromStdString(e.what()), next ? next->first : 0);
      continue;
    }
    state.snapshot = editor_->snapshot();
    state.history = history_;
    state.undo = editor_->undoSize();
    state.redo = editor_->redoSize();
    state.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    emit updated(state);
  }
}

}  // namespace parcelscope::gui
