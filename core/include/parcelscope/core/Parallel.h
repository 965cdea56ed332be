#pragma once
// A small parallel loop over independent items. Results must be written to
// per-index slots so that the outcome does not depend on scheduling.
#include <cstddef>
#include <functional>
#include <memory>

namespace parcelscope {

/// Number of worker threads parallelFor uses: the cores this process may run on
/// (its CPU affinity: taskset, cgroups, Slurm, an MPI binding), at least 1.
unsigned workerCount();

/// Calls body(i) for every i in [0, n) on up to workerCount() threads. The
/// calling thread runs `tick(done)` (for progress; it may throw to stop the
/// loop early) before the first item, every few milliseconds while items run
/// (between items when there is one thread) and, unless the loop failed, once
/// with done == n after the last. A loop of no items, and a loop nested in
/// another's body, do not tick. The first exception thrown by `body` or `tick` is
/// rethrown on the calling thread after all workers stop. Called from within a
/// parallelFor's body, it runs the loop on the calling thread, in order.
void parallelFor(std::size_t n, const std::function<void(std::size_t)>& body,
                 const std::function<void(std::size_t done)>& tick = {});

/// Runs `work` on a new thread of the lowest scheduling priority (nice 19) and
/// waits for it; a parallelFor inside runs on threads of that priority too.
/// For work that should use only the CPU time nothing else wants (what an
/// interactive update can measure after its result is on screen). Exceptions
/// from `work` are rethrown here.
void runAtLowestPriority(const std::function<void()>& work);

/// Drops `garbage` on a background thread of the lowest scheduling priority
/// (nice 19), so that freeing a large structure (the replaced state of an
/// interactive update, say) does not delay the caller. When many releases are
/// already waiting, it is dropped on the calling thread instead, so that
/// memory cannot pile up while every core is busy.
void releaseInBackground(std::shared_ptr<const void> garbage);
/// How many releases may wait at once.
constexpr std::size_t kMaxWaitingReleases = 8;

/// Returns once everything handed to releaseInBackground before the call has
/// been dropped.
void waitForBackgroundReleases();

}  // namespace parcelscope
