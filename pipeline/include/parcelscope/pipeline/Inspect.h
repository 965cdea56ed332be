#pragma once
// One observed parcel and its block, as `parcelscope inspect` prints them and
// the application's inspector shows them: the parcel's identity (ids, key,
// source feature, role), every metric of the metric registry
// (analysis::parcelMetrics()) and its block's statistics (the blocks.csv row).
#include <string>
#include <utility>
#include <vector>

#include "parcelscope/core/Json.h"
#include "parcelscope/core/Progress.h"
#include "parcelscope/core/Table.h"
#include "parcelscope/io/ParcelReader.h"
#include "parcelscope/pipeline/GenerateJob.h"
#include "parcelscope/pipeline/StatsJob.h"

namespace parcelscope::pipeline {

/// Named values in a fixed order.
using NamedValues = std::vector<std::pair<std::string, Value>>;

struct ParcelInspection {
  std::string path;  ///< the input file
  /// What the input says of the parcel: parcel_id, parcel_key, source_fid,
  /// part, block_id, block_key, role, stack_count, repaired (the parcels.csv columns).
  NamedValues attributes;
  /// Every metric of analysis::parcelMetrics(), in its order.
  NamedValues metrics;
  /// The block's statistics and derived bounds (the blocks.csv row); empty for
  /// a right-of-way parcel, which belongs to no block.
  NamedValues block;
};

/// Index of the observed parcel of `data` containing `p` (local metres, on its
/// boundary included), or -1. Where parcels overlap, the first in input order.
int parcelAt(const ObservedData& data, const Point& p);
/// Index of the generated parcel of `g` containing `p` (local metres), or -1.
int generatedParcelAt(const GeneratedParcels& g, const Point& p);

/// Parcel `parcel` (an index into data.layer.parcels) and its block.
ParcelInspection inspectParcel(const ObservedData& data, int parcel);
/// A generated parcel (an index into g.parcels): its ids and every metric;
/// `block` is left empty (the caller has the block's comparison).
ParcelInspection inspectGeneratedParcel(const GeneratedParcels& g, int parcel);

struct InspectRequest {
  io::ReadOptions input;
  /// Values of analysis::analysisParameters() (k, block tolerance, ...).
  ParameterValues parameters;
  /// The point, in the input's coordinates (longitude and latitude for a
  /// geographic CRS; that of --crs when given).
  double x = 0, y = 0;
};

/// Reads and analyses the input as `stats` does and inspects the parcel at the
/// point. Throws Error(Input) naming the file when no parcel is there (or as
/// loadObserved).
ParcelInspection inspect(const InspectRequest& request, const ProgressFn& progress = {});

/// One "name: value" line per attribute, metric and block statistic, in that
/// order; block statistics are prefixed "block." (block.mean_area: 812.5).
std::string inspectionText(const ParcelInspection& inspection);
/// {"file", "parcel": {attributes}, "metrics": {...}, "block": {...} or null}.
Json inspectionJson(const ParcelInspection& inspection);
/// A value as the text tables write it (reals with up to 10 significant digits; NaN as "nan").
std::string valueText(const Value& value);

}  // namespace parcelscope::pipeline
