#pragma once
// The `stats` job: read observed parcels, analyse them, write the tables, the
// block layer and the run record. The command line and the GUI both call this.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/Json.h"
#include "parcelscope/io/ParcelReader.h"
#include "parcelscope/io/Writers.h"

namespace parcelscope::pipeline {

struct StreetNetwork;

struct ObservedData {
  io::ParcelLayer layer;
  analysis::ObservedAnalysis analysis;
  /// With --streets: the street network whose blocks `analysis.blocks` are
  /// (block b is the network's block b; see assignToStreetBlocks), and the
  /// lots that lie in none of them. Null: blocks grouped from the parcels.
  std::shared_ptr<const StreetNetwork> streets;
  std::int64_t outsideStreetBlocks = 0;
  /// Per block, its outline as a file holds it (io::fileGeometry), when made
  /// beside the blocks (by the shards of the run); empty otherwise.
  std::vector<io::FileGeometry> blocksWritten;
};

/// Reads `input` and analyses it with `parameters` (names of analysisParameters()).
ObservedData loadObserved(const io::ReadOptions& input, const ParameterValues& parameters,
                          const ProgressFn& progress = {});

/// Adds the run record's "input" and "counts" sections for observed data to `record`.
void addObservedRecord(Json& record, const ObservedData& data);

/// A finished job: its run record (as written to run.json) and a few lines of
/// summary for people.
struct JobOutcome {
  Json record;
  std::string summary;
  /// What the job made (its result; may be null), handed to the caller: a
  /// command line about to exit may keep it rather than free it piece by piece.
  std::shared_ptr<const void> result;
};

/// One-paragraph summary of what was read, repaired, skipped and grouped.
std::string summarize(const ObservedData& data);

/// Runs `stats` and writes, all at once when complete, into `outDir`:
/// parcels.csv, blocks.csv, blocks.gpkg (layer `blocks`, input CRS) and run.json.
/// Throws Error on bad input or failed output; the output directory is then
/// left as it was.
JobOutcome runStats(const io::ReadOptions& input, const ParameterValues& parameters, const std::string& outDir,
                    const ProgressFn& progress = {});

/// "0.1.0": the project version written into run records.
std::string version();

/// The opening of every run record: tool, version, command, GDAL version and the
/// parameter values.
Json runRecord(const std::string& command, const ParameterValues& parameters);

/// The run record's "written" entry for the polygon layers written: per file,
/// its features and how many were repaired in the CRS written (see
/// io::writePolygonLayer).
Json writtenLayersJson(const std::vector<std::pair<std::string, io::LayerWrite>>& layers);

}  // namespace parcelscope::pipeline
