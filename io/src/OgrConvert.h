#pragma once
// Conversions between OGR geometries and ParcelScope's plain polygons.
// Internal to io/: no other module sees OGR types.
#include <ogr_core.h>
#include <ogr_geometry.h>

#include <memory>
#include <vector>

#include "parcelscope/core/Geometry.h"
#include "parcelscope/core/Table.h"

namespace parcelscope::io::detail {

/// The polygon as an OGRPolygon with closed rings.
std::unique_ptr<OGRPolygon> toOgr(const Polygon& polygon);
/// A multipolygon of all parts.
std::unique_ptr<OGRMultiPolygon> toOgr(const std::vector<Polygon>& parts);
/// Reads an OGRPolygon's rings (no normalisation).
Polygon fromOgr(const OGRPolygon& polygon);
/// Appends every polygon found in `geometry` (polygons, multipolygons,
/// collections, curved geometries linearised) to `out`. Returns false if the
/// geometry held something other than polygons (points, lines).
bool collectPolygons(const OGRGeometry& geometry, std::vector<std::unique_ptr<OGRPolygon>>& out);

/// The OGR field type a table column is written as.
OGRFieldType ogrFieldType(Column::Type type);

/// Silences GDAL's error printing for its lifetime and restores it after;
/// the last message stays available through CPLGetLastErrorMsg().
class QuietErrors {
public:
  QuietErrors();
  ~QuietErrors();
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;
};

/// Registers GDAL's drivers once.
void ensureGdalRegistered();

}  // namespace parcelscope::io::detail
