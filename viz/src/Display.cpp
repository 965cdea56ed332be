// The X server check lives alone in this file: Xlib's macros (None, Status,
// Bool) must not meet VTK's or ParcelScope's names.
#include <X11/Xlib.h>

#include <cstdlib>
#include <string>

#include "parcelscope/core/Error.h"
#include "parcelscope/viz/Figures.h"

namespace parcelscope::viz {

void requireDisplay() {
  const char* name = std::getenv("DISPLAY");
  const std::string hint = " (run under 'xvfb-run -a' on a machine without a screen, or pass --figures 0)";
  if (name == nullptr || *name == '\0') {
    throw ioError("rendering figures needs an X server, and DISPLAY is not set" + hint);
  }
  // The connection stays open for the life of the process: an X server such as
  // Xvfb resets (and may drop its authorisation) when its last client leaves,
  // which would happen between two figures otherwise.
  static ::Display* keepAlive = nullptr;
  if (keepAlive != nullptr) return;
  keepAlive = XOpenDisplay(name);
  if (keepAlive == nullptr) {
    throw ioError("rendering figures needs an X server, and none answers on DISPLAY=" + std::string(name) + hint);
  }
}

}  // namespace parcelscope::viz
