#pragma once
// The `compare` job (Vanegas et al. 2012, section 6): observed parcels in;
// blocks and per-block parameters exactly as `stats` derives them; procedural
// parcels generated in every block; both sets measured with the same metrics
// and compared block by block and city-wide; tables, layers, run records and
// figures out. The command line and the GUI both call this.
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/analysis/StatsJob.h"
#include "parcelscope/core/Parameter.h"
#include "parcelscope/generation/GenerateJob.h"
#include "parcelscope/io/ParcelReader.h"

namespace parcelscope::viz {

struct CompareRequest {
  io::ReadOptions input;         ///< observed parcels
  std::string style = "obb";     ///< generator style, passed to generation::GenerateRequest::style
  /// Values named as in compareParameters() (analysis, generator and comparison).
  ParameterValues parameters;
  /// Names the user set explicitly: a generator bound given here overrides the per-block ones.
  std::set<std::string> explicitParameters;
};

/// The comparison's own parameters: histogram bins and range, figures and their
/// size, the aspect ratio shown fully green.
const std::vector<ParameterDescription>& comparisonParameters();
/// Every parameter of `compare`: analysisParameters(), the generator's
/// (generationParameterDescriptions(), "seed" included) and comparisonParameters(),
/// each name once.
std::vector<ParameterDescription> compareParameters();

struct CompareResult {
  analysis::ObservedData observed;
  generation::GeneratedParcels generated;
  /// Metrics of the observed parcels that belong to a block (right-of-way left out).
  std::vector<analysis::ParcelMetrics> observedLots;
  analysis::Comparison city;
  /// One per observed block, in block order; generated parcels are matched to
  /// blocks by block id (a multipart block's parts are one block).
  std::vector<analysis::BlockComparison> blocks;
  /// City-wide histograms on shared bins, in the order of analysis::kComparedMetrics.
  std::vector<analysis::SharedHistogram> histograms;
  /// Seconds per stage: "read" (read, project, clean), "blocks" (observed
  /// metrics, blocks, statistics), "generate" (subdivision), "metrics"
  /// (measuring the generated parcels and comparing).
  std::vector<std::pair<std::string, double>> seconds;
};

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
/// also as SVG; the maps map_aspect_ratio and map_blocks as PNG only). Throws as compare(), and Error(IO) when
/// figures are asked for without an X server; the output directory is then
/// left as it was.
analysis::JobOutcome runCompare(const CompareRequest& request, const std::string& outDir,
                                const ProgressFn& progress = {});

}  // namespace parcelscope::viz
