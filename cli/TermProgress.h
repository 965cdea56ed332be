#pragma once
// Progress on stderr, in the manner of GDALTermProgress: a bar that updates in
// place on a terminal, or one line per stage otherwise. Ctrl-C is turned into a
// request to stop: the next progress report returns false, the job throws
// Error(Cancelled) and its staged outputs are removed. A second Ctrl-C ends
// the process at once (outputs still never appear half-written).
#include "parcelscope/core/Progress.h"

namespace parcelscope::cli {

/// Installs the SIGINT handler that terminalProgress() watches.
void installInterruptHandler();

/// Progress shown on stderr (nothing when `quiet`); returns false once Ctrl-C was pressed.
ProgressFn terminalProgress(bool quiet);

}  // namespace parcelscope::cli
