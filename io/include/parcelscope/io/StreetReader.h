#pragma once
// Reading street centre lines from any line layer GDAL reads (LineString,
// MultiLineString; curves linearised), into the local metric plane, with a
// width, a name and whether each line meets what it crosses (bridges and
// tunnels do not).
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"
#include "parcelscope/core/Keys.h"
#include "parcelscope/io/LocalFrame.h"
#include "parcelscope/io/ParcelReader.h"

namespace parcelscope::io {

/// The widest street width taken (metres): a width field, a class width or an
/// edit above it is an error (a street 1e300 m wide emptied every block).
constexpr double kMaxStreetWidth = 1000.0;
/// Farthest a street point may lie from the parcels' centre (m) when streets
/// are read in the parcels' frame: farther, the file is refused.
constexpr double kMaxStreetReach = 1000000.0;

struct StreetReadOptions {
  std::string path;
  std::string layer;        ///< layer name; empty = the first layer
  std::string where;        ///< OGR SQL attribute filter; empty = none
  std::string crsOverride;  ///< e.g. "EPSG:2286"; replaces a missing or wrong CRS
  /// Numeric field holding each street's width: metres, or the unit of a
  /// projected CRS (US feet for EPSG:2286). Empty: none.
  std::string widthField;
  /// Field holding each street's class, and the width in metres of each class
  /// value (a value not listed gives no width). Used where the width field is
  /// absent or null.
  std::string classField;
  std::map<std::string, double> classWidths;
  std::string nameField;  ///< field holding the street's name; empty = none
  /// OGR SQL filter selecting the lines that meet nothing they cross (bridges,
  /// tunnels); empty = none.
  std::string noNodeWhere;
};

struct StreetReport {
  std::int64_t features = 0;          ///< features read (after --where)
  std::int64_t nullOrEmpty = 0;       ///< skipped: null or empty geometry
  std::int64_t nonLinear = 0;         ///< skipped: neither a line nor lines
  std::int64_t nonFiniteSkipped = 0;  ///< skipped: a NaN or infinite coordinate, or beyond 1e12
  std::int64_t lines = 0;             ///< lines kept (a multiline gives one per part)
  std::int64_t withWidth = 0;         ///< lines with a width from the width or class field
  std::int64_t noNode = 0;            ///< lines selected by noNodeWhere
};

struct StreetFeature {
  std::vector<Point> line;  ///< local metres
  double width = NAN;       ///< metres; NaN when unknown
  std::string name;
  bool noNode = false;
  Key key = 0;  ///< hash of the feature's geometry (ISO WKB), mixed with its part
  std::int64_t fid = -1;
};

struct StreetLayer {
  std::string path;
  std::string layerName;
  std::vector<StreetFeature> streets;
  LocalFrame frame;
  CrsInfo crs;
  StreetReport report;
};

/// Reads one line layer. With `frame` and `crs` (those of parcels read
/// before), the lines are taken to that CRS (when theirs differs) and that
/// frame, so that streets and parcels share one plane; otherwise the layer
/// chooses its own frame as readParcels does. Throws Error(Input) with a
/// one-line message naming the file (and the feature or field) on the same
/// grounds as readParcels, and when a named field is missing, a width is
/// negative or not finite, or the layer holds no line; Error(Usage) for an
/// unknown --crs.
StreetLayer readStreets(const StreetReadOptions& options, const LocalFrame* frame = nullptr,
                        const CrsInfo* crs = nullptr);

}  // namespace parcelscope::io
