#include "TermProgress.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>

namespace parcelscope::cli {

ProgressFn terminalProgress(bool quiet) {
  if (quiet) return {};
  struct State {
    std::string stage;
    int lastPercent = -1;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    bool tty = ::isatty(STDERR_FILENO) != 0;
  };
  auto st = std::make_shared<State>();
  return [st](double fraction, const std::string& stage) {
    const int percent = static_cast<int>(fraction * 100.0 + 0.5);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - st->start).count();
    if (st->tty) {
      if (percent != st->lastPercent || stage != st->stage) {
        std::fprintf(stderr, "\r%-12s %3d%%  %6.1f s", stage.c_str(), percent, secs);
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
