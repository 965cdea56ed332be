#include "TermProgress.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

namespace parcelscope::cli {

namespace {

std::atomic<bool> gInterrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void onInterrupt(int) {
  gInterrupted.store(true);
  ::signal(SIGINT, SIG_DFL);  // a second Ctrl-C ends the process at once
}

constexpr int kBarWidth = 30;

}  // namespace

void installInterruptHandler() {
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
}

ProgressFn terminalProgress(bool quiet) {
  struct State {
    std::string stage;
    int lastPercent = -1;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    bool tty = ::isatty(STDERR_FILENO) != 0;
  };
  auto st = std::make_shared<State>();
  return [st, quiet](double fraction, const std::string& stage) {
    if (gInterrupted.load()) {
      if (!quiet && st->tty && st->lastPercent >= 0) std::fputc('\n', stderr);
      return false;
    }
    if (quiet) return true;
    const int percent = std::clamp(static_cast<int>(fraction * 100.0 + 0.5), 0, 100);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - st->start).count();
    if (st->tty) {
      if (percent != st->lastPercent || stage != st->stage) {
        const int filled = percent * kBarWidth / 100;
        std::fprintf(stderr, "\r[%s%s] %3d%%  %-12s %6.1f s", std::string(filled, '#').c_str(),
                     std::string(kBarWidth - filled, '.').c_str(), percent, stage.c_str(), secs);
        if (percent >= 100) std::fputc('\n', stderr);
        std::fflush(stderr);
      }
    } else if (stage != st->stage) {
      std::fprintf(stderr, "%s ... (%d%%, %.1f s)\n", stage.c_str(), percent, secs);
    }
    st->stage = stage;
    st->lastPercent = percent;
    return true;
  };
}

}  // namespace parcelscope::cli
