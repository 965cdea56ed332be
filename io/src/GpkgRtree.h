#pragma once
// A GeoPackage layer's R-tree spatial index (SQLite's rtree module, extension
// gpkg_rtree_index) built in bulk. GDAL 3.6 fills it row by row through
// SQLite's R-tree insertion when a written layer is closed, about 10 us per
// feature; packing the tree once from all boxes (sort-tile-recursive) and
// writing its shadow tables takes a small fraction of that.
#include <cstdint>
#include <string>
#include <vector>

namespace parcelscope::io::detail {

/// One feature's envelope, in the layer's CRS.
struct RtreeEntry {
  std::int64_t id = 0;  ///< the feature's fid
  double minx = 0, maxx = 0, miny = 0, maxy = 0;
};

/// Replaces the content of the R-tree `rtreeName` of the GeoPackage at `path`
/// (a virtual table `USING rtree(id, minx, maxx, miny, maxy)` SQLite created,
/// empty) by a tree packed from `entries`, then runs `afterSql` (for example
/// the insert trigger taken away while the features were written), all in one
/// transaction. Boxes are rounded outward to single precision, as SQLite's
/// rtree stores them. Throws Error(IO) naming the file.
void fillRtree(const std::string& path, const std::string& rtreeName, std::vector<RtreeEntry> entries,
               const std::string& afterSql);

/// `text` quoted for SQL with `quote` (' for a string, " for a name), the
/// quote character doubled inside.
std::string sqlQuoted(const std::string& text, char quote);

}  // namespace parcelscope::io::detail
