#pragma once
// Writing tables, vector layers and run records. Every writer writes to the path
// it is given; atomicity comes from OutputDirectory (write into its staging
// folder, then commit).
#include <cstdint>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"
#include "parcelscope/core/Json.h"
#include "parcelscope/core/Table.h"
#include "parcelscope/io/LocalFrame.h"
#include "parcelscope/io/ParcelReader.h"

namespace parcelscope::io {

/// RFC 4180 CSV with a header row; reals with up to 10 significant digits.
/// Throws Error(IO) on failure.
void writeCsv(const std::string& path, const Table& table);
/// The same, rows made in parallel batches as they are written (a few
/// thousand rows held at a time).
void writeCsv(const std::string& path, const RowSource& rows);

/// Writes `json.dump()` followed by a newline. Throws Error(IO) on failure.
void writeJson(const std::string& path, const Json& json);

/// Reads a JSON file (GDAL's JSON parser). Throws Error(Input) naming the file
/// when it is missing or not valid JSON.
Json readJson(const std::string& path);

/// Writes a GeoPackage (or GeoJSON, for a path ending in .geojson or .json)
/// with one polygon layer. Feature i has geometry
/// `geometries[i]` (one or more polygons, written as a MultiPolygon) and the
/// attributes of `attributes.rows[i]`. Coordinates are mapped back from local
/// metres with `frame` and tagged with `crs` (OGC:CRS84 when the CRS was assumed).
/// A GeoPackage layer gets an R-tree spatial index unless `spatialIndex` is
/// false: GIS tools draw large layers faster with it. GDAL makes the empty
/// index, its triggers and its extension entry; the tree is packed from all
/// features' boxes once they are written (about 1 microsecond per feature,
/// against 10 for GDAL 3.6 inserting them one by one). GDAL makes the
/// GeoPackage, its table and metadata; the rows go in through SQLite, with the
/// bytes and values GDAL's CreateFeature would store (io/src/GpkgFeatures.h).
///
/// Validity is that of the file, in the CRS written: a polygon valid in local
/// metres can be invalid once mapped back (edges straight in metres are not
/// straight in degrees, by about 0.2 mm over 100 m, and doubles in degrees
/// merge points closer than about 1e-9 m). Each geometry is checked there
/// (GEOS) and, when invalid, repaired there (make-valid, structure method);
/// the count is returned. A geometry that collapses entirely is written empty
/// and counted apart.
/// Throws Error(IO) on failure.
struct LayerWrite {
  std::int64_t features = 0;
  std::int64_t repaired = 0;  ///< invalid once mapped back, repaired in the CRS written
  std::int64_t emptied = 0;   ///< of those, collapsed entirely (written as an empty geometry)
};
LayerWrite writePolygonLayer(const std::string& path, const std::string& layerName,
                             const std::vector<std::vector<Polygon>>& geometries, const Table& attributes,
                             const LocalFrame& frame, const CrsInfo& crs, bool spatialIndex = true);
/// The same with attributes made row by row as features are written.
LayerWrite writePolygonLayer(const std::string& path, const std::string& layerName,
                             const std::vector<std::vector<Polygon>>& geometries, const RowSource& attributes,
                             const LocalFrame& frame, const CrsInfo& crs, bool spatialIndex = true);
/// Feature i's polygons into `parts`, which comes empty; called from other
/// threads, several at once (features in any order).
using PolygonSource = std::function<void(std::size_t i, std::vector<Polygon>& parts)>;
/// A feature's geometry as writePolygonLayer writes it: mapped back with the
/// frame, checked and repaired in the CRS written, as a MultiPolygon in ISO
/// WKB (little-endian).
struct FileGeometry {
  std::string wkb;
  bool repaired = false;  ///< invalid once mapped back, repaired
  bool emptied = false;   ///< of those, collapsed entirely (an empty MultiPolygon)
};
/// `parts` (local metres) as writePolygonLayer writes them; made wherever the
/// parts are (a shard of the run), then handed to the writer.
FileGeometry fileGeometry(std::vector<Polygon> parts, const LocalFrame& frame);
/// Feature i's geometry made already by fileGeometry with the layer's frame,
/// or null: the writer makes it from the PolygonSource. Called from other
/// threads, several at once.
using ReadyGeometry = std::function<const FileGeometry*(std::size_t i)>;
/// The same with geometries too made feature by feature (attributes.rows
/// features), or taken from `ready` where it has them.
LayerWrite writePolygonLayer(const std::string& path, const std::string& layerName, const PolygonSource& geometries,
                             const RowSource& attributes, const LocalFrame& frame, const CrsInfo& crs,
                             bool spatialIndex = true, const ReadyGeometry& ready = {});

/// Writes a GeoPackage with a point layer `nodes` (one point per row of
/// `nodeAttributes`) and a line layer `edges` (one line string per row of
/// `edgeAttributes`), mapped back from local metres with `frame` and tagged
/// with `crs`. A NaN real is written as NULL. Throws Error(IO) on failure.
void writeNetworkLayers(const std::string& path, const std::vector<Point>& nodes, const Table& nodeAttributes,
                        const std::vector<std::vector<Point>>& edges, const Table& edgeAttributes,
                        const LocalFrame& frame, const CrsInfo& crs);

/// The GDAL version string, for run records.
std::string gdalVersion();

}  // namespace parcelscope::io
