#pragma once
// A GeoPackage layer's features written straight through SQLite, as GDAL
// would write them. GDAL 3.6 makes an OGRFeature and an OGRGeometry per row,
// formats every Integer64 value as text for SQLite to parse back, and exports
// the geometry a second time to compute its envelope; for hundreds of
// thousands of small polygons that is most of the time spent inserting. GDAL
// still makes the file, the table, its metadata and its spatial index; only
// the rows go through here.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"
#include "parcelscope/core/Table.h"

namespace parcelscope::io::detail {

/// A geometry's envelope (min/max over every vertex), or empty.
struct Envelope {
  bool empty = true;
  double minx = 0, maxx = 0, miny = 0, maxy = 0;
  /// Grown to hold the point.
  void cover(double x, double y) {
    if (empty) {
      *this = {false, x, x, y, y};
      return;
    }
    minx = std::min(minx, x);
    maxx = std::max(maxx, x);
    miny = std::min(miny, y);
    maxy = std::max(maxy, y);
  }
  /// Grown to hold `e` (unchanged when `e` is empty).
  void merge(const Envelope& e) {
    if (e.empty) return;
    cover(e.minx, e.miny);
    cover(e.maxx, e.maxy);
  }
};

/// `parts` as an ISO WKB MultiPolygon, little-endian, each ring closed by
/// repeating its first point: the bytes OGR's exportToWkb writes for the
/// OGRMultiPolygon that detail::toOgr makes of them (a ring without points is
/// written without points; toOgr's would hold one point it never sets).
void appendMultiPolygonWkb(std::string& out, const std::vector<Polygon>& parts);
/// The envelope of a little-endian WKB MultiPolygon (as above), as OGR's
/// getEnvelope gives it; empty when it has no point. Throws std::logic_error
/// on anything else.
Envelope multiPolygonWkbEnvelope(const std::string& wkb);

/// The GeoPackage geometry blob of a MultiPolygon: the standard header
/// (version 0, little-endian, an XY envelope unless empty, `srsId`) then the
/// WKB, as GDAL's GeoPackage driver writes it.
void appendGpkgGeometry(std::string& out, const std::string& wkb, const Envelope& envelope, std::int32_t srsId);

/// One row as it is bound: the geometry blob and a value per field (a NaN
/// real is NULL).
struct GpkgRow {
  std::string geometry;
  Envelope envelope;
  std::vector<Value> values;
};

/// Field values of `row` converted as OGR converts them into fields of
/// `columns`' types (OGRFeature::SetField, then read back the way GDAL binds
/// the field), so that the stored values equal GDAL's.
void convertToColumns(const std::vector<Column>& columns, std::vector<Value>& row);

/// What insertGpkgFeatures did: the R-tree of the geometry column, when GDAL
/// made one, and the SQL of its insert trigger, taken away (for fillRtree to
/// fill the tree and put the trigger back).
struct GpkgInsert {
  std::string rtreeName, rtreeInsertTrigger;
};

/// Appends rows to the feature table `table` (geometry column `geometryColumn`,
/// fields `columns` in order) of the GeoPackage at `path`, which GDAL made and
/// closed, empty. `next` fills the next row and returns false when there is
/// none. In one transaction: the table's feature-count triggers are taken away
/// and put back, gpkg_ogr_contents gets the count, gpkg_contents the extent of
/// the non-empty geometries and the time of the change (both left as they are
/// when there is no row, as GDAL leaves them); the R-tree's insert
/// trigger (rtree_<table>_<column>_insert), if any, is taken away and
/// returned. `inserted(fid, row)` is called after each row. Throws Error(IO)
/// naming the file.
GpkgInsert insertGpkgFeatures(const std::string& path, const std::string& table, const std::string& geometryColumn,
                              const std::vector<Column>& columns, const std::function<bool(GpkgRow&)>& next,
                              const std::function<void(std::int64_t fid, const GpkgRow&)>& inserted);

/// The srs_id GDAL gave the geometry column of `table` in the GeoPackage at
/// `path` (gpkg_geometry_columns). Throws Error(IO) naming the file.
std::int32_t gpkgSrsId(const std::string& path, const std::string& table);

}  // namespace parcelscope::io::detail
