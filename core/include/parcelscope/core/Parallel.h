#pragma once
// A small parallel loop over independent items. Results must be written to
// per-index slots so that the outcome does not depend on scheduling.
#include <cstddef>
#include <functional>

namespace parcelscope {

/// Number of worker threads parallelFor uses (hardware threads, at least 1).
unsigned workerCount();

/// Calls body(i) for every i in [0, n) on up to workerCount() threads. Between
/// chunks the calling thread runs `tick(done)` (for progress; it may throw to
/// stop the loop early). The first exception thrown by `body` or `tick` is
/// rethrown on the calling thread after all workers stop. Called from within a
/// parallelFor's body, it runs the loop on the calling thread, in order.
void parallelFor(std::size_t n, const std::function<void(std::size_t)>& body,
                 const std::function<void(std::size_t done)>& tick = {});

}  // namespace parcelscope
