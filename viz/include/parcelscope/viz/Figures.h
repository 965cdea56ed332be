#pragma once
// Figures rendered off screen with VTK (PNG, plus a vector copy): parcel maps
// coloured by a value, and overlaid frequency histograms. Plain ParcelScope
// types in, files out; no VTK type appears here, so callers do not depend on
// VTK's headers.
//
// Rendering needs an X server (VTK on Debian renders through GLX, off screen
// in a hidden window). When $DISPLAY names none (unset, or nothing answers),
// the first figure starts a private Xvfb for the process (requireDisplay), so
// figures render headless with nothing to set up; only when Xvfb is missing
// too does every function throw Error(IO) naming what to install.
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::viz {

struct Rgb {
  double r = 0, g = 0, b = 0;  ///< each in [0, 1]
};

/// Where and how large a figure is written.
struct FigureOutput {
  std::string png;     ///< PNG path (written exactly `width` x `height` pixels)
  std::string vector;  ///< optional vector copy: a path ending in .svg or .pdf; empty = none (not maps)
  /// Maps only: vector copies (.svg, .pdf) whose shapes are paths (writeVectorMaps).
  std::vector<std::string> mapVectors;
  int width = 1800;  ///< pixels
  int height = 900;  ///< pixels
};

/// Makes sure an X server is there to render on, once per process: the one on
/// $DISPLAY if it answers; otherwise (DISPLAY unset, or nothing answers) a
/// private `Xvfb -displayfd FD -screen 0 1920x1080x24 -nolisten tcp
/// -terminate` on a display number it picks itself, with $DISPLAY set to it for
/// the rest of the process. That server is stopped and reaped when the process
/// exits (normally or through an error); if the process is killed, it ends by
/// itself once the process's connections close. Keeps a connection open for
/// the process's life. Throws Error(IO) when Xvfb is needed but not installed
/// (naming the package) or does not start. Not for concurrent use with VTK
/// rendering (it may set DISPLAY).
void requireDisplay();

/// A colour scale for map values. Values below `minimum` or above `maximum` take
/// the end colours; NaN values are drawn light grey.
struct ColourScale {
  enum class Kind {
    RedToGreen,  ///< red at minimum to green at maximum (Vanegas et al. 2012, Figure 1)
    Sequential   ///< pale yellow at minimum to dark purple at maximum
  };
  Kind kind = Kind::RedToGreen;
  double minimum = 0, maximum = 1;
  std::string title;  ///< colour bar title, with unit
};

/// One map of a side-by-side figure.
struct MapPanel {
  std::string title;
  std::vector<const Polygon*> shapes;  ///< local metres; holes are left unfilled
  std::vector<double> values;          ///< one per shape
};

/// Outlines are drawn only around shapes at least this many pixels across
/// (outlineSize): smaller ones would be covered by their own outline, and a
/// city drawn whole would turn grey. Maps and views both follow it.
inline constexpr double kMinOutlinedPixels = 6.0;

/// A shape's size across for the rule above, in its units: 4 area / perimeter
/// (the side of a square; about twice the width of a long strip).
double outlineSize(const Polygon& shape);

/// Renders `panels` side by side with the same extent (the union of every
/// panel's shapes) and the same scale, each with its title and a scale bar in
/// metres, one shared colour bar below and `title` above. A text too wide for
/// its room is set smaller (to 4/5 of its size), then on two lines. Throws
/// Error(Usage) when a panel's values do not match its shapes or no panel has a
/// shape, Error(IO) when there is no display or a file cannot be written.
void renderMaps(const std::string& title, const std::vector<MapPanel>& panels, const ColourScale& scale,
                const FigureOutput& output);

/// The maps of renderMaps as a vector figure of `width` x `height` (px; a PDF
/// page is half as many points): every shape a filled path (holes even-odd),
/// outlined where the PNG outlines it, with the same layout, colours, titles,
/// scale bars and colour bar; SVG or PDF by the extension of `path`. Needs no
/// display. Throws Error(Usage) as renderMaps, or for another extension;
/// Error(IO) when the file cannot be written.
void writeVectorMaps(const std::string& title, const std::vector<MapPanel>& panels, const ColourScale& scale, int width,
                     int height, const std::string& path);

/// The colours `scale` gives `values` on the maps (NaN: the no-value grey).
std::vector<Rgb> scaleColours(const ColourScale& scale, const std::vector<double>& values);

/// One series of an overlaid histogram.
struct HistogramSeries {
  std::string label;        ///< legend entry
  std::vector<int> counts;  ///< one per bin (frequencies, not normalised)
  Rgb colour;
};

/// Renders overlaid frequency histograms on shared bins `edges` (bins + 1
/// increasing values): each series as a translucent filled step outline, with
/// axis titles, a legend and `title`; the titles are fitted to the width as
/// renderMaps's (the vector copy keeps each on one line, only smaller). Throws
/// Error(Usage) when a series does not have one count per bin, Error(IO) as
/// renderMaps.
void renderHistogram(const std::string& title, const std::string& xTitle, const std::string& yTitle,
                     const std::vector<double>& edges, const std::vector<HistogramSeries>& series,
                     const FigureOutput& output);

/// "VTK 9.1.0", for run records.
std::string vtkVersionString();

}  // namespace parcelscope::viz
