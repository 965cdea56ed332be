#include "parcelscope/io/ParcelReader.h"

#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include "OgrConvert.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"

namespace parcelscope::io {

namespace {

using detail::QuietErrors;

// Parts smaller than this (m², a 3 cm square) are make-valid leftovers or
// zero-area slivers, not parcels.
constexpr double kMinPartArea = 1e-3;

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
std::string describeFileType(std::filesystem::file_type type) {
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
GDALDatasetUniquePtr openVector(const std::string& path) {
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

struct Feature {
  std::int64_t fid = -1;
  std::unique_ptr<OGRGeometry> geometry;
  int stackCount = 1;
  std::vector<double> values;  // ReadOptions::numericFields
  Key key = 0;                 // Parcel::featureKey
};

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

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
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

// Projects every vertex of `g` to the local frame, in place.
void projectInPlace(OGRGeometry& g, const LocalFrame& frame) {
  const auto type = wkbFlatten(g.getGeometryType());
  if (type == wkbPolygon) {
    for (OGRLinearRing* ring : *g.toPolygon()) {
      for (int i = 0, n = ring->getNumPoints(); i < n; ++i) {
        const Point p = frame.toLocal(ring->getX(i), ring->getY(i));
        ring->setPoint(i, p.x, p.y);
      }
    }
  } else if (OGR_GT_IsSubClassOf(type, wkbGeometryCollection)) {
    for (OGRGeometry* part : *g.toGeometryCollection()) projectInPlace(*part, frame);
  }
}

// One feature after projection, repair and splitting.
struct Cleaned {
  std::vector<Parcel> parcels;
  bool nonPolygonal = false, repaired = false, repairFailed = false;
  bool mixed = false;  // points or lines dropped beside polygons
  int inputParts = 0;  // polygon parts of the input geometry
  int degenerate = 0;
};

Cleaned cleanFeature(const Feature& f, const LocalFrame& frame) {
  QuietErrors quiet;  // error handlers are per thread
  Cleaned c;
  std::vector<std::unique_ptr<OGRPolygon>> polygons;
  const bool onlyPolygons = detail::collectPolygons(*f.geometry, polygons);
  if (polygons.empty()) {
    c.nonPolygonal = true;
    return c;
  }
  c.mixed = !onlyPolygons;
  c.inputParts = static_cast<int>(polygons.size());
  for (auto& p : polygons) projectInPlace(*p, frame);
  // Fast path: a single ring that is clearly simple needs no GEOS check.
  if (polygons.size() == 1 && polygons[0]->getNumInteriorRings() == 0) {
    Parcel parcel;
    parcel.shape = detail::fromOgr(*polygons[0]);
    if (normalise(parcel.shape) && isClearlySimple(parcel.shape.outer)) {
      if (area(parcel.shape) < kMinPartArea) {
        ++c.degenerate;
        return c;
      }
      parcel.sourceFid = f.fid;
      parcel.stackCount = f.stackCount;
      c.parcels.push_back(std::move(parcel));
      return c;
    }
  }
  // Validity is judged on the whole feature so that wrongly nested parts of a
  // multipolygon (a hole stored as a part) are repaired into holes.
  std::unique_ptr<OGRGeometry> whole;
  if (polygons.size() == 1) {
    whole = std::move(polygons.front());
  } else {
    auto multi = std::make_unique<OGRMultiPolygon>();
    for (auto& p : polygons) multi->addGeometryDirectly(p.release());
    whole = std::move(multi);
  }
  polygons.clear();
  if (!whole->IsValid()) {
    const char* const makeValidOptions[] = {"METHOD=STRUCTURE", nullptr};
    std::unique_ptr<OGRGeometry> fixed(whole->MakeValid(makeValidOptions));
    if (!fixed || fixed->IsEmpty()) {
      c.repairFailed = true;
      return c;
    }
    whole = std::move(fixed);
    c.repaired = true;
  }
  detail::collectPolygons(*whole, polygons);
  int part = 0;
  for (auto& p : polygons) {
    Parcel parcel;
    parcel.shape = detail::fromOgr(*p);
    if (!normalise(parcel.shape) || area(parcel.shape) < kMinPartArea) {
      ++c.degenerate;
      continue;
    }
    parcel.sourceFid = f.fid;
    parcel.part = part++;
    parcel.stackCount = f.stackCount;
    parcel.repaired = c.repaired;
    c.parcels.push_back(std::move(parcel));
  }
  return c;
}

}  // namespace

std::vector<std::string> layerNames(const std::string& path) {
  const GDALDatasetUniquePtr ds = openVector(path);
  std::vector<std::string> names;
  for (int i = 0; i < ds->GetLayerCount(); ++i) names.emplace_back(ds->GetLayer(i)->GetName());
  return names;
}

ParcelLayer readParcels(const ReadOptions& options, const ProgressFn& progress) {
  const std::string& path = options.path;
  Timings timings;
  timings.start("read");
  auto ds = openVector(path);
  QuietErrors quiet;

  OGRLayer* layer = nullptr;
  if (options.layer.empty()) {
    layer = ds->GetLayer(0);
  } else {
    layer = ds->GetLayerByName(options.layer.c_str());
    if (!layer) {
      std::string names;
      for (int i = 0; i < ds->GetLayerCount(); ++i) {
        names += (i ? ", " : "") + std::string(ds->GetLayer(i)->GetName());
      }
      throw inputError(path + ": no layer named '" + options.layer + "' (layers: " + names + ")");
    }
  }

  ParcelLayer result;
  result.path = path;
  result.layerName = layer->GetName();
  CleaningReport& report = result.report;

  if (!options.where.empty()) {
    CPLErrorReset();
    if (layer->SetAttributeFilter(options.where.c_str()) != OGRERR_NONE) {
      throw inputError(path + ": --where \"" + options.where + "\" is not a valid filter on layer " + result.layerName +
                       " (" + lastGdalMessage() + ")");
    }
  }

  // CRS: --crs replaces whatever the file declares.
  OGRSpatialReference overrideSrs;
  const OGRSpatialReference* srs = layer->GetSpatialRef();
  if (!options.crsOverride.empty()) {
    CPLErrorReset();
    if (overrideSrs.SetFromUserInput(options.crsOverride.c_str()) != OGRERR_NONE) {
      throw usageError(path + ": --crs " + options.crsOverride + " is not a CRS GDAL knows (" + lastGdalMessage() +
                       ")");
    }
    overrideSrs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    srs = &overrideSrs;
    result.crs.overridden = true;
  }

  std::vector<int> fieldIndex;
  for (const auto& name : options.numericFields) {
    fieldIndex.push_back(layer->GetLayerDefn()->GetFieldIndex(name.c_str()));
  }
  const int keyIndex = options.keyField.empty() ? -1 : layer->GetLayerDefn()->GetFieldIndex(options.keyField.c_str());
  if (!options.keyField.empty() && keyIndex < 0 && !options.keyFieldOptional) {
    throw inputError(path + ": layer " + result.layerName + " has no field '" + options.keyField + "' (--key-field)");
  }
  // A feature's key: its key field's value, else its geometry (see Parcel::featureKey).
  auto featureKey = [&](const OGRFeature& feature, const std::string& geometryWkb) -> Key {
    if (keyIndex >= 0 && feature.IsFieldSetAndNotNull(keyIndex)) {
      const char* value = feature.GetFieldAsString(keyIndex);
      if (const auto parsed = parseKey(value)) return *parsed;
      return hashBytes(value);
    }
    if (keyIndex >= 0 && !options.keyFieldOptional) {
      throw inputError(path + ": feature " + std::to_string(feature.GetFID()) + " has no value in key field '" +
                       options.keyField + "'");
    }
    return hashBytes(geometryWkb);
  };

  // Pass 1: read features, collapse exact duplicate geometries, find the extent.
  const GIntBig total = layer->GetFeatureCount(FALSE);
  std::vector<Feature> features;
  // Features by the hash of their WKB; the bytes are compared again (exported
  // anew) only when hashes meet, so no copy of every geometry is kept.
  std::unordered_multimap<std::size_t, std::size_t> byHash;
  std::string wkb, earlier;
  auto exportWkb = [](const OGRGeometry& g, std::string& out) {
    out.resize(static_cast<std::size_t>(g.WkbSize()));
    g.exportToWkb(wkbNDR, reinterpret_cast<unsigned char*>(out.data()), wkbVariantIso);
  };
  if (total > 0) byHash.reserve(static_cast<std::size_t>(total));
  Envelope env;
  // A read error stops the loop as if the layer had ended (SQLite's "database
  // disk image is malformed" after a few features of a corrupt GeoPackage), so
  // GDAL's error state is checked for every feature and after the last one.
  auto throwIfReadFailed = [&] {
    if (CPLGetLastErrorType() != CE_Failure && CPLGetLastErrorType() != CE_Fatal) return;
    throw inputError(path + ": reading layer " + result.layerName +
                     (options.where.empty() ? "" : " with --where \"" + options.where + "\"") + " failed after " +
                     std::to_string(report.features) + " features (" + lastGdalMessage() + ")");
  };
  CPLErrorReset();
  layer->ResetReading();
  for (auto& feature : *layer) {
    throwIfReadFailed();
    ++report.features;
    if (report.features % 2000 == 0 && total > 0) {
      reportProgress(progress, 0.6 * static_cast<double>(report.features) / static_cast<double>(total), "reading");
    }
    OGRGeometry* g = feature->GetGeometryRef();
    if (!g || g->IsEmpty()) {
      ++report.nullOrEmpty;
      continue;
    }
    exportWkb(*g, wkb);
    const std::size_t hash = std::hash<std::string_view>{}(wkb);
    Feature* original = nullptr;
    for (auto [it, end] = byHash.equal_range(hash); it != end && !original; ++it) {
      exportWkb(*features[it->second].geometry, earlier);
      if (earlier == wkb) original = &features[it->second];
    }
    if (original) {
      if (original->stackCount == 1) ++report.duplicateStacks;
      ++original->stackCount;
      ++report.duplicatesCollapsed;
      // The stack's key is the least of its features' keys, whatever their order.
      original->key = std::min(original->key, featureKey(*feature, wkb));
      continue;
    }
    OGREnvelope e;
    g->getEnvelope(&e);
    if (!coordinatesFinite(*g) || !std::isfinite(e.MinX) || !std::isfinite(e.MinY) || !std::isfinite(e.MaxX) ||
        !std::isfinite(e.MaxY) || std::fabs(e.MinX) > 1e12 || std::fabs(e.MaxX) > 1e12 || std::fabs(e.MinY) > 1e12 ||
        std::fabs(e.MaxY) > 1e12) {
      ++report.nonFiniteSkipped;  // NaN, infinite or absurd coordinates
      continue;
    }
    env.merge(e);
    std::vector<double> values;
    for (int idx : fieldIndex) {
      values.push_back(idx >= 0 && feature->IsFieldSetAndNotNull(idx) ? feature->GetFieldAsDouble(idx)
                                                                      : std::numeric_limits<double>::quiet_NaN());
    }
    byHash.emplace(hash, features.size());
    const Key key = featureKey(*feature, wkb);
    features.push_back(
        {feature->GetFID(), std::unique_ptr<OGRGeometry>(feature->StealGeometry()), 1, std::move(values), key});
  }
  throwIfReadFailed();
  const std::string featuresRead =
      std::to_string(report.features) + " features read" + (options.where.empty() ? "" : " with --where");
  if (features.empty() && report.nonFiniteSkipped > 0) {
    const std::string absurd = "non-finite or absurd coordinates (NaN, infinite or beyond 1e12)";
    throw inputError(path + ": layer " + result.layerName + " holds no usable polygon: every feature was skipped" +
                     (report.nullOrEmpty == 0
                          ? " for " + absurd
                          : ", " + std::to_string(report.nonFiniteSkipped) + " for " + absurd + " and " +
                                std::to_string(report.nullOrEmpty) + " for a null or empty geometry") +
                     " (" + featuresRead + ")");
  }
  if (features.empty()) {
    throw inputError(path + ": layer " + result.layerName + " holds no polygon geometry (" + featuresRead + ")");
  }

  result.frame = chooseFrame(path, srs, env, result.crs);
  if (srs) {
    char* wkt = nullptr;
    const char* wktOptions[] = {"FORMAT=WKT2_2018", nullptr};
    if (srs->exportToWkt(&wkt, wktOptions) == OGRERR_NONE && wkt) result.crs.wkt = wkt;
    CPLFree(wkt);
  }

  // Pass 2: project, repair, split into parts, normalise; features in parallel,
  // merged in input order.
  timings.start("clean");
  std::vector<Cleaned> cleaned(features.size());
  parallelFor(
      features.size(), [&](std::size_t k) { cleaned[k] = cleanFeature(features[k], result.frame); },
      [&](std::size_t done) {
        reportProgress(progress, 0.6 + 0.4 * static_cast<double>(done) / static_cast<double>(features.size()),
                       "cleaning");
      });
  for (std::size_t k = 0; k < cleaned.size(); ++k) {
    Cleaned& c = cleaned[k];
    if (!options.numericFields.empty()) {
      result.fields.insert(result.fields.end(), c.parcels.size(), features[k].values);
    }
    report.nonPolygonal += c.nonPolygonal;
    report.degenerateSkipped += c.degenerate;
    if (c.repairFailed || (c.repaired && c.parcels.empty())) ++report.invalidSkipped;
    if (c.repaired && !c.parcels.empty()) ++report.invalidRepaired;
    report.nonPolygonalParts += c.mixed;
    if (c.inputParts > 1) {
      ++report.multipartFeatures;
      report.partsFromMultipart += static_cast<std::int64_t>(c.parcels.size());
    }
    for (Parcel& p : c.parcels) {
      p.featureKey = features[k].key;
      if (!p.shape.holes.empty()) ++report.withHoles;
      result.parcels.push_back(std::move(p));
    }
  }
  report.parcels = static_cast<std::int64_t>(result.parcels.size());
  if (result.parcels.empty()) {
    throw inputError(path + ": layer " + result.layerName + " holds no usable polygon (" +
                     std::to_string(report.features) + " features, all skipped)");
  }
  reportProgress(progress, 1.0, "cleaning");
  timings.stop();
  result.timings = timings;
  return result;
}

}  // namespace parcelscope::io
