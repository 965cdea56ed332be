#pragma once
// The `compare` job (Vanegas et al. 2012, section 6): observed parcels in;
// blocks and per-block parameters exactly as `stats` derives them; procedural
// parcels generated in every block; both sets measured with the same metrics
// and compared block by block and city-wide; tables, layers, run records and
// figures out. The command line and the GUI both call this.
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/core/Parameter.h"
#include "parcelscope/io/ParcelReader.h"
#include "parcelscope/io/StreetReader.h"
#include "parcelscope/pipeline/GenerateJob.h"
#include "parcelscope/pipeline/StatsJob.h"

namespace parcelscope::pipeline {

struct CompareRequest {
  io::ReadOptions input;  ///< observed parcels
  /// Street centre lines: blocks come from the street network and the observed
  /// parcels are assigned to them (see StreetsJob.h); the street parameters
  /// (streetParameters()) are read from `parameters`. None: blocks grouped from
  /// the parcels.
  std::optional<io::StreetReadOptions> streets;
  std::string style = "obb";  ///< generator style, passed to pipeline::GenerateRequest::style
  /// Values named as in compareParameters() (analysis, generator and comparison).
  ParameterValues parameters;
  /// Names the user set explicitly: a generator bound given here overrides the per-block ones.
  std::set<std::string> explicitParameters;
  /// Per-block style and parameters over the run's (see pipeline::BlockOverride).
  pipeline::BlockOverrides overrides;
  /// Overrides by block id, from version 1 session files (see BlockOverridesById).
  pipeline::BlockOverridesById overridesById;
  /// A parcel quantity (analysis::parcelQuantities()) drawn as the extra figures
  /// map_<metric> and hist_<metric> when it is not one drawn anyway.
  std::string metric = "aspect_ratio";
  /// Vector copy of the histograms written by runCompare: "svg" or "pdf".
  std::string vectorFormat = "svg";
  /// Format of the generated parcels written by runCompare: "gpkg"
  /// (parcels.gpkg) or "geojson" (parcels.geojson).
  std::string parcelsFormat = "gpkg";
  /// Other files or folders the request came from (its session file, the
  /// shard folders of a merge): inputs too for the output folder's checks.
  /// Not written to sessions.
  std::vector<std::string> readFrom;
};

/// The files `request` reads (its input, its streets when given, and
/// `readFrom`): an output folder must never hold or lie in one of them
/// (io::OutputDirectory).
std::vector<std::string> inputPaths(const CompareRequest& request);

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
  std::shared_ptr<const pipeline::ObservedData> observed;
  pipeline::GeneratedParcels generated;
  /// Metrics of the observed parcels that belong to a block (right-of-way left out).
  std::vector<analysis::ParcelMetrics> observedLots;
  /// While generated.contextPending is not empty (a CompareSession update that
  /// deferred the context), the generated street access share of the city and
  /// of the blocks holding pending entries is NaN.
  analysis::Comparison city;
  /// One per observed block, in block order; generated parcels are matched to
  /// blocks by block key (a multipart block's parts are one block). Blocks of
  /// the generation that no observed block matches (a block source without
  /// observed parcels there) follow, each compared with an empty observed side.
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

/// Index of the observed block that contains `p` (local metres), or -1.
int blockAt(const CompareResult& result, const Point& p);

/// The tables of `compare`, by file name: observed_parcels.csv,
/// generated_parcels.csv, blocks.csv, summary.csv, distances.csv.
std::vector<std::pair<std::string, Table>> comparisonTables(const CompareResult& result);

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
/// The same with the observed data already read and analysed (as
/// loadObservedInStreetBlocks gives it for `request`): only generates and compares.
/// With `premade`, block entries made elsewhere (GenerateRequest::premade);
/// with `reusable` and `keep`, outcomes of earlier runs on the same blocks
/// (GenerateRequest::reusable, ::keep).
CompareResult compare(const CompareRequest& request, std::shared_ptr<const pipeline::ObservedData> observed,
                      const ProgressFn& progress = {}, std::vector<PremadeBlock>* premade = nullptr,
                      const OutcomeLibrary* reusable = nullptr, OutcomeLibrary* keep = nullptr);

/// What draws the figures of runCompare; the rendering library supplies one
/// (viz::compareFigureRenderer()), so that this library links no renderer.
struct FigureRenderer {
  /// Throws Error when no figure can be drawn here; called before the long work.
  std::function<void()> check;
  /// Draws the figures of `result`: `stage` turns a name relative to the
  /// output folder ("figures/map_aspect_ratio.png") into the path to write;
  /// returns the relative names written.
  std::function<std::vector<std::string>(const CompareResult& result, const CompareRequest& request,
                                         const std::function<std::string(const std::string&)>& stage,
                                         const ProgressFn& progress)>
      draw;
  /// The renderer's version, recorded in run.json ("vtk").
  std::string version;
};

/// Runs compare() and writes into `outDir`, all at once when complete:
/// parcels.gpkg (generated parcels, layer `parcels`, input CRS, block_id and the
/// metrics), blocks.gpkg (observed blocks with the per-block comparison),
/// observed_parcels.csv, generated_parcels.csv, blocks.csv, summary.csv,
/// distances.csv, summary.json, run.json and, unless figures = 0, the figures in
/// figures/ (PNG; the histograms hist_area, hist_width and hist_aspect_ratio
/// also as SVG; the maps map_aspect_ratio and map_blocks as PNG only; with
/// another request.metric also map_<metric> and hist_<metric>). Throws as compare(), and as
/// `figures`; the output directory is then left as it was.
/// `figures` draws them (figures = 1 without one is Error(Usage)). With
/// `prepared`, its data is compared (as compare(request, observed)).
/// Observed data read and analysed elsewhere (pipeline::mergeShards of the
/// shards of several processes), and what run.json records of them.
struct PreparedObserved {
  std::shared_ptr<const ObservedData> data;
  /// Block entries the shards subdivided and measured (GenerateRequest::premade):
  /// the run takes them as its own where its plan agrees. Null: none.
  std::shared_ptr<std::vector<PremadeBlock>> premade;
  int ranks = 1;  ///< run.json's "ranks"
  Json shards;    ///< run.json's "shards": each one's blocks, parcels and seconds
};
JobOutcome runCompare(const CompareRequest& request, const std::string& outDir, const ProgressFn& progress = {},
                      const FigureRenderer* figures = nullptr, const PreparedObserved* prepared = nullptr);

}  // namespace parcelscope::pipeline
