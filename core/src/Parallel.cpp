#include "parcelscope/core/Parallel.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace parcelscope {

unsigned workerCount() { return std::max(1u, std::thread::hardware_concurrency()); }

namespace {
// True on a thread running a parallelFor's body: a loop nested in it runs on
// that thread alone (the outer loop already keeps every core busy; starting
// threads per block would only cost).
thread_local bool tInsideLoop = false;

struct InsideLoop {
  bool was = tInsideLoop;
  InsideLoop() { tInsideLoop = true; }
  ~InsideLoop() { tInsideLoop = was; }
};
}  // namespace

void parallelFor(std::size_t n, const std::function<void(std::size_t)>& body,
                 const std::function<void(std::size_t)>& tick) {
  if (tInsideLoop) {
    for (std::size_t i = 0; i < n; ++i) body(i);
    return;
  }
  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> stop{false};
  std::exception_ptr error;
  std::mutex errorMutex;
  auto fail = [&](std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(errorMutex);
    if (!error) error = e;
    stop = true;
  };
  // The ticking thread sleeps between ticks until the last item is done.
  std::mutex finishedMutex;
  std::condition_variable finished;
  auto work = [&] {
    const InsideLoop inside;
    for (std::size_t i; !stop && (i = next.fetch_add(1)) < n;) {
      try {
        body(i);
      } catch (...) {
        fail(std::current_exception());
      }
      if (done.fetch_add(1) + 1 == n) {
        std::lock_guard<std::mutex> lock(finishedMutex);
        finished.notify_all();
      }
    }
  };
  const unsigned threads = static_cast<unsigned>(std::min<std::size_t>(workerCount(), n));
  const bool ticking = tick && threads > 1;
  std::vector<std::thread> pool;
  for (unsigned t = ticking ? 0 : 1; t < threads; ++t) pool.emplace_back(work);
  if (ticking) {
    // The calling thread reports progress while the workers run.
    while (!stop && done.load() < n) {
      try {
        tick(done.load());
      } catch (...) {
        fail(std::current_exception());
      }
      std::unique_lock<std::mutex> lock(finishedMutex);
      finished.wait_for(lock, std::chrono::milliseconds(5), [&] { return stop || done.load() >= n; });
    }
  } else {
    work();
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace parcelscope
