#pragma once
// Progress reporting for long operations, in the manner of GDALProgressFunc:
// the callback receives the fraction done in [0, 1] and the current stage name,
// and returns false to ask the operation to stop (it then throws
// Error(Kind::Cancelled)).
#include <functional>
#include <string>

namespace parcelscope {

using ProgressFn = std::function<bool(double fraction, const std::string& stage)>;

/// Calls `progress` (if set) and throws Error(Kind::Cancelled) when it returns false.
void reportProgress(const ProgressFn& progress, double fraction, const std::string& stage);

/// Maps the progress of a sub-step onto [begin, end] of the parent's range.
ProgressFn scaledProgress(const ProgressFn& parent, double begin, double end);

}  // namespace parcelscope
