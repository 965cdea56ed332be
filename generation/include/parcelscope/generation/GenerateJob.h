#pragma once
// The `generate` job: blocks in (a block layer, or observed parcels grouped into
// blocks exactly as `stats` does), procedural parcels out, with the same
// metrics as observed parcels. The command line and the GUI both call this.
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/analysis/StatsJob.h"
#include "parcelscope/core/Json.h"
#include "parcelscope/generation/ObbSubdivision.h"
#include "parcelscope/io/ParcelReader.h"

namespace parcelscope::generation {

struct GenerateRequest {
  io::ReadOptions input;
  /// The input holds observed parcels: build blocks and per-block A_min, A_max,
  /// W_min, W_max from them (as `stats`). Otherwise it holds block polygons, and
  /// numeric fields a_min, a_max, w_min, w_max (as in `stats`' blocks.gpkg) are
  /// used per block when present.
  bool fromParcels = false;
  std::string style = "obb";
  /// Values of analysis::analysisParameters() and obbParameterDescriptions().
  ParameterValues parameters;
  /// Names the user set explicitly: these override per-block values.
  std::set<std::string> explicitParameters;
  /// With fromParcels: the input already read and analysed with `parameters`
  /// (as `compare` does before generating); used instead of reading it again.
  const analysis::ObservedData* observed = nullptr;
};

/// Parameters a block runs with: the request's values, with the per-block bounds
/// (NaN when the block has none) where the user did not set them.
ObbParameters blockParameters(const GenerateRequest& request, double aMin, double aMax, double wMin,
                              double wMax);

struct GeneratedParcels {
  io::ParcelLayer source;                 ///< the input as read (frame, CRS, cleaning report)
  std::vector<Block> blocks;              ///< block outlines; `parcels` index `parcels` below
  std::vector<std::int64_t> blockIds;     ///< id of each entry of `blocks` (ids repeat for multipart blocks)
  std::vector<Polygon> parcels;           ///< generated parcels, local metres
  std::vector<analysis::ParcelMetrics> metrics;
  std::int64_t failedBlocks = 0, oversize = 0, withoutAccess = 0;
  std::int64_t clampedBounds = 0;         ///< per-block bounds moved into the parameter ranges
  std::vector<std::string> failures;      ///< one line per failed block
  std::uint64_t seed = 0;
  Timings timings;                        ///< "subdivide" and "measure"
};

/// Reads the input and subdivides every block (in parallel). Throws Error on bad
/// input or parameters (A_min > A_max, W_min > W_max, unknown style).
GeneratedParcels generate(const GenerateRequest& request, const ProgressFn& progress = {});

/// The generated parcels as parcels.gpkg and parcels.csv hold them: one row per
/// parcel in block order (parcel_id, block_id and every metric) and, when
/// `geometries` is given, each row's geometry.
Table generatedParcelTable(const GeneratedParcels& g, std::vector<std::vector<Polygon>>* geometries = nullptr);

/// Runs `generate` and writes DIR/parcels.gpkg (layer `parcels`, input CRS, field
/// block_id and the metrics), DIR/parcels.csv and DIR/run.json, all at once when
/// complete.
analysis::JobOutcome runGenerate(const GenerateRequest& request, const std::string& outDir,
                                 const ProgressFn& progress = {});

}  // namespace parcelscope::generation
