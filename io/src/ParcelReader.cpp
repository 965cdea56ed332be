#include "parcelscope/io/ParcelReader.h"

#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include "GpkgRtree.h"
#include "OgrConvert.h"
#include "VectorInput.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/GeosOps.h"
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
  bool owned = true;           // counted in the report (its shard's, see ShardRead)
  double minX = 0;             // its envelope's, input CRS
  bool inWindow = true;        // cleaned and returned
};

// A feature as read, before duplicates are collapsed.
struct RawFeature {
  std::int64_t fid = -1;
  std::unique_ptr<OGRGeometry> geometry;
  std::vector<double> values;
  std::optional<Key> fieldKey;  // from ReadOptions::keyField; none: the geometry's
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
  std::vector<Polygon> shapes;
  if (!whole->IsValid()) {
    // A street network stored as a parcel, its blocks the holes: see validWithManyHoles.
    std::optional<std::vector<Polygon>> quick;
    if (wkbFlatten(whole->getGeometryType()) == wkbPolygon &&
        static_cast<std::size_t>(whole->toPolygon()->getNumInteriorRings()) >= geos::kManyHoles) {
      quick = geos::validWithManyHoles(detail::fromOgr(*whole->toPolygon()));
    }
    if (quick) {
      shapes = std::move(*quick);
    } else {
      const char* const makeValidOptions[] = {"METHOD=STRUCTURE", nullptr};
      std::unique_ptr<OGRGeometry> fixed(whole->MakeValid(makeValidOptions));
      if (fixed) {
        detail::collectPolygons(*fixed, polygons);
        for (auto& p : polygons) shapes.push_back(detail::fromOgr(*p));
      }
    }
    if (shapes.empty()) {
      c.repairFailed = true;
      return c;
    }
    c.repaired = true;
  } else {
    detail::collectPolygons(*whole, polygons);
    for (auto& p : polygons) shapes.push_back(detail::fromOgr(*p));
  }
  int part = 0;
  for (Polygon& shape : shapes) {
    Parcel parcel;
    parcel.shape = std::move(shape);
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

// Narrows the reading of a shard's layer to features whose envelope may meet
// `window` where the format indexes envelopes: a GeoPackage's R-tree, through
// an SQL attribute filter (its boxes are rounded outwards, so none is missed),
// with every feature the R-tree lacks (null or empty geometries, a stale
// index). GDAL's spatial filter is not used: it tests the geometry itself
// against the rectangle, and drops an invalid feature that crosses its edge
// (GEOS finds no intersection). Other formats are read whole; the reader tests
// envelopes.
void restrictToWindow(GDALDataset& ds, OGRLayer& layer, const std::string& where, const Box& window) {
  if (!EQUAL(ds.GetDriverName(), "GPKG") || !*layer.GetFIDColumn() || !*layer.GetGeometryColumn()) return;
  const std::string rtree = std::string("rtree_") + layer.GetName() + "_" + layer.GetGeometryColumn();

  {
    const std::string probe =
        "SELECT name FROM sqlite_master WHERE type = 'table' AND name = " + detail::sqlQuoted(rtree, '\'');
    OGRLayer* found = ds.ExecuteSQL(probe.c_str(), nullptr, nullptr);
    const bool indexed = found && found->GetFeatureCount() > 0;
    if (found) ds.ReleaseResultSet(found);
    if (!indexed) return;
  }
  std::string box;
  auto bound = [&](const char* column, const char* op, double value) {
    if (!std::isfinite(value)) return;
    char clause[96];
    std::snprintf(clause, sizeof clause, "%s%s %s %.17g", box.empty() ? "" : " AND ", column, op, value);
    box += clause;
  };
  bound("maxx", ">=", window.minX);
  bound("minx", "<=", window.maxX);
  bound("maxy", ">=", window.minY);
  bound("miny", "<=", window.maxY);
  if (box.empty()) return;  // the whole layer
  const std::string fid = detail::sqlQuoted(layer.GetFIDColumn(), '"'), table = detail::sqlQuoted(rtree, '"');
  const std::string filter = (where.empty() ? "" : "(" + where + ") AND ") + "(" + fid + " IN (SELECT id FROM " +
                             table + " WHERE " + box + ") OR " + fid + " NOT IN (SELECT id FROM " + table + "))";
  CPLErrorReset();
  if (layer.SetAttributeFilter(filter.c_str()) != OGRERR_NONE) {
    throw inputError(ds.GetDescription() + std::string(": the R-tree of layer ") + layer.GetName() +
                     " cannot be queried (" + lastGdalMessage() + ")");
  }
}

// The layer `name` of `ds` (empty: the first). Throws Error(Input) naming `path`.
OGRLayer& namedLayer(GDALDataset& ds, const std::string& path, const std::string& name) {
  OGRLayer* layer = name.empty() ? ds.GetLayer(0) : ds.GetLayerByName(name.c_str());
  if (!layer) throw inputError(path + ": no layer named '" + name + "'");
  return *layer;
}

// Sets `options.where` (if any) on `layer`. Throws Error(Input) naming the file and the filter.
void applyWhere(OGRLayer& layer, const ReadOptions& options) {
  if (options.where.empty()) return;
  CPLErrorReset();
  if (layer.SetAttributeFilter(options.where.c_str()) != OGRERR_NONE) {
    throw inputError(options.path + ": --where \"" + options.where + "\" is not a valid filter on layer " +
                     layer.GetName() + " (" + lastGdalMessage() + ")");
  }
}

// --where for a folder or list input, evaluated feature by feature: the union
// of its files numbers its features in turn, and a filter set on the union
// would number only those that pass (a feature's id would not be the one it
// has in the file they were split from). Null when there is no --where.
std::unique_ptr<OGRFeatureQuery> whereQuery(OGRLayer& layer, const ReadOptions& options) {
  if (options.where.empty()) return nullptr;
  auto query = std::make_unique<OGRFeatureQuery>();
  CPLErrorReset();
  if (query->Compile(&layer, options.where.c_str()) != OGRERR_NONE) {
    throw inputError(options.path + ": --where \"" + options.where + "\" is not a valid filter on layer " +
                     layer.GetName() + " (" + lastGdalMessage() + ")");
  }
  return query;
}

}  // namespace

std::vector<std::string> layerNames(const std::string& path) {
  const GDALDatasetUniquePtr ds = openVector(path);
  std::vector<std::string> names;
  for (int i = 0; i < ds->GetLayerCount(); ++i) names.emplace_back(ds->GetLayer(i)->GetName());
  return names;
}

std::vector<FieldInfo> layerFields(const std::string& path, const std::string& layerName) {
  const GDALDatasetUniquePtr ds = openVector(path, layerName);
  std::vector<FieldInfo> fields;
  OGRFeatureDefn* defn = namedLayer(*ds, path, layerName).GetLayerDefn();
  for (int i = 0; i < defn->GetFieldCount(); ++i) {
    const OGRFieldType type = defn->GetFieldDefn(i)->GetType();
    fields.push_back(
        {defn->GetFieldDefn(i)->GetNameRef(), type == OFTInteger || type == OFTInteger64 || type == OFTReal});
  }
  return fields;
}

std::vector<std::string> inputFiles(const std::string& path) { return detail::inputFiles(path); }

Box layerExtent(const ReadOptions& options) {
  const GDALDatasetUniquePtr ds = openVector(options.path, options.layer);
  OGRLayer* layer = &namedLayer(*ds, options.path, options.layer);
  OGREnvelope e;
  QuietErrors quiet;
  if (layer->GetExtent(&e, TRUE) != OGRERR_NONE || !std::isfinite(e.MinX) || !std::isfinite(e.MaxX) ||
      !std::isfinite(e.MinY) || !std::isfinite(e.MaxY)) {
    throw inputError(options.path + ": layer " + layer->GetName() + " has no extent (" + lastGdalMessage() + ")");
  }
  return {e.MinX, e.MinY, e.MaxX, e.MaxY};
}

std::int64_t featureCount(const ReadOptions& options) {
  const GDALDatasetUniquePtr ds = openVector(options.path, options.layer);
  OGRLayer& layer = namedLayer(*ds, options.path, options.layer);
  QuietErrors quiet;
  applyWhere(layer, options);
  return layer.GetFeatureCount(TRUE);
}

ParcelLayer readParcels(const ReadOptions& options, const ProgressFn& progress) {
  const std::string& path = options.path;
  Timings timings;
  timings.start("read");
  auto ds = openVector(path, options.layer);
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
  // A failure GDAL reports while opening a layer it still opens (a VRT whose
  // source file is missing): the reason, should no feature come of it.
  CPLErrorReset();
  layer->GetLayerDefn();
  const std::string openFailure = CPLGetLastErrorType() >= CE_Failure ? lastGdalMessage() : "";
  result.layerName = layer->GetName();
  CleaningReport& report = result.report;

  // One file: the filter is set on the layer (its driver may use an index).
  // Several files: each feature is tested as it is read (whereQuery).
  std::unique_ptr<OGRFeatureQuery> where;
  if (inputFiles(path).empty()) {
    applyWhere(*layer, options);
  } else {
    where = whereQuery(*layer, options);
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
  // A feature's key field's value as a key (none: its geometry gives the key; see Parcel::featureKey).
  auto fieldKey = [&](const OGRFeature& feature) -> std::optional<Key> {
    if (keyIndex >= 0 && feature.IsFieldSetAndNotNull(keyIndex)) {
      const char* value = feature.GetFieldAsString(keyIndex);
      if (const auto parsed = parseKey(value)) return *parsed;
      return hashBytes(value);
    }
    if (keyIndex >= 0 && !options.keyFieldOptional) {
      throw inputError(path + ": feature " + std::to_string(feature.GetFID()) + " has no value in key field '" +
                       options.keyField + "'");
    }
    return std::nullopt;
  };
  const ShardRead* shard = options.shard ? &*options.shard : nullptr;
  const bool filtered = shard && shard->spatialFilter;
  if (filtered) restrictToWindow(*ds, *layer, options.where, shard->window);
  // In a shard, a feature belongs to the strip of its envelope's smallest x; one
  // without a usable envelope to the first strip.
  auto ownedBy = [&](const OGREnvelope* e) {
    if (!shard) return true;
    if (!e || !std::isfinite(e->MinX)) return shard->tileMinX == -std::numeric_limits<double>::infinity();
    return e->MinX >= shard->tileMinX && e->MinX < shard->tileMaxX;
  };

  // Pass 1: read features, collapse exact duplicate geometries, find the extent.
  const GIntBig total = layer->GetFeatureCount(FALSE);
  std::vector<Feature> features;
  std::unordered_map<Key, std::int64_t> fieldKeyOwner;  // key field value -> first feature id
  auto exportWkb = [](const OGRGeometry& g, std::string& out) {
    out.resize(static_cast<std::size_t>(g.WkbSize()));
    g.exportToWkb(wkbNDR, reinterpret_cast<unsigned char*>(out.data()), wkbVariantIso);
  };
  Envelope env;
  // A read error stops the loop as if the layer had ended (SQLite's "database
  // disk image is malformed" after a few features of a corrupt GeoPackage), so
  // GDAL's error state is checked for every feature and after the last one.
  std::int64_t featuresRead = 0;
  auto throwIfReadFailed = [&] {
    if (CPLGetLastErrorType() != CE_Failure && CPLGetLastErrorType() != CE_Fatal) return;
    throw inputError(path + ": reading layer " + result.layerName +
                     (options.where.empty() ? "" : " with --where \"" + options.where + "\"") + " failed after " +
                     std::to_string(featuresRead) + " features (" + lastGdalMessage() + ")");
  };
  auto rawOf = [&](OGRFeature& feature) {
    RawFeature raw;
    raw.fid = feature.GetFID();
    for (int idx : fieldIndex) {
      raw.values.push_back(idx >= 0 && feature.IsFieldSetAndNotNull(idx) ? feature.GetFieldAsDouble(idx)
                                                                         : std::numeric_limits<double>::quiet_NaN());
    }
    OGRGeometry* g = feature.GetGeometryRef();
    if (g && !g->IsEmpty()) raw.fieldKey = fieldKey(feature);
    raw.geometry.reset(feature.StealGeometry());
    return raw;
  };
  CPLErrorReset();
  layer->ResetReading();
  // Features are taken in the order of their ids (stable: read order where
  // ids repeat): a spatial filter returns them in any order (an R-tree's), and
  // so may a filtered SQL read or a GeoJSON file's own ids; a shard then takes
  // them as a whole read does.
  std::vector<RawFeature> read;
  for (auto& feature : *layer) {
    throwIfReadFailed();
    ++featuresRead;
    if (featuresRead % 2000 == 0 && total > 0) {
      reportProgress(progress, 0.6 * static_cast<double>(featuresRead) / static_cast<double>(total), "reading");
    }
    if (where && !where->Evaluate(feature.get())) continue;
    read.push_back(rawOf(*feature));
  }
  throwIfReadFailed();
  if (!std::is_sorted(read.begin(), read.end(),
                      [](const RawFeature& a, const RawFeature& b) { return a.fid < b.fid; })) {
    std::stable_sort(read.begin(), read.end(), [](const RawFeature& a, const RawFeature& b) { return a.fid < b.fid; });
  }
  for (std::size_t i = 1; shard && i < read.size(); ++i) {
    if (read[i].fid == read[i - 1].fid) {
      throw inputError(path + ": layer " + result.layerName + " gives two features the id " +
                       std::to_string(read[i].fid) + ", so it cannot be read in shards");
    }
  }

  // What each feature's geometry gives, in parallel: its envelope, its key
  // (the hash of its WKB, unless a key field gave one), the hash that finds
  // exact duplicates, and whether its coordinates are usable.
  struct Digest {
    bool present = false, usable = false;
    OGREnvelope envelope;
    Key key = 0;
    std::size_t hash = 0;
  };
  std::vector<Digest> digests(read.size());
  parallelFor(read.size(), [&](std::size_t i) {
    const OGRGeometry* g = read[i].geometry.get();
    Digest& d = digests[i];
    if (!g || g->IsEmpty()) return;
    d.present = true;
    g->getEnvelope(&d.envelope);
    thread_local std::string bytes;
    exportWkb(*g, bytes);
    d.key = read[i].fieldKey ? *read[i].fieldKey : hashBytes(bytes);
    d.hash = std::hash<std::string_view>{}(bytes);
    const OGREnvelope& e = d.envelope;
    d.usable = coordinatesFinite(*g) && std::isfinite(e.MinX) && std::isfinite(e.MinY) && std::isfinite(e.MaxX) &&
               std::isfinite(e.MaxY) && std::fabs(e.MinX) <= 1e12 && std::fabs(e.MaxX) <= 1e12 &&
               std::fabs(e.MinY) <= 1e12 && std::fabs(e.MaxY) <= 1e12;  // not NaN, infinite or absurd
  });
  // Exact duplicates: a feature whose WKB equals that of an earlier feature
  // kept (a usable one that is no duplicate itself) joins that feature's
  // stack. Features meet by hash (sorted runs); bytes are compared (exported
  // anew) only within a run, so no copy of every geometry is kept.
  std::vector<std::int64_t> original(read.size(), -1);
  {
    std::vector<std::pair<std::size_t, std::size_t>> byHash;  // (hash, feature)
    byHash.reserve(read.size());
    for (std::size_t i = 0; i < read.size(); ++i) {
      if (digests[i].present) byHash.emplace_back(digests[i].hash, i);
    }
    std::sort(byHash.begin(), byHash.end());
    std::string wkb, earlier;
    std::vector<std::size_t> kept;
    for (std::size_t from = 0; from < byHash.size();) {
      std::size_t to = from + 1;
      while (to < byHash.size() && byHash[to].first == byHash[from].first) ++to;
      kept.clear();
      for (std::size_t k = from; to - from > 1 && k < to; ++k) {
        const std::size_t i = byHash[k].second;
        exportWkb(*read[i].geometry, wkb);
        for (std::size_t m : kept) {
          exportWkb(*read[m].geometry, earlier);
          if (earlier == wkb) {
            original[i] = static_cast<std::int64_t>(m);
            break;
          }
        }
        if (original[i] < 0 && digests[i].usable) kept.push_back(i);
      }
      from = to;
    }
  }
  std::vector<std::size_t> featureOf(read.size(), 0);  // a kept feature's index in `features`
  for (std::size_t i = 0; i < read.size(); ++i) {
    RawFeature& raw = read[i];
    const Digest& d = digests[i];
    if (!d.present) {
      if (ownedBy(nullptr)) {
        ++report.features;
        ++report.nullOrEmpty;
      }
      continue;
    }
    const OGREnvelope& e = d.envelope;
    const bool owned = ownedBy(&e);
    report.features += owned;
    if (original[i] >= 0) {
      Feature& first = features[featureOf[static_cast<std::size_t>(original[i])]];
      if (owned) {
        if (first.stackCount == 1) ++report.duplicateStacks;
        ++report.duplicatesCollapsed;
      }
      ++first.stackCount;
      // The stack's key is the least of its features' keys, whatever their order.
      first.key = std::min(first.key, d.key);
      continue;
    }
    if (raw.fieldKey) {
      // Another geometry with the same key field value: keys would collide.
      const auto [seen, fresh] = fieldKeyOwner.emplace(*raw.fieldKey, raw.fid);
      if (!fresh) {
        throw inputError(path + ": features " + std::to_string(seen->second) + " and " + std::to_string(raw.fid) +
                         " have the same value in --key-field " + options.keyField +
                         " (a key names one parcel; give a field of unique values, or no --key-field)");
      }
    }
    if (!d.usable) {
      report.nonFiniteSkipped += owned;  // NaN, infinite or absurd coordinates
      continue;
    }
    // The frame's sample: every feature, except in a filtered shard, which
    // samples its own and exchanges.
    if (!filtered || owned) env.merge(e);
    const bool inWindow = !shard || (e.MinX <= shard->window.maxX && e.MaxX >= shard->window.minX &&
                                     e.MinY <= shard->window.maxY && e.MaxY >= shard->window.minY);
    featureOf[i] = features.size();
    features.push_back({raw.fid, std::move(raw.geometry), 1, std::move(raw.values), d.key, owned, e.MinX, inWindow});
  }
  read = std::vector<RawFeature>();
  const std::string featuresText =
      std::to_string(report.features) + " features read" + (options.where.empty() ? "" : " with --where");
  if (!shard && features.empty() && report.nonFiniteSkipped > 0) {
    const std::string absurd = "non-finite or absurd coordinates (NaN, infinite or beyond 1e12)";
    throw inputError(path + ": layer " + result.layerName + " holds no usable polygon: every feature was skipped" +
                     (report.nullOrEmpty == 0
                          ? " for " + absurd
                          : ", " + std::to_string(report.nonFiniteSkipped) + " for " + absurd + " and " +
                                std::to_string(report.nullOrEmpty) + " for a null or empty geometry") +
                     " (" + featuresText + ")");
  }
  if (!shard && features.empty()) {
    // GDAL's reason when reading failed (a VRT whose source file is missing).
    const std::string gdal = !openFailure.empty()                  ? "; GDAL: " + openFailure
                             : CPLGetLastErrorType() >= CE_Failure ? "; GDAL: " + lastGdalMessage()
                                                                   : "";
    throw inputError(path + ": layer " + result.layerName + " holds no polygon geometry (" + featuresText + ")" + gdal);
  }

  if (filtered && !shard->frame && shard->exchange) {
    FrameSample sample;
    sample.extent = {env.minX, env.minY, env.maxX, env.maxY};
    sample.centresX = std::move(env.centresX);
    sample.centresY = std::move(env.centresY);
    shard->exchange(sample);
    env = Envelope{};
    env.minX = sample.extent.minX;
    env.minY = sample.extent.minY;
    env.maxX = sample.extent.maxX;
    env.maxY = sample.extent.maxY;
    env.centresX = std::move(sample.centresX);
    env.centresY = std::move(sample.centresY);
  }
  if (env.centresX.empty()) {
    if (!shard || !shard->frame) {
      throw inputError(path + ": layer " + result.layerName + " holds no polygon geometry (" + featuresText + ")");
    }
    OGREnvelope origin;  // the CRS is still named and checked; the given frame is kept
    origin.MinX = origin.MaxX = origin.MinY = origin.MaxY = 0;
    env.merge(origin);
  }
  result.frame = chooseFrame(path, srs, env, result.crs);
  if (shard && shard->frame) result.frame = *shard->frame;
  if (srs) {
    char* wkt = nullptr;
    const char* wktOptions[] = {"FORMAT=WKT2_2018", nullptr};
    if (srs->exportToWkt(&wkt, wktOptions) == OGRERR_NONE && wkt) result.crs.wkt = wkt;
    CPLFree(wkt);
  }

  // Pass 2: project, repair, split into parts, normalise; features in parallel,
  // merged in input order. A shard cleans its window's features only.
  timings.start("clean");
  if (shard) {
    std::vector<Feature> kept;
    for (Feature& f : features) {
      if (f.inWindow) kept.push_back(std::move(f));
    }
    features = std::move(kept);
  }
  std::vector<Cleaned> cleaned(features.size());
  // Largest geometries first, so that one street network stored as a parcel
  // (tens of thousands of vertices to repair) does not finish last alone.
  std::vector<std::size_t> bySize(features.size());
  std::vector<std::size_t> sizes(features.size());
  for (std::size_t k = 0; k < features.size(); ++k) {
    bySize[k] = k;
    sizes[k] = features[k].geometry->WkbSize();
  }
  std::stable_sort(bySize.begin(), bySize.end(), [&](std::size_t x, std::size_t y) { return sizes[x] > sizes[y]; });
  parallelFor(
      features.size(),
      [&](std::size_t i) {
        const std::size_t k = bySize[i];
        cleaned[k] = cleanFeature(features[k], result.frame);
      },
      [&](std::size_t done) {
        reportProgress(progress, 0.6 + 0.4 * static_cast<double>(done) / static_cast<double>(features.size()),
                       "cleaning");
      });
  for (std::size_t k = 0; k < cleaned.size(); ++k) {
    Cleaned& c = cleaned[k];
    if (!options.numericFields.empty()) {
      result.fields.insert(result.fields.end(), c.parcels.size(), features[k].values);
    }
    if (features[k].owned) {
      report.nonPolygonal += c.nonPolygonal;
      report.degenerateSkipped += c.degenerate;
      if (c.repairFailed || (c.repaired && c.parcels.empty())) ++report.invalidSkipped;
      if (c.repaired && !c.parcels.empty()) ++report.invalidRepaired;
      report.nonPolygonalParts += c.mixed;
      if (c.inputParts > 1) {
        ++report.multipartFeatures;
        report.partsFromMultipart += static_cast<std::int64_t>(c.parcels.size());
      }
      report.parcels += static_cast<std::int64_t>(c.parcels.size());
    }
    if (shard) result.sourceMinX.insert(result.sourceMinX.end(), c.parcels.size(), features[k].minX);
    for (Parcel& p : c.parcels) {
      p.featureKey = features[k].key;
      if (!p.shape.holes.empty() && features[k].owned) ++report.withHoles;
      result.parcels.push_back(std::move(p));
    }
  }
  if (result.parcels.empty() && !shard) {
    // Why, by reason; parts under 0.001 m2 mostly come from a CRS whose unit is
    // not the data's (lon/lat read as metres).
    std::string why;
    const auto add = [&](std::int64_t n, const char* reason) {
      if (n > 0) why += (why.empty() ? ": " : ", ") + std::to_string(n) + " " + reason;
    };
    add(report.nullOrEmpty, "null or empty");
    add(report.nonPolygonal, "not polygons");
    add(report.nonFiniteSkipped, "with coordinates that are not finite");
    add(report.invalidSkipped, "invalid beyond repair");
    add(report.degenerateSkipped, "degenerate parts (under 0.001 m2 or under 3 vertices)");
    const bool tiny = report.degenerateSkipped > 0;
    throw inputError(path + ": layer " + result.layerName + " holds no usable polygon (" +
                     std::to_string(report.features) + " features, all skipped" + why + ")" +
                     (tiny ? (options.crsOverride.empty() ? "; is the layer's CRS right? (--crs EPSG:N)"
                                                          : "; is --crs " + options.crsOverride + " the data's CRS?")
                           : ""));
  }
  reportProgress(progress, 1.0, "cleaning");
  timings.stop();
  result.timings = timings;
  return result;
}

}  // namespace parcelscope::io
