#pragma once
// Reading observed parcels from any polygon source GDAL/OGR reads (GeoJSON,
// TopoJSON, GeoPackage, Shapefile, FlatGeobuf, ...), projecting them to a local
// metric plane and cleaning them. Cleaning is never silent: every repair, split,
// collapse and skip is counted in CleaningReport.
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "parcelscope/core/Parcel.h"
#include "parcelscope/core/Progress.h"
#include "parcelscope/core/Timings.h"
#include "parcelscope/io/LocalFrame.h"

namespace parcelscope::io {

/// The features' extent and envelope centres from which the local frame is
/// chosen (its origin is the median centre), input CRS.
struct FrameSample {
  Box extent{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
             std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest()};
  std::vector<double> centresX, centresY;
};

/// One shard of a layer read by several processes (see pipeline/Shards.h).
/// The shards' tiles are vertical strips that cover the plane: a feature
/// belongs to the strip holding its envelope's smallest x, so each feature is
/// counted once. A shard reads the features whose envelope meets its window.
struct ShardRead {
  /// Input CRS: features whose envelope intersects it are cleaned and returned.
  Box window;
  /// [tileMinX, tileMaxX): the strip whose features this shard counts (cleaning report).
  double tileMinX = -std::numeric_limits<double>::infinity();
  double tileMaxX = std::numeric_limits<double>::infinity();
  /// true: only the window is read (a GeoPackage's R-tree; other formats are
  /// read whole, their features' envelopes tested), and `exchange` turns
  /// this shard's frame sample (its own features) into every shard's. false:
  /// every feature is read to choose the frame, only the window's are cleaned.
  bool spatialFilter = false;
  std::function<void(FrameSample&)> exchange;
  /// When set, the frame (of an earlier read of the same layer) is used as is
  /// and nothing is exchanged.
  std::optional<LocalFrame> frame;
};

struct ReadOptions {
  std::string path;
  std::string layer;        ///< layer name; empty = the first layer
  std::string where;        ///< OGR SQL attribute filter; empty = none
  std::string crsOverride;  ///< e.g. "EPSG:2286"; replaces a missing or wrong CRS
  /// Numeric attributes to carry per parcel (ParcelLayer::fields); absent or
  /// null values read as NaN.
  std::vector<std::string> numericFields;
  /// Field whose value is each feature's stable key (Parcel::featureKey): a
  /// value of 16 hexadecimal digits is the key itself (as `stats` writes
  /// block_key), any other value is hashed. Empty: keys come from geometries.
  /// A value missing on a feature, or the field missing from the layer, is
  /// Error(Input) unless `keyFieldOptional` (then that feature's geometry is used).
  std::string keyField;
  bool keyFieldOptional = false;
  /// Set: read one shard (features in input order of their ids; a window
  /// without features is no error).
  std::optional<ShardRead> shard;
};

struct CleaningReport {
  std::int64_t features = 0;             ///< features read (after --where)
  std::int64_t nullOrEmpty = 0;          ///< skipped: null or empty geometry
  std::int64_t nonPolygonal = 0;         ///< skipped: points or lines only
  std::int64_t nonPolygonalParts = 0;    ///< point or line members dropped from mixed collections
  std::int64_t nonFiniteSkipped = 0;     ///< skipped: a NaN or infinite coordinate (any vertex), or beyond 1e12
  std::int64_t multipartFeatures = 0;    ///< multipolygon features with more than one part
  std::int64_t partsFromMultipart = 0;   ///< parcels those features were split into (after repair)
  std::int64_t withHoles = 0;            ///< parcels that keep one or more holes
  std::int64_t invalidRepaired = 0;      ///< invalid polygons repaired by make-valid
  std::int64_t invalidSkipped = 0;       ///< invalid polygons make-valid could not save
  std::int64_t degenerateSkipped = 0;    ///< parts under 0.001 m² or with fewer than 3 vertices
  std::int64_t duplicatesCollapsed = 0;  ///< features dropped as exact copies of another
  std::int64_t duplicateStacks = 0;      ///< distinct geometries that had copies
  std::int64_t parcels = 0;              ///< parcels kept
};

struct CrsInfo {
  std::string wkt;             ///< CRS of the input (or of --crs); empty when none was declared
  std::string name;            ///< human-readable name, e.g. "WGS 84" or "assumed OGC:CRS84"
  bool assumedLonLat = false;  ///< no CRS declared; coordinates look like degrees
  bool overridden = false;     ///< came from --crs
};

struct ParcelLayer {
  std::string path;
  std::string layerName;
  std::vector<Parcel> parcels;  ///< local metres, normalised
  LocalFrame frame;
  CrsInfo crs;
  CleaningReport report;
  Timings timings;  ///< "read" and "clean"
  /// Per parcel, the values of ReadOptions::numericFields in that order.
  std::vector<std::vector<double>> fields;
  /// A shard's read only: per parcel, its feature's envelope's smallest x in
  /// the input CRS (what places a block in a strip, exactly, in every shard).
  std::vector<double> sourceMinX;
};

/// The names of the vector layers of `path`, in order. Throws Error(Input) as
/// readParcels when the file cannot be opened or holds no layer.
std::vector<std::string> layerNames(const std::string& path);

/// The attribute fields of layer `layer` of `path` (empty: the first), in
/// order, and whether each is numeric. Throws Error(Input) as layerNames, and
/// when there is no such layer.
struct FieldInfo {
  std::string name;
  bool numeric = false;
};
std::vector<FieldInfo> layerFields(const std::string& path, const std::string& layer = {});

/// The files of a multi-file input, in order: a folder's vector files (by
/// extension, sorted by name; a .gdb folder is one dataset) or the paths a list
/// file (.txt, .lst) holds, one per line. Empty when `path` is one dataset.
/// readParcels reads such an input as one layer (the union of each file's layer).
std::vector<std::string> inputFiles(const std::string& path);

/// The extent of the layer `options` names (input CRS) as GDAL reports it,
/// without reading every feature where the format stores it; the filter and
/// the shard are ignored. Throws Error(Input) as readParcels.
Box layerExtent(const ReadOptions& options);

/// The number of features of the layer `options` names that pass its filter
/// (geometry or not), counted by GDAL (an SQL count where the format has one).
std::int64_t featureCount(const ReadOptions& options);

/// Reads, projects and cleans the polygons of one layer.
/// Throws Error(Input) with a one-line message naming the file (and the feature
/// or layer) when the file is missing, empty, neither a regular file nor a folder
/// (a device or a named pipe is refused before GDAL opens it, so it never
/// blocks), not a format GDAL reads, or fails to read part way through the layer
/// (GDAL's message; the layer is never returned truncated); when the layer or the
/// filter is wrong, the layer holds no polygon (saying so when every feature was
/// skipped for non-finite or absurd coordinates), or the CRS cannot be used
/// (including lon/lat claimed for coordinates that cannot be degrees);
/// Error(Usage) when `crsOverride` is not a CRS GDAL knows.
ParcelLayer readParcels(const ReadOptions& options, const ProgressFn& progress = {});

}  // namespace parcelscope::io
