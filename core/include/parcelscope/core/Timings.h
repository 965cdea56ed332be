#pragma once
// Wall-clock seconds per stage of a job, kept for run records (run.json) so
// users and benchmarks see where the time goes.
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace parcelscope {

class Timings {
public:
  /// Ends the current stage (if any) and starts `stage`.
  void start(const std::string& stage) {
    stop();
    current_ = stage;
    began_ = std::chrono::steady_clock::now();
  }
  /// Ends the current stage.
  void stop() {
    if (current_.empty()) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - began_).count();
    stages_.emplace_back(current_, s);
    current_.clear();
  }
  const std::vector<std::pair<std::string, double>>& stages() const { return stages_; }
  /// Records a stage timed elsewhere (another process's).
  void add(const std::string& stage, double seconds) { stages_.emplace_back(stage, seconds); }

private:
  std::string current_;
  std::chrono::steady_clock::time_point began_;
  std::vector<std::pair<std::string, double>> stages_;
};

}  // namespace parcelscope
