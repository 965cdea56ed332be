#pragma once
// The `compare` job (Vanegas et al. 2012, section 6): observed parcels in;
// blocks and per-block parameters exactly as `stats` derives them; procedural
// parcels generated in every block; both sets measured with the same metrics
// and compared block by block and city-wide; tables, layers, run records and
// figures out. The command line and the GUI both call this.
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/analysis/StatsJob.h"
#include "parcelscope/core/Parameter.h"
#include "parcelscope/generation/GenerateJob.h"
#include "parcelscope/io/ParcelReader.h"
#include "parcelscope/viz/Figures.h"

namespace parcelscope::viz {

struct CompareRequest {
  io::ReadOptions input;         ///< observed parcels
  std::string style = "obb";     ///< generator style, passed to generation::GenerateRequest::style
  /// Values named as in compareParameters() (analysis, generator and comparison).
  ParameterValues parameters;
  /// Names the user set explicitly: a generator bound given here overrides the per-block ones.
  std::set<std::string> explicitParameters;
  /// Per-block style and parameters over the run's (see generation::BlockOverride).
  generation::BlockOverrides overrides;
  /// A parcel quantity (analysis::parcelQuantities()) drawn as the extra figures
  /// map_<metric> and hist_<metric> when it is not one drawn anyway.
  std::string metric = "aspect_ratio";
  /// Vector copy of the histograms written by runCompare: "svg" or "pdf".
  std::string vectorFormat = "svg";
  /// Format of the generated parcels written by runCompare: "gpkg"
  /// (parcels.gpkg) or "geojson" (parcels.geojson).
  std::string parcelsFormat = "gpkg";
};

/// The value of compare parameter `name` in `request`, or its default.
double compareValue(const CompareRequest& request, const std::string& name);

/// The comparison's own parameters: histogram bins and range, figures and their
/// size, the aspect ratio shown fully green.
const std::vector<ParameterDescription>& comparisonParameters();
/// Every parameter of `compare`: analysisParameters(), the generator's
/// (generationParameterDescriptions(), "seed" included) and comparisonParameters(),
/// each name once.
std::vector<ParameterDescription> compareParameters();

struct CompareResult {
  /// Shared between successive results of a CompareSession.
  std::shared_ptr<const analysis::ObservedData> observed;
  generation::GeneratedParcels generated;
  /// Metrics of the observed parcels that belong to a block (right-of-way left out).
  std::vector<analysis::ParcelMetrics> observedLots;
  /// While generated.contextPending is not empty (a CompareSession update that
  /// deferred the context), the generated street access share of the city and
  /// of the blocks holding pending entries is NaN.
  analysis::Comparison city;
  /// One per observed block, in block order; generated parcels are matched to
  /// blocks by block id (a multipart block's parts are one block).
  std::vector<analysis::BlockComparison> blocks;
  /// The observed side of every comparison, prepared once per observed data
  /// and shared between successive results of a CompareSession: one per
  /// observed block, in block order, then the city's (observedLots).
  std::shared_ptr<const std::vector<analysis::PreparedSet>> observedSides;
  /// City-wide histograms on shared bins, in the order of analysis::kComparedMetrics,
  /// made with `histogramBins` bins up to the pooled `histogramQuantile`.
  std::vector<analysis::SharedHistogram> histograms;
  int histogramBins = 0;
  double histogramQuantile = 0;
  /// Seconds per stage: "read" (read, project, clean), "blocks" (observed
  /// metrics, blocks, statistics), "generate" (subdivision), "metrics"
  /// (measuring the generated parcels and comparing).
  std::vector<std::pair<std::string, double>> seconds;
};

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
                                    const std::string& quantity,
                                    HistogramTexts texts = HistogramTexts::WithNumbers);

/// Index of the observed block that contains `p` (local metres), or -1.
int blockAt(const CompareResult& result, const Point& p);

/// The figures of `compare`, one at a time (the GUI exports what it shows with
/// these): observed and procedural parcels side by side coloured by
/// `quantity`; the overlaid histograms of `quantity` (observed red, procedural
/// blue); the blocks coloured by the KS statistic of area. Throw as renderMaps.
void renderQuantityMap(const CompareResult& result, const CompareRequest& request, const std::string& quantity,
                       const FigureOutput& output);
void renderQuantityHistogram(const CompareResult& result, const CompareRequest& request,
                             const std::string& quantity, const FigureOutput& output);
void renderBlocksMap(const CompareResult& result, const CompareRequest& request, const FigureOutput& output);

/// The tables of `compare`, by file name: observed_parcels.csv,
/// generated_parcels.csv, blocks.csv, summary.csv, distances.csv.
std::vector<std::pair<std::string, Table>> comparisonTables(const CompareResult& result);

/// The figures a result can be exported as: map_<quantity> and hist_<quantity>
/// for every parcel quantity, and map_blocks.
std::vector<std::string> figureNames();

/// Renders figure `name` (see figureNames()) into `path`, which appears only
/// when complete: .png for every figure; .svg or .pdf for histograms (VTK
/// rasterises maps). `inputs` are never overwritten. Throws Error(Usage) on an
/// unknown figure or extension, Error(IO) as renderMaps.
void exportFigure(const CompareResult& result, const CompareRequest& request, const std::string& name,
                  const std::string& path, int width, int height);
/// Writes the generated parcels as compare's parcels.gpkg does, into a
/// GeoPackage (.gpkg) or GeoJSON (.geojson, .json) file, atomically.
void exportParcels(const CompareResult& result, const std::string& path, const std::vector<std::string>& inputs);
/// Writes comparisonTables() into the existing folder `folder`, each file atomically.
void exportTables(const CompareResult& result, const std::string& folder, const std::vector<std::string>& inputs);
/// Writes sessionJson(request) into `path`, atomically.
void exportSession(const CompareRequest& request, const std::string& path);

/// Reads, analyses, generates and compares (blocks in parallel). Throws Error on
/// bad input or parameters (an unknown style is Error(Usage)), Error(Cancelled)
/// when `progress` asks to stop.
CompareResult compare(const CompareRequest& request, const ProgressFn& progress = {});

/// Runs compare() and writes into `outDir`, all at once when complete:
/// parcels.gpkg (generated parcels, layer `parcels`, input CRS, block_id and the
/// metrics), blocks.gpkg (observed blocks with the per-block comparison),
/// observed_parcels.csv, generated_parcels.csv, blocks.csv, summary.csv,
/// distances.csv, summary.json, run.json and, unless figures = 0, the figures in
/// figures/ (PNG; the histograms hist_area, hist_width and hist_aspect_ratio
/// also as SVG; the maps map_aspect_ratio and map_blocks as PNG only; with
/// another request.metric also map_<metric> and hist_<metric>). Throws as compare(), and Error(IO) when
/// figures are asked for without an X server; the output directory is then
/// left as it was.
analysis::JobOutcome runCompare(const CompareRequest& request, const std::string& outDir,
                                const ProgressFn& progress = {});

}  // namespace parcelscope::viz
