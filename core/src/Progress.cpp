#include "parcelscope/core/Progress.h"

#include "parcelscope/core/Error.h"

namespace parcelscope {

void reportProgress(const ProgressFn& progress, double fraction, const std::string& stage) {
  if (progress && !progress(fraction, stage)) {
    throw Error(Error::Kind::Cancelled, "cancelled during " + stage);
  }
}

ProgressFn scaledProgress(const ProgressFn& parent, double begin, double end) {
  if (!parent) return {};
  return [parent, begin, end](double f, const std::string& stage) { return parent(begin + (end - begin) * f, stage); };
}

}  // namespace parcelscope
