#include "parcelscope/io/Writers.h"

#include <cpl_json.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <charconv>
#include <deque>
#include <fstream>
#include <future>
#include <stdexcept>

#include "GpkgFeatures.h"
#include "GpkgRtree.h"
#include "OgrConvert.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/core/Parallel.h"

namespace parcelscope::io {

namespace {
// A CSV field: integers and %.10g reals (std::to_chars gives what printf gives),
// strings quoted when they hold a separator, quote or line break.
void appendCsvField(std::string& out, const Value& v) {
  char buf[64];
  if (const auto* i = std::get_if<std::int64_t>(&v)) {
    out.append(buf, std::to_chars(buf, buf + sizeof buf, *i).ptr);
    return;
  }
  if (const auto* d = std::get_if<double>(&v)) {
    out.append(buf, std::to_chars(buf, buf + sizeof buf, *d, std::chars_format::general, 10).ptr);
    return;
  }
  const std::string& s = std::get<std::string>(v);
  if (s.find_first_of(",\"\n\r") == std::string::npos) {
    out += s;
    return;
  }
  out += '"';
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
}

void writeText(const std::string& path, const std::vector<std::string>& chunks) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  for (const std::string& chunk : chunks) out.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
  out.close();
  if (!out) throw ioError(path + ": cannot write");
}
}  // namespace

void writeCsv(const std::string& path, const Table& table) { writeCsv(path, RowSource::of(table)); }

void writeCsv(const std::string& path, const RowSource& rows) {
  // Rows made and formatted in parallel, in chunks written in order, a batch
  // of chunks at a time.
  constexpr std::size_t kRowsPerChunk = 4096, kChunksPerBatch = 16;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  std::string header;
  for (std::size_t c = 0; c < rows.columns.size(); ++c) {
    if (c) header += ',';
    appendCsvField(header, rows.columns[c].name);
  }
  header += '\n';
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  const std::size_t chunks = (rows.rows + kRowsPerChunk - 1) / kRowsPerChunk;
  std::vector<std::string> text(kChunksPerBatch);
  for (std::size_t first = 0; first < chunks && out; first += kChunksPerBatch) {
    const std::size_t batch = std::min(kChunksPerBatch, chunks - first);
    parallelFor(batch, [&](std::size_t k) {
      std::string& chunk = text[k];
      chunk.clear();
      std::vector<Value> row;
      const std::size_t begin = (first + k) * kRowsPerChunk;
      for (std::size_t r = begin, end = std::min(rows.rows, begin + kRowsPerChunk); r < end; ++r) {
        row.clear();
        rows.row(r, row);
        for (std::size_t c = 0; c < row.size(); ++c) {
          if (c) chunk += ',';
          appendCsvField(chunk, row[c]);
        }
        chunk += '\n';
      }
    });
    for (std::size_t k = 0; k < batch; ++k) out.write(text[k].data(), static_cast<std::streamsize>(text[k].size()));
  }
  out.close();
  if (!out) throw ioError(path + ": cannot write");
}

void writeJson(const std::string& path, const Json& json) { writeText(path, {json.dump() + "\n"}); }

namespace {
Json fromCpl(const CPLJSONObject& o) {
  switch (o.GetType()) {
    case CPLJSONObject::Type::Object: {
      Json j = Json::object();
      for (const CPLJSONObject& child : o.GetChildren()) j.set(child.GetName(), fromCpl(child));
      return j;
    }
    case CPLJSONObject::Type::Array: {
      Json j = Json::array();
      const CPLJSONArray a = o.ToArray();
      for (int i = 0; i < a.Size(); ++i) j.push(fromCpl(a[i]));
      return j;
    }
    case CPLJSONObject::Type::Boolean:
      return Json(o.ToBool());
    case CPLJSONObject::Type::String:
      return Json(o.ToString());
    case CPLJSONObject::Type::Integer:
    case CPLJSONObject::Type::Long:
      return Json(static_cast<long long>(o.ToLong()));
    case CPLJSONObject::Type::Double:
      return Json(o.ToDouble());
    default:
      return Json();
  }
}
}  // namespace

Json readJson(const std::string& path) {
  detail::QuietErrors quiet;
  CPLErrorReset();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw inputError(path + ": cannot open");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CPLJSONDocument doc;
  if (!doc.LoadMemory(text)) {
    throw inputError(path + ": not valid JSON (" + std::string(CPLGetLastErrorMsg()) + ")");
  }
  return fromCpl(doc.GetRoot());
}

namespace {

void setFields(OGRFeature& feature, const std::vector<Value>& row) {
  for (std::size_t c = 0; c < row.size(); ++c) {
    const Value& v = row[c];
    const int idx = static_cast<int>(c);
    if (const auto* n = std::get_if<std::int64_t>(&v)) {
      feature.SetField(idx, static_cast<GIntBig>(*n));
    } else if (const auto* d = std::get_if<double>(&v)) {
      if (std::isnan(*d)) {
        feature.SetFieldNull(idx);
      } else {
        feature.SetField(idx, *d);
      }
    } else {
      feature.SetField(idx, std::get<std::string>(v).c_str());
    }
  }
}

template <typename Fail>
void createFields(OGRLayer& layer, const std::vector<Column>& columns, const Fail& fail) {
  for (const Column& c : columns) {
    OGRFieldDefn field(c.name.c_str(), detail::ogrFieldType(c.type));
    if (layer.CreateField(&field) != OGRERR_NONE) throw fail("cannot create field " + c.name);
  }
}

OGRSpatialReference outputSrs(const CrsInfo& crs) {
  OGRSpatialReference srs;
  if (!crs.wkt.empty()) {
    srs.importFromWkt(crs.wkt.c_str());
  } else {
    srs.SetFromUserInput("OGC:CRS84");
  }
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return srs;
}

}  // namespace

LayerWrite writePolygonLayer(const std::string& path, const std::string& layerName,
                             const std::vector<std::vector<Polygon>>& geometries, const Table& attributes,
                             const LocalFrame& frame, const CrsInfo& crs, bool spatialIndex) {
  return writePolygonLayer(path, layerName, geometries, RowSource::of(attributes), frame, crs, spatialIndex);
}

LayerWrite writePolygonLayer(const std::string& path, const std::string& layerName,
                             const std::vector<std::vector<Polygon>>& geometries, const RowSource& attributes,
                             const LocalFrame& frame, const CrsInfo& crs, bool spatialIndex) {
  if (geometries.size() != attributes.rows) throw std::logic_error("writePolygonLayer: geometries and rows differ");
  return writePolygonLayer(
      path, layerName, [&](std::size_t i, std::vector<Polygon>& parts) { parts = geometries[i]; }, attributes, frame,
      crs, spatialIndex);
}

namespace {
// Mapped back, checked and repaired in the CRS written (fileGeometry).
std::vector<Polygon> fileParts(std::vector<Polygon> parts, const LocalFrame& frame, bool& repaired, bool& emptied) {
  for (Polygon& p : parts) {
    for (Point& q : p.outer) q = frame.toSource(q);
    for (Ring& h : p.holes)
      for (Point& q : h) q = frame.toSource(q);
  }
  parts = geos::validMultiPolygon(std::move(parts), repaired);
  emptied = repaired && parts.empty();
  return parts;
}

detail::Envelope envelopeOf(const std::vector<Polygon>& parts) {
  detail::Envelope e;
  for (const Polygon& p : parts) {
    for (const Point& q : p.outer) e.cover(q.x, q.y);
    for (const Ring& h : p.holes)
      for (const Point& q : h) e.cover(q.x, q.y);
  }
  return e;
}
}  // namespace

FileGeometry fileGeometry(std::vector<Polygon> parts, const LocalFrame& frame) {
  FileGeometry g;
  detail::appendMultiPolygonWkb(g.wkb, fileParts(std::move(parts), frame, g.repaired, g.emptied));
  return g;
}

LayerWrite writePolygonLayer(const std::string& path, const std::string& layerName, const PolygonSource& geometries,
                             const RowSource& attributes, const LocalFrame& frame, const CrsInfo& crs,
                             bool spatialIndex, const ReadyGeometry& ready) {
  detail::ensureGdalRegistered();
  detail::QuietErrors quiet;
  CPLErrorReset();
  auto fail = [&](const std::string& what) {
    return ioError(path + ": " + what + " (" + std::string(CPLGetLastErrorMsg()) + ")");
  };
  auto endsWith = [&](const char* suffix) {
    const std::string s(suffix);
    return path.size() >= s.size() && path.compare(path.size() - s.size(), s.size(), s) == 0;
  };
  const bool geojson = endsWith(".geojson") || endsWith(".json");
  const char* format = geojson ? "GeoJSON" : "GPKG";
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(format);
  if (!driver) throw ioError(path + ": GDAL has no " + format + " driver");
  GDALDatasetUniquePtr ds(driver->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  if (!ds) throw fail(std::string("cannot create ") + format + " file");

  OGRSpatialReference srs = outputSrs(crs);
  CPLStringList layerOptions;
  if (!geojson && !spatialIndex) layerOptions.SetNameValue("SPATIAL_INDEX", "NO");
  OGRLayer* layer = ds->CreateLayer(layerName.c_str(), &srs, wkbMultiPolygon, layerOptions.List());
  if (!layer) throw fail("cannot create layer " + layerName);
  createFields(*layer, attributes.columns, fail);
  LayerWrite report;
  const std::size_t count = attributes.rows;
  report.features = static_cast<std::int64_t>(count);
  constexpr std::size_t kBatch = 4096;
  if (!geojson) {
    // GDAL made the file, the table and its metadata; the rows go in through
    // SQLite (detail::insertGpkgFeatures), prepared in batches on other
    // threads (mapped back, checked, repaired, encoded) while this one inserts.
    const std::string table = layer->GetName(), column = layer->GetGeometryColumn();
    std::vector<Column> fields = attributes.columns;
    for (std::size_t c = 0; c < fields.size(); ++c) {
      fields[c].name = layer->GetLayerDefn()->GetFieldDefn(static_cast<int>(c))->GetNameRef();
    }
    ds.reset();
    if (CPLGetLastErrorType() == CE_Failure) throw fail("cannot create layer " + layerName);
    const std::int32_t srsId = detail::gpkgSrsId(path, table);
    struct Batch {
      std::vector<detail::GpkgRow> rows;
      std::int64_t repaired = 0, emptied = 0;
    };
    auto prepare = [&](std::size_t from) {
      detail::QuietErrors quietHere;  // OGR's conversions of mismatched values warn
      Batch batch;
      const std::size_t to = std::min(count, from + kBatch);
      batch.rows.resize(to - from);
      std::vector<Polygon> parts;
      std::string wkb;
      for (std::size_t i = from; i < to; ++i) {
        detail::GpkgRow& row = batch.rows[i - from];
        if (const FileGeometry* made = ready ? ready(i) : nullptr) {
          row.envelope = detail::multiPolygonWkbEnvelope(made->wkb);
          detail::appendGpkgGeometry(row.geometry, made->wkb, row.envelope, srsId);
          batch.repaired += made->repaired;
          batch.emptied += made->emptied;
        } else {
          parts.clear();
          geometries(i, parts);
          bool repaired = false, emptied = false;
          const std::vector<Polygon> written = fileParts(std::move(parts), frame, repaired, emptied);
          wkb.clear();
          detail::appendMultiPolygonWkb(wkb, written);
          row.envelope = envelopeOf(written);
          detail::appendGpkgGeometry(row.geometry, wkb, row.envelope, srsId);
          batch.repaired += repaired;
          batch.emptied += emptied;
        }
        attributes.row(i, row.values);
        detail::convertToColumns(fields, row.values);
      }
      return batch;
    };
    // Two batches in preparation while one is inserted.
    constexpr std::size_t kAhead = 2;
    std::deque<std::future<Batch>> coming;
    std::size_t nextFrom = 0;
    auto launch = [&] {
      while (coming.size() < kAhead && nextFrom < count) {
        coming.push_back(std::async(std::launch::async, prepare, nextFrom));
        nextFrom += kBatch;
      }
    };
    Batch current;
    std::size_t at = 0;
    launch();
    const auto next = [&](detail::GpkgRow& row) {
      if (at == current.rows.size()) {
        if (coming.empty()) return false;
        std::future<Batch> first = std::move(coming.front());
        coming.pop_front();
        current = first.get();  // a failure while preparing comes out here, as thrown
        launch();
        report.repaired += current.repaired;
        report.emptied += current.emptied;
        at = 0;
      }
      row = std::move(current.rows[at++]);
      return true;
    };
    // The R-tree GDAL made is packed from all boxes once the rows are in
    // (detail::fillRtree), its insert trigger taken away meanwhile.
    std::vector<detail::RtreeEntry> boxes;
    if (spatialIndex) boxes.reserve(count);
    const auto inserted = [&](std::int64_t fid, const detail::GpkgRow& row) {
      if (spatialIndex && !row.envelope.empty) {
        boxes.push_back({fid, row.envelope.minx, row.envelope.maxx, row.envelope.miny, row.envelope.maxy});
      }
    };
    detail::GpkgInsert done;
    try {
      done = detail::insertGpkgFeatures(path, table, column, fields, next, inserted);
    } catch (...) {
      // Batches still in preparation read the caller's data: wait for them.
      for (auto& f : coming) {
        if (f.valid()) f.wait();
      }
      throw;
    }
    if (!done.rtreeName.empty()) detail::fillRtree(path, done.rtreeName, std::move(boxes), done.rtreeInsertTrigger);
    return report;
  }

  // GeoJSON: features through OGR, geometries converted in batches on a
  // second thread while this one inserts the batch before.
  using Batch = std::vector<std::unique_ptr<OGRMultiPolygon>>;
  auto prepare = [&](std::size_t from) {
    Batch batch;
    const std::size_t to = std::min(count, from + kBatch);
    batch.reserve(to - from);
    std::vector<Polygon> parts;
    for (std::size_t i = from; i < to; ++i) {
      if (const FileGeometry* made = ready ? ready(i) : nullptr) {
        OGRGeometry* g = nullptr;
        if (OGRGeometryFactory::createFromWkb(made->wkb.data(), nullptr, &g, made->wkb.size()) != OGRERR_NONE || !g ||
            wkbFlatten(g->getGeometryType()) != wkbMultiPolygon) {
          delete g;
          throw std::logic_error("writePolygonLayer: feature " + std::to_string(i) + " came as no MultiPolygon");
        }
        report.repaired += made->repaired;
        report.emptied += made->emptied;
        batch.emplace_back(g->toMultiPolygon());
        continue;
      }
      parts.clear();
      geometries(i, parts);
      bool repaired = false, emptied = false;
      batch.push_back(detail::toOgr(fileParts(std::move(parts), frame, repaired, emptied)));
      report.repaired += repaired;
      report.emptied += emptied;
    }
    return batch;
  };
  std::future<Batch> next = std::async(std::launch::async, prepare, 0);
  for (std::size_t from = 0; from < count; from += kBatch) {
    Batch batch = next.get();
    if (from + kBatch < count) next = std::async(std::launch::async, prepare, from + kBatch);
    std::vector<Value> row;
    for (std::size_t k = 0; k < batch.size(); ++k) {
      const std::size_t i = from + k;
      OGRFeature feature(layer->GetLayerDefn());
      row.clear();
      attributes.row(i, row);
      setFields(feature, row);
      feature.SetGeometryDirectly(batch[k].release());
      if (layer->CreateFeature(&feature) != OGRERR_NONE) {
        throw fail("cannot write feature " + std::to_string(i));
      }
    }
  }
  ds.reset();  // flush and close before the caller renames the file
  if (CPLGetLastErrorType() == CE_Failure) throw fail("closing failed");
  return report;
}

void writeNetworkLayers(const std::string& path, const std::vector<Point>& nodes, const Table& nodeAttributes,
                        const std::vector<std::vector<Point>>& edges, const Table& edgeAttributes,
                        const LocalFrame& frame, const CrsInfo& crs) {
  detail::ensureGdalRegistered();
  detail::QuietErrors quiet;
  CPLErrorReset();
  auto fail = [&](const std::string& what) {
    return ioError(path + ": " + what + " (" + std::string(CPLGetLastErrorMsg()) + ")");
  };
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GPKG");
  if (!driver) throw ioError(path + ": GDAL has no GPKG driver");
  GDALDatasetUniquePtr ds(driver->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  if (!ds) throw fail("cannot create GPKG file");
  OGRSpatialReference srs = outputSrs(crs);
  auto write = [&](const char* name, OGRwkbGeometryType type, const Table& attributes, std::size_t count,
                   const auto& geometry) {
    OGRLayer* layer = ds->CreateLayer(name, &srs, type, nullptr);
    if (!layer) throw fail(std::string("cannot create layer ") + name);
    createFields(*layer, attributes.columns, fail);
    if (ds->StartTransaction() != OGRERR_NONE) throw fail("cannot start transaction");
    for (std::size_t i = 0; i < count; ++i) {
      OGRFeature feature(layer->GetLayerDefn());
      setFields(feature, attributes.rows[i]);
      feature.SetGeometryDirectly(geometry(i));
      if (layer->CreateFeature(&feature) != OGRERR_NONE) throw fail("cannot write feature " + std::to_string(i));
    }
    if (ds->CommitTransaction() != OGRERR_NONE) throw fail("cannot commit");
  };
  write("nodes", wkbPoint, nodeAttributes, nodes.size(), [&](std::size_t i) {
    const Point p = frame.toSource(nodes[i]);
    return new OGRPoint(p.x, p.y);
  });
  write("edges", wkbLineString, edgeAttributes, edges.size(), [&](std::size_t i) {
    auto* line = new OGRLineString;
    for (const Point& q : edges[i]) {
      const Point p = frame.toSource(q);
      line->addPoint(p.x, p.y);
    }
    return line;
  });
  ds.reset();
  if (CPLGetLastErrorType() == CE_Failure) throw fail("closing failed");
}

std::string gdalVersion() { return GDALVersionInfo("RELEASE_NAME"); }

}  // namespace parcelscope::io
