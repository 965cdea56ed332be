#pragma once
// The `stats` job: read observed parcels, analyse them, write the tables, the
// block layer and the run record. The command line and the GUI both call this.
#include <string>

#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/Json.h"
#include "parcelscope/io/ParcelReader.h"

namespace parcelscope::analysis {

struct ObservedData {
  io::ParcelLayer layer;
  ObservedAnalysis analysis;
};

/// Reads `input` and analyses it with `parameters` (names of analysisParameters()).
ObservedData loadObserved(const io::ReadOptions& input, const ParameterValues& parameters,
                          const ProgressFn& progress = {});

/// Adds the run record's "input" and "counts" sections for observed data to `record`.
void addObservedRecord(Json& record, const ObservedData& data);

/// Runs `stats` and writes, all at once when complete, into `outDir`:
/// parcels.csv, blocks.csv, blocks.gpkg (layer `blocks`, input CRS) and run.json.
/// Returns the run record. Throws Error on bad input or failed output; the
/// output directory is then left as it was.
Json runStats(const io::ReadOptions& input, const ParameterValues& parameters, const std::string& outDir,
              const ProgressFn& progress = {});

/// "0.1.0": the project version written into run records.
std::string version();

}  // namespace parcelscope::analysis
