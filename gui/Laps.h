#pragma once
// Milliseconds between successive calls: where an update's time went.
#include <QElapsedTimer>

namespace parcelscope::gui {

class Laps {
public:
  Laps() { timer_.start(); }
  double operator()() {
    const double now = total(), ms = now - last_;
    last_ = now;
    return ms;
  }
  double total() const { return static_cast<double>(timer_.nsecsElapsed()) / 1e6; }

private:
  QElapsedTimer timer_;
  double last_ = 0;
};

}  // namespace parcelscope::gui
