#pragma once
// Progress on stderr, in the manner of GDALTermProgress: a percentage that
// updates in place on a terminal, or one line per stage otherwise.
#include "parcelscope/core/Progress.h"

namespace parcelscope::cli {

ProgressFn terminalProgress(bool quiet);

}  // namespace parcelscope::cli
