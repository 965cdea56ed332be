#include "parcelscope/io/Writers.h"

#include <cpl_json.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <cstdio>
#include <fstream>

#include "OgrConvert.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::io {

namespace {
std::string csvField(const Value& v) {
  if (const auto* i = std::get_if<std::int64_t>(&v)) return std::to_string(*i);
  if (const auto* d = std::get_if<double>(&v)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", *d);
    return buf;
  }
  const std::string& s = std::get<std::string>(v);
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw ioError(path + ": cannot write");
}
}  // namespace

void writeCsv(const std::string& path, const Table& table) {
  std::string text;
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    text += (c ? "," : "") + csvField(table.columns[c].name);
  }
  text += '\n';
  for (const auto& row : table.rows) {
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (c) text += ',';
      text += csvField(row[c]);
    }
    text += '\n';
  }
  writeText(path, text);
}

void writeJson(const std::string& path, const Json& json) { writeText(path, json.dump() + "\n"); }

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
    case CPLJSONObject::Type::Boolean: return Json(o.ToBool());
    case CPLJSONObject::Type::String: return Json(o.ToString());
    case CPLJSONObject::Type::Integer:
    case CPLJSONObject::Type::Long: return Json(static_cast<long long>(o.ToLong()));
    case CPLJSONObject::Type::Double: return Json(o.ToDouble());
    default: return Json();
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

void writePolygonLayer(const std::string& path, const std::string& layerName,
                       const std::vector<std::vector<Polygon>>& geometries, const Table& attributes,
                       const LocalFrame& frame, const CrsInfo& crs) {
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

  OGRSpatialReference srs;
  if (!crs.wkt.empty()) {
    srs.importFromWkt(crs.wkt.c_str());
  } else {
    srs.SetFromUserInput("OGC:CRS84");
  }
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  OGRLayer* layer = ds->CreateLayer(layerName.c_str(), &srs, wkbMultiPolygon, nullptr);
  if (!layer) throw fail("cannot create layer " + layerName);
  for (const Column& c : attributes.columns) {
    const OGRFieldType type = c.type == Column::Type::Integer ? OFTInteger64
                              : c.type == Column::Type::Real  ? OFTReal
                                                              : OFTString;
    OGRFieldDefn field(c.name.c_str(), type);
    if (layer->CreateField(&field) != OGRERR_NONE) throw fail("cannot create field " + c.name);
  }
  if (!geojson && ds->StartTransaction() != OGRERR_NONE) throw fail("cannot start transaction");
  for (std::size_t i = 0; i < geometries.size(); ++i) {
    OGRFeature feature(layer->GetLayerDefn());
    for (std::size_t c = 0; c < attributes.columns.size(); ++c) {
      const Value& v = attributes.rows[i][c];
      const int idx = static_cast<int>(c);
      if (const auto* n = std::get_if<std::int64_t>(&v)) {
        feature.SetField(idx, static_cast<GIntBig>(*n));
      } else if (const auto* d = std::get_if<double>(&v)) {
        feature.SetField(idx, *d);
      } else {
        feature.SetField(idx, std::get<std::string>(v).c_str());
      }
    }
    auto multi = detail::toOgr(geometries[i]);
    for (OGRPolygon* p : *multi) {
      for (OGRLinearRing* ring : *p) {
        for (int k = 0, n = ring->getNumPoints(); k < n; ++k) {
          const Point s = frame.toSource({ring->getX(k), ring->getY(k)});
          ring->setPoint(k, s.x, s.y);
        }
      }
    }
    feature.SetGeometryDirectly(multi.release());
    if (layer->CreateFeature(&feature) != OGRERR_NONE) {
      throw fail("cannot write feature " + std::to_string(i));
    }
  }
  if (!geojson && ds->CommitTransaction() != OGRERR_NONE) throw fail("cannot commit");
  ds.reset();  // flush and close before the caller renames the file
  if (CPLGetLastErrorType() == CE_Failure) throw fail("closing failed");
}

std::string gdalVersion() { return GDALVersionInfo("RELEASE_NAME"); }

}  // namespace parcelscope::io
