#pragma once
// The figures of `compare`: colour scales, histograms, maps, and the renderer
// that pipeline::runCompare draws them with.
#include <functional>
#include <string>
#include <vector>

#include "parcelscope/pipeline/Calibrate.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/Leaderboard.h"
#include "parcelscope/viz/Figures.h"

namespace parcelscope::viz {

using pipeline::CompareRequest;
using pipeline::CompareResult;

/// The colour scale of parcel quantity `quantity`, shared by both sets: aspect
/// ratio red (1:1) to green (map-aspect-ratio-max, Vanegas et al. 2012, Figure 1);
/// street access 0 to 1; the others pale to dark from the smallest observed
/// value to the observed histogram-quantile (nearest rank), values beyond
/// either end drawn at that end. The generated parcels set the range only when
/// no observed parcel has a value, so the scale stays put while generation
/// parameters change. Throws Error(Usage) for an unknown quantity.
ColourScale quantityScale(const CompareResult& result, const CompareRequest& request, const std::string& quantity);

/// The overlaid histograms of parcel quantity `quantity` on shared bins, with
/// titles and legend labels, as hist_<quantity> draws them. Empty edges when
/// neither side has a finite value. Throws Error(Usage) for an unknown quantity.
struct QuantityHistogram {
  std::string title, xTitle, yTitle;
  std::vector<double> edges;
  std::vector<HistogramSeries> series;  ///< observed (red), procedural (blue)
};
/// Which texts a histogram carries: the figure's, with the numbers of this
/// result (legend counts, the value the last bin starts at), or texts that
/// stay the same from one result to the next (a chart redrawn after every
/// change: VTK keeps the textures of the last 50 texts drawn, first in first
/// out, so one new text per redraw soon made it draw every label again).
enum class HistogramTexts { WithNumbers, Steady };
QuantityHistogram quantityHistogram(const CompareResult& result, const CompareRequest& request,
                                    const std::string& quantity, HistogramTexts texts = HistogramTexts::WithNumbers);

/// The figures of `compare`, one at a time (the GUI exports what it shows with
/// these): observed and procedural parcels side by side coloured by
/// `quantity`; the overlaid histograms of `quantity` (observed red, procedural
/// blue); the blocks coloured by the KS statistic of area. Throw as renderMaps.
void renderQuantityMap(const CompareResult& result, const CompareRequest& request, const std::string& quantity,
                       const FigureOutput& output);
void renderQuantityHistogram(const CompareResult& result, const CompareRequest& request, const std::string& quantity,
                             const FigureOutput& output);
void renderBlocksMap(const CompareResult& result, const CompareRequest& request, const FigureOutput& output);

/// The figures a result can be exported as: map_<quantity> and hist_<quantity>
/// for every parcel quantity, and map_blocks.
std::vector<std::string> figureNames();

/// Renders figure `name` (see figureNames()) into `path`, which appears only
/// when complete: .png for every figure; .svg or .pdf for histograms (VTK
/// rasterises maps). `inputs` are never overwritten. Throws Error(Usage) on an
/// unknown figure or extension, Error(IO) as renderMaps.
void exportFigure(const CompareResult& result, const CompareRequest& request, const std::string& name,
                  const std::string& path, int width, int height);
/// The renderer of compare's figures for pipeline::runCompare: the maps of
/// aspect ratio and blocks, the histograms of the compared metrics, and those
/// of request.metric; it needs an X server (Error(IO) without one).
const pipeline::FigureRenderer& compareFigureRenderer();

/// The leaderboard's figure (compare --style all): the aspect-ratio maps of the
/// observed parcels and of every style, small multiples on one scale, as
/// leaderboard.png (rendered: needs an X server, started if none) and
/// leaderboard.svg (vector paths). Returns the names written.
std::vector<std::string> drawLeaderboard(const pipeline::Leaderboard& board, const CompareRequest& request,
                                         const std::function<std::string(const std::string&)>& stage);

/// The calibration's figures: `figures/map_fit.png` (+ .svg), the blocks
/// coloured by their distance to their observed parcels before (the paper's
/// rule) and after calibration; `figures/hist_calibration_QUANTITY.png` (+
/// .svg) for area, width and aspect ratio: observed, before and after on
/// shared bins. Returns the names written.
std::vector<std::string> drawCalibration(const pipeline::Calibration& calibration, const CompareRequest& request,
                                         const std::function<std::string(const std::string&)>& stage);

/// pipeline::runCalibrate with drawCalibration.
pipeline::JobOutcome runCalibrate(const CompareRequest& request, const std::string& outDir,
                                  const ProgressFn& progress = {});

/// pipeline::runLeaderboard with drawLeaderboard.
pipeline::JobOutcome runLeaderboard(const CompareRequest& request, const std::string& outDir,
                                    const ProgressFn& progress = {});

/// pipeline::runCompare with compareFigureRenderer().
pipeline::JobOutcome runCompare(const CompareRequest& request, const std::string& outDir,
                                const ProgressFn& progress = {}, const pipeline::PreparedObserved* prepared = nullptr);

}  // namespace parcelscope::viz
