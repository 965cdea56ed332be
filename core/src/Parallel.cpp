#include "parcelscope/core/Parallel.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

namespace parcelscope {

unsigned workerCount() {
  // The cores this process may run on (taskset, a cgroup, Slurm's
  // --cpus-per-task, an MPI launcher's binding), not all the machine's.
  static const unsigned count = [] {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) {
      return static_cast<unsigned>(CPU_COUNT(&set));
    }
    return std::max(1u, std::thread::hardware_concurrency());
  }();
  return count;
}

namespace {
constexpr auto kTickInterval = std::chrono::milliseconds(5);

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
  if (n == 0) return;  // nothing to report either (callers divide by n)
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
  auto work = [&](bool tickHere) {
    const InsideLoop inside;
    auto lastTick = std::chrono::steady_clock::now();
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
      if (tickHere && !stop && std::chrono::steady_clock::now() - lastTick >= kTickInterval) {
        lastTick = std::chrono::steady_clock::now();
        try {
          tick(done.load());
        } catch (...) {
          fail(std::current_exception());
        }
      }
    }
  };
  // Ticked once before any item and once after the last, so that a loop whose
  // items all finish before the first poll still reports its start and end.
  if (tick) tick(0);
  const unsigned threads = static_cast<unsigned>(std::min<std::size_t>(workerCount(), n));
  const bool ticking = tick && threads > 1;
  std::vector<std::thread> pool;
  for (unsigned t = ticking ? 0 : 1; t < threads; ++t) pool.emplace_back(work, false);
  if (ticking) {
    // The calling thread reports progress while the workers run.
    while (!stop && done.load() < n) {
      std::unique_lock<std::mutex> lock(finishedMutex);
      finished.wait_for(lock, kTickInterval, [&] { return stop || done.load() >= n; });
      lock.unlock();
      if (stop || done.load() >= n) break;
      try {
        tick(done.load());
      } catch (...) {
        fail(std::current_exception());
      }
    }
  } else {
    // One thread: it ticks between items itself.
    work(static_cast<bool>(tick));
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  if (tick) tick(n);
}

void runAtLowestPriority(const std::function<void()>& work) {
  std::exception_ptr error;
  std::thread worker([&] {
    // Linux gives each thread its own nice value, and threads it starts inherit it.
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 19);
    try {
      work();
    } catch (...) {
      error = std::current_exception();
    }
  });
  worker.join();
  if (error) std::rethrow_exception(error);
}

namespace {

// One background thread, started on first use and joined at exit (after
// dropping what is still queued).
class Releaser {
public:
  ~Releaser() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      quit_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

  void release(std::shared_ptr<const void> garbage) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (quit_ || queue_.size() >= kMaxWaitingReleases) {
      lock.unlock();
      garbage.reset();
      return;
    }
    if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
    queue_.push_back(std::move(garbage));
    ++queued_;
    lock.unlock();
    wake_.notify_all();
  }

  void wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    const std::size_t target = queued_;
    wake_.wait(lock, [&] { return released_ >= target; });
  }

private:
  void run() {
    // Lowest priority for this thread only (Linux gives each thread its own nice value).
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 19);
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return quit_ || !queue_.empty(); });
      if (queue_.empty()) return;  // quitting, nothing left
      std::shared_ptr<const void> garbage = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      garbage.reset();
      lock.lock();
      ++released_;
      wake_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<const void>> queue_;
  std::size_t queued_ = 0, released_ = 0;
  bool quit_ = false;
  std::thread thread_;
};

Releaser& releaser() {
  static Releaser r;
  return r;
}

}  // namespace

void releaseInBackground(std::shared_ptr<const void> garbage) {
  if (garbage) releaser().release(std::move(garbage));
}

void waitForBackgroundReleases() { releaser().wait(); }

}  // namespace parcelscope
