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
#include "VectorInput.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"

namespace parcelscope::io {

namespace {

using detail::QuietErrors;

// Parts smaller than this (m², a 3 cm square) are make-valid leftovers or
// zero-area slivers, not parcels.
constexpr double kMinPartArea = 1e-3;

using detail::chooseFrame;
using detail::coordinatesFinite;
using detail::Envelope;
using detail::gdalMessage;
using detail::lastGdalMessage;
using detail::openVector;

struct Feature {
  std::int64_t fid = -1;
  std::unique_ptr<OGRGeometry> geometry;
  int stackCount = 1;
  std::vector<double> values;  // ReadOptions::numericFields
  Key key = 0;                 // Parcel::featureKey
};

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

std::vector<FieldInfo> layerFields(const std::string& path, const std::string& layerName) {
  const GDALDatasetUniquePtr ds = openVector(path);
  OGRLayer* layer = layerName.empty() ? ds->GetLayer(0) : ds->GetLayerByName(layerName.c_str());
  if (!layer) throw inputError(path + ": no layer named '" + layerName + "'");
  std::vector<FieldInfo> fields;
  OGRFeatureDefn* defn = layer->GetLayerDefn();
  for (int i = 0; i < defn->GetFieldCount(); ++i) {
    const OGRFieldType type = defn->GetFieldDefn(i)->GetType();
    fields.push_back(
        {defn->GetFieldDefn(i)->GetNameRef(), type == OFTInteger || type == OFTInteger64 || type == OFTReal});
  }
  return fields;
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
  const OGRSpatialReference* srs =
      detail::layerCrs(path, *layer, options.crsOverride, overrideSrs, result.crs.overridden);

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
