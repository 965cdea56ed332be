#pragma once
// Opening vector inputs and choosing their local frame: what every reader of
// io/ (parcels, street centre lines) shares. Internal to io/.
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "parcelscope/io/LocalFrame.h"
#include "parcelscope/io/ParcelReader.h"

namespace parcelscope::io::detail {

/// GDAL's last message on one line; empty when GDAL left none.
std::string gdalMessage();
/// gdalMessage(), or "unknown GDAL error".
std::string lastGdalMessage();

/// Opens `path` as a vector dataset, read-only. What GDAL cannot read is named
/// (missing, empty, a folder, a device; a named pipe is refused before GDAL
/// opens it). Throws Error(Input).
/// A folder of vector files (by extension, sorted by name; a .gdb folder is one
/// dataset) or a list file (.txt, .lst: one path per line, relative to the list,
/// # comments) is read as one layer: the union of each file's `layer` (empty:
/// its first), whose features are numbered in turn. Their CRSs must agree.
GDALDatasetUniquePtr openVector(const std::string& path, const std::string& layer = {});
/// The files of such an input, in order; empty when `path` is one dataset.
std::vector<std::string> inputFiles(const std::string& path);
/// Every file `path` makes a reader open besides itself: the files of a folder
/// or list (inputFiles), the source datasets of an OGR VRT (SrcDataSource,
/// relative to the VRT where it says so), and theirs in turn. What cannot be
/// listed is left out (the reader names it). For the output folder's checks.
std::vector<std::string> filesReadWith(const std::string& path);

/// The CRS of `layer`: `crsOverride` (the --crs flag) when given, parsed into
/// `storage` (and `overridden` set), else the one the layer declares (null:
/// none). Throws Error(Usage) naming `path` when GDAL does not know `crsOverride`.
const OGRSpatialReference* layerCrs(const std::string& path, OGRLayer& layer, const std::string& crsOverride,
                                    OGRSpatialReference& storage, bool& overridden);

/// Whether every coordinate stored in `g` is finite.
bool coordinatesFinite(const OGRGeometry& g);

/// Extent of the features read and their centres (for the frame's origin).
struct Envelope {
  double minX = std::numeric_limits<double>::max(), minY = minX;
  double maxX = std::numeric_limits<double>::lowest(), maxY = maxX;
  std::vector<double> centresX, centresY;
  void merge(const OGREnvelope& e) {
    minX = std::min(minX, e.MinX);
    minY = std::min(minY, e.MinY);
    maxX = std::max(maxX, e.MaxX);
    maxY = std::max(maxY, e.MaxY);
    centresX.push_back(0.5 * (e.MinX + e.MaxX));
    centresY.push_back(0.5 * (e.MinY + e.MaxY));
  }
  // `unit`: degrees per coordinate unit of a geographic CRS.
  bool looksLikeDegrees(double unit = 1.0) const {
    return minX * unit >= -180.0 && maxX * unit <= 180.0 && minY * unit >= -90.0 && maxY * unit <= 90.0;
  }
  // The median of the features' centres: one stray feature far away (a record
  // at 0, 0, say) does not move the local frame off the data.
  Point centre() {
    auto median = [](std::vector<double>& v) {
      std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
      return v[v.size() / 2];
    };
    return {median(centresX), median(centresY)};
  }
};

/// The local frame of a layer whose CRS is `srs` (null: none declared) and
/// extent `env`; fills `crs`. Throws Error(Input) when the CRS cannot be used.
LocalFrame chooseFrame(const std::string& path, const OGRSpatialReference* srs, Envelope& env, CrsInfo& crs);

}  // namespace parcelscope::io::detail
