#include "VectorInput.h"

#include <cpl_error.h>
#include <ogr_spatialref.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "OgrConvert.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::io::detail {

// GDAL's last message on one line (some span several, with a caret marker);
// empty when GDAL left none.
std::string gdalMessage() {
  std::string m, raw = CPLGetLastErrorMsg();
  for (char c : raw) {
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
    if (c == ' ' && (m.empty() || m.back() == ' ')) continue;
    m += c;
  }
  while (!m.empty() && m.back() == ' ') m.pop_back();
  return m;
}

std::string lastGdalMessage() {
  const std::string m = gdalMessage();
  return m.empty() ? "unknown GDAL error" : m;
}

// What a path that is neither a regular file nor a folder is, for messages.
static std::string describeFileType(std::filesystem::file_type type) {
  using std::filesystem::file_type;
  switch (type) {
    case file_type::fifo:
      return "a named pipe (FIFO)";
    case file_type::character:
      return "a character device";
    case file_type::block:
      return "a block device";
    case file_type::socket:
      return "a socket";
    default:
      return "not a regular file";
  }
}

// Opens `path` as a vector dataset. The path is looked at first (stat), so that
// what GDAL cannot read is named (an empty file, a folder, a device) and a named
// pipe without a writer is refused instead of blocking GDAL's open.
static GDALDatasetUniquePtr openOne(const std::string& path) {
  namespace fs = std::filesystem;
  detail::ensureGdalRegistered();
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) throw inputError(path + ": no such file");
  if (ec) throw inputError(path + ": cannot be read (" + ec.message() + ")");
  const bool folder = status.type() == fs::file_type::directory;
  if (!folder && status.type() != fs::file_type::regular) {
    throw inputError(path + ": is " + describeFileType(status.type()) +
                     ", not a regular file or folder, so it is not read");
  }
  if (!folder && fs::file_size(path, ec) == 0 && !ec) throw inputError(path + ": is empty (0 bytes)");
  // A file GDAL may not open is told as such, not as a format GDAL does not read.
  if (!folder && ::access(path.c_str(), R_OK) != 0) {
    throw inputError(path + ": cannot be read (" + std::strerror(errno) + ")");
  }
  QuietErrors quiet;
  CPLErrorReset();
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  if (!ds) {
    const std::string why = gdalMessage();
    if (folder) {
      throw inputError(path + ": is a folder, not a file, and GDAL reads no vector dataset from it" +
                       (why.empty() ? "" : " (" + why + ")"));
    }
    throw inputError(path + ": is not a file format GDAL reads (not a vector format GDAL can read" +
                     (why.empty() ? "; no driver recognises its contents" : ": " + why) + ")");
  }
  if (ds->GetLayerCount() == 0) throw inputError(path + ": holds no vector layer");
  return ds;
}

namespace {

// The extension of `p`, in lower case (".gpkg").
std::string lowerExtension(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// Extensions of the vector files a folder input is made of (shapefiles by their .shp).
bool isVectorFile(const std::filesystem::path& p) {
  const std::string ext = lowerExtension(p);
  for (const char* known :
       {".gpkg", ".geojson", ".json", ".topojson", ".shp", ".fgb", ".gml", ".kml", ".sqlite", ".tab", ".mif"}) {
    if (ext == known) return true;
  }
  return false;
}

std::string xml(const std::string& text) {
  char* escaped = CPLEscapeString(text.c_str(), -1, CPLES_XML);
  std::string out = escaped;
  CPLFree(escaped);
  return out;
}

}  // namespace

std::vector<std::string> inputFiles(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<std::string> files;
  if (fs::is_directory(path, ec)) {
    std::string name = fs::path(path).filename().string();
    if (name.empty()) name = fs::path(path).parent_path().filename().string();
    if (name.size() > 4 && name.substr(name.size() - 4) == ".gdb") return {};  // a File Geodatabase is one dataset
    fs::directory_iterator entries(path, ec), end;
    for (; !ec && entries != end; entries.increment(ec)) {
      std::error_code typeError;
      if (entries->is_regular_file(typeError) && isVectorFile(entries->path())) {
        files.push_back(entries->path().string());
      }
    }
    if (ec) throw inputError(path + ": the folder cannot be listed (" + ec.message() + ")");
    std::sort(files.begin(), files.end());
    return files;
  }
  const std::string ext = lowerExtension(path);
  if (!fs::is_regular_file(path, ec) || (ext != ".txt" && ext != ".lst")) return {};
  std::ifstream list(path);
  if (!list) throw inputError(path + ": cannot be read (" + std::strerror(errno) + ")");
  std::string line;
  for (int number = 1; std::getline(list, line); ++number) {
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte order mark
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    std::size_t start = 0;
    while (start < line.size() && std::isspace(static_cast<unsigned char>(line[start]))) ++start;
    line = line.substr(start);
    if (line.empty() || line[0] == '#') continue;
    fs::path file(line);
    if (file.is_relative()) file = fs::path(path).parent_path() / file;
    const std::string where = path + ": line " + std::to_string(number) + ": " + file.string();
    if (!fs::exists(file, ec)) throw inputError(where + ": no such file");
    // A list names files: a folder or another list in it is not read as one.
    const std::string inner = lowerExtension(file);
    if (fs::is_directory(file, ec) && inner != ".gdb") {
      throw inputError(where +
                       ": is a folder; a list names files (give the folder itself as INPUT, or list its files)");
    }
    if (inner == ".txt" || inner == ".lst") {
      throw inputError(where + ": is a list; lists do not nest (list its files here)");
    }
    files.push_back(file.lexically_normal().string());
  }
  if (files.empty()) throw inputError(path + ": lists no file (one path per line; # starts a comment)");
  return files;
}

std::vector<std::string> filesReadWith(const std::string& path) {
  namespace fs = std::filesystem;
  std::vector<std::string> out;
  std::vector<std::pair<std::string, int>> pending = {{path, 0}};
  while (!pending.empty()) {
    const auto [p, depth] = pending.back();
    pending.pop_back();
    if (depth > 4) continue;  // VRTs naming VRTs or lists: a few levels, never a cycle
    std::vector<std::string> named;
    try {
      named = inputFiles(p);
    } catch (const Error&) {
    }
    std::error_code ec;
    if (named.empty() && lowerExtension(p) == ".vrt" && fs::is_regular_file(p, ec)) {
      QuietErrors quiet;
      if (CPLXMLNode* root = CPLParseXMLFile(p.c_str())) {
        std::vector<const CPLXMLNode*> nodes = {root};
        while (!nodes.empty()) {
          const CPLXMLNode* n = nodes.back();
          nodes.pop_back();
          for (; n; n = n->psNext) {
            if (n->eType != CXT_Element) continue;
            if (EQUAL(n->pszValue, "SrcDataSource")) {
              const char* value = CPLGetXMLValue(n, nullptr, "");
              const char* relative = CPLGetXMLValue(n, "relativeToVRT", "0");
              if (*value) {
                // Relative: to the VRT when it says so, else to the working
                // folder; both are kept, whichever GDAL takes.
                const fs::path source(value);
                if (source.is_relative()) named.push_back((fs::path(p).parent_path() / source).lexically_normal());
                if (!source.is_relative() || !EQUAL(relative, "1")) named.push_back(source.lexically_normal());
              }
            } else if (n->psChild) {
              nodes.push_back(n->psChild);
            }
          }
        }
        CPLDestroyXMLNode(root);
      }
    }
    for (const std::string& f : named) {
      out.push_back(f);
      pending.emplace_back(f, depth + 1);
    }
  }
  return out;
}

// Opens `path` as a vector dataset; a folder of vector files or a list of
// them (inputFiles) is opened as one layer, the union of each file's layer
// `layer` (or first layer), through an in-memory OGR VRT.
GDALDatasetUniquePtr openVector(const std::string& path, const std::string& layer) {
  detail::ensureGdalRegistered();
  const std::vector<std::string> files = inputFiles(path);
  if (files.empty()) return openOne(path);
  std::string unionName, sources, geometryName;
  std::unique_ptr<OGRSpatialReference> firstCrs;
  for (std::size_t k = 0; k < files.size(); ++k) {
    const GDALDatasetUniquePtr ds = openOne(files[k]);
    OGRLayer* l = layer.empty() ? ds->GetLayer(0) : ds->GetLayerByName(layer.c_str());
    if (!l) throw inputError(files[k] + ": no layer named '" + layer + "' (in " + path + ")");
    const OGRSpatialReference* crs = l->GetSpatialRef();
    if (k == 0) {
      unionName = layer.empty() ? l->GetName() : layer;
      geometryName = l->GetGeometryColumn();
      if (crs) firstCrs.reset(crs->Clone());
    } else if (geometryName != l->GetGeometryColumn()) {
      // A union layer matches geometries by their column's name: others would read as null.
      throw inputError(files[k] + ": its geometry column ('" + std::string(l->GetGeometryColumn()) +
                       "') is not that of " + files.front() + " ('" + geometryName + "'); the files of " + path +
                       " are read as one layer: give them one format (ogr2ogr)");
    } else if ((crs == nullptr) != (firstCrs == nullptr) || (crs && !crs->IsSame(firstCrs.get()))) {
      auto name = [](const OGRSpatialReference* c) { return std::string(c && c->GetName() ? c->GetName() : "none"); };
      throw inputError(files[k] + ": its CRS (" + name(crs) + ") is not that of " + files.front() + " (" +
                       name(firstCrs.get()) + "); the files of " + path +
                       " are read as one layer and must share one CRS (reproject with ogr2ogr -t_srs)");
    }
    sources += "<OGRVRTLayer name=\"part" + std::to_string(k) + "\"><SrcDataSource>" + xml(files[k]) +
               "</SrcDataSource><SrcLayer>" + xml(l->GetName()) + "</SrcLayer></OGRVRTLayer>";
  }
  const std::string vrt = "<OGRVRTDataSource><OGRVRTUnionLayer name=\"" + xml(unionName) + "\">" + sources +
                          "</OGRVRTUnionLayer></OGRVRTDataSource>";
  QuietErrors quiet;
  CPLErrorReset();
  GDALDatasetUniquePtr ds(GDALDataset::Open(vrt.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  if (!ds || ds->GetLayerCount() == 0) {
    throw inputError(path + ": its " + std::to_string(files.size()) + " files cannot be read as one layer (" +
                     lastGdalMessage() + ")");
  }
  return ds;
}

// Whether every coordinate stored in `g` (x, y, and z and m where present) is
// finite. OGR envelopes do not tell: their min and max pass over NaN.
bool coordinatesFinite(const OGRGeometry& g) {
  struct Visitor : OGRDefaultConstGeometryVisitor {
    bool finite = true;
    using OGRDefaultConstGeometryVisitor::visit;
    // A point whose x and y are NaN counts as an empty point, so vertices are
    // read from their curves, and only a standalone point may be empty.
    void visit(const OGRPoint* p) override {
      if (!finite || p->IsEmpty()) return;
      finite = std::isfinite(p->getX()) && std::isfinite(p->getY()) && (!p->Is3D() || std::isfinite(p->getZ())) &&
               (!p->IsMeasured() || std::isfinite(p->getM()));
    }
    void vertices(const OGRSimpleCurve& c) {
      for (int i = 0, n = c.getNumPoints(); i < n && finite; ++i) {
        finite = std::isfinite(c.getX(i)) && std::isfinite(c.getY(i)) && (!c.Is3D() || std::isfinite(c.getZ(i))) &&
                 (!c.IsMeasured() || std::isfinite(c.getM(i)));
      }
    }
    void visit(const OGRLineString* c) override { vertices(*c); }
    void visit(const OGRLinearRing* c) override { vertices(*c); }
    void visit(const OGRCircularString* c) override { vertices(*c); }
  } visitor;
  g.accept(&visitor);
  return visitor.finite;
}

static std::string fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

// Lon/lat a local frame cannot hold: parcels within half a degree of a pole
// (longitudes wrap there, and a parcel written back came out empty) or spread
// over more than 180 degrees of longitude (across the antimeridian, a block
// was written round the globe; or continents apart, with areas 46 % off).
void requireOneLocalArea(const std::string& path, const Envelope& env, double degreesPerUnit) {
  const double west = env.minX * degreesPerUnit, east = env.maxX * degreesPerUnit;
  const double south = env.minY * degreesPerUnit, north = env.maxY * degreesPerUnit;
  const std::string reproject = "; reproject the layer to a projected CRS of its area first (ogr2ogr -t_srs EPSG:N)";
  if (north > 89.5 || south < -89.5) {
    throw inputError(path + ": parcels reach latitude " + fmt(north > 89.5 ? north : south) +
                     ", within half a degree of a pole, where lon/lat cannot be measured or written" + reproject);
  }
  if (east - west > 180) {
    throw inputError(path + ": parcels span longitudes " + fmt(west) + " to " + fmt(east) +
                     ", more than 180 degrees (across the antimeridian, or continents apart)" + reproject);
  }
}

// Chooses the local frame and records the CRS, or throws when the CRS cannot be used.
LocalFrame chooseFrame(const std::string& path, const OGRSpatialReference* srs, Envelope& env, CrsInfo& crs) {
  const Point c = env.centre();
  const double cx = c.x, cy = c.y;
  const std::string hint = "; give the real CRS with --crs EPSG:N";
  if (!srs) {
    if (!env.looksLikeDegrees()) {
      throw inputError(path + ": the layer declares no CRS and its coordinates (x " + fmt(env.minX) + " to " +
                       fmt(env.maxX) + ", y " + fmt(env.minY) + " to " + fmt(env.maxY) + ") are not degrees" + hint);
    }
    requireOneLocalArea(path, env, 1.0);
    crs.assumedLonLat = true;
    crs.name = "assumed OGC:CRS84 (no CRS declared)";
    return LocalFrame::geographic(cx, cy);
  }
  const char* name = srs->GetName();
  crs.name = name ? name : "unnamed CRS";
  if (const char* code = srs->GetAuthorityCode(nullptr)) {
    const char* auth = srs->GetAuthorityName(nullptr);
    crs.name += std::string(" (") + (auth ? auth : "") + ":" + code + ")";
  }
  if (srs->IsGeographic()) {
    const double degreesPerUnit = srs->GetAngularUnits() * 180.0 / M_PI;  // 0.9 for grads
    if (!(degreesPerUnit > 0)) throw inputError(path + ": CRS " + crs.name + " has no usable angular unit");
    if (!env.looksLikeDegrees(degreesPerUnit)) {
      throw inputError(path + ": the layer claims lon/lat (" + crs.name + ") but its coordinates (x " + fmt(env.minX) +
                       " to " + fmt(env.maxX) + ", y " + fmt(env.minY) + " to " + fmt(env.maxY) +
                       ") cannot be degrees" + hint);
    }
    requireOneLocalArea(path, env, degreesPerUnit);
    OGRErr err = OGRERR_NONE;
    const double a = srs->GetSemiMajor(&err);
    const double invf = srs->GetInvFlattening(&err);
    return LocalFrame::geographic(cx * degreesPerUnit, cy * degreesPerUnit, a, invf > 0 ? 1.0 / invf : 0.0,
                                  degreesPerUnit);
  }
  if (srs->IsProjected()) {
    const double unit = srs->GetLinearUnits();
    if (!(unit > 0)) throw inputError(path + ": CRS " + crs.name + " has no usable linear unit");
    return LocalFrame::projected(unit, cx, cy);
  }
  throw inputError(path + ": CRS " + crs.name + " is neither geographic nor projected, so parcels cannot be measured" +
                   hint);
}

const OGRSpatialReference* layerCrs(const std::string& path, OGRLayer& layer, const std::string& crsOverride,
                                    OGRSpatialReference& storage, bool& overridden) {
  if (crsOverride.empty()) return layer.GetSpatialRef();
  CPLErrorReset();
  if (storage.SetFromUserInput(crsOverride.c_str()) != OGRERR_NONE) {
    throw usageError(path + ": --crs " + crsOverride + " is not a CRS GDAL knows (" + lastGdalMessage() + ")");
  }
  storage.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  overridden = true;
  return &storage;
}

}  // namespace parcelscope::io::detail
