#include "GpkgFeatures.h"

#include <cpl_conv.h>
#include <ogr_feature.h>
#include <sqlite3.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>

#include "GpkgRtree.h"
#include "OgrConvert.h"
#include "SqliteHandles.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::io::detail {

namespace {

void putU32(std::string& out, std::uint32_t v) {
  char b[4];
  for (int i = 0; i < 4; ++i) b[i] = static_cast<char>((v >> (8 * i)) & 0xffu);
  out.append(b, 4);
}
void putDouble(std::string& out, double d) {
  static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559);
  std::uint64_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  char b[8];
  for (int i = 0; i < 8; ++i) b[i] = static_cast<char>((bits >> (8 * i)) & 0xffu);
  out.append(b, 8);
}

void appendRing(std::string& out, const Ring& ring) {
  putU32(out, static_cast<std::uint32_t>(ring.empty() ? 0 : ring.size() + 1));
  for (const Point& p : ring) {
    putDouble(out, p.x);
    putDouble(out, p.y);
  }
  if (!ring.empty()) {
    putDouble(out, ring.front().x);
    putDouble(out, ring.front().y);
  }
}

// A little-endian WKB reader over a string, failing past the end.
struct WkbReader {
  const std::string& wkb;
  std::size_t at = 0;
  const unsigned char* bytes(std::size_t n) {
    if (wkb.size() - at < n || at > wkb.size()) throw std::logic_error("WKB MultiPolygon: truncated");
    const auto* p = reinterpret_cast<const unsigned char*>(wkb.data()) + at;
    at += n;
    return p;
  }
  std::uint32_t u32() {
    const unsigned char* p = bytes(4);
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
  }
  double real() {
    const unsigned char* p = bytes(8);
    std::uint64_t bits = 0;
    for (int i = 7; i >= 0; --i) bits = bits << 8 | p[i];
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }
  void header(std::uint32_t type) {
    if (*bytes(1) != 1 || u32() != type) throw std::logic_error("WKB MultiPolygon: not a little-endian MultiPolygon");
  }
};

// The SQL of the triggers of `db` that meet `condition` (on sqlite_master),
// and the triggers dropped.
std::vector<std::string> takeTriggers(const Connection& db, const std::string& condition) {
  std::vector<std::string> names, sql;
  {
    Stmt s = db.prepare("SELECT name, sql FROM sqlite_master WHERE type = 'trigger' AND " + condition);
    while (sqlite3_step(s.get()) == SQLITE_ROW) {
      names.emplace_back(reinterpret_cast<const char*>(sqlite3_column_text(s.get(), 0)));
      sql.emplace_back(reinterpret_cast<const char*>(sqlite3_column_text(s.get(), 1)));
    }
  }
  for (const std::string& n : names) db.exec("DROP TRIGGER " + sqlQuoted(n, '"'));
  return sql;
}

}  // namespace

void appendMultiPolygonWkb(std::string& out, const std::vector<Polygon>& parts) {
  out += '\x01';
  putU32(out, 6);  // MultiPolygon
  putU32(out, static_cast<std::uint32_t>(parts.size()));
  for (const Polygon& p : parts) {
    out += '\x01';
    putU32(out, 3);  // Polygon
    putU32(out, static_cast<std::uint32_t>(1 + p.holes.size()));
    appendRing(out, p.outer);
    for (const Ring& h : p.holes) appendRing(out, h);
  }
}

Envelope multiPolygonWkbEnvelope(const std::string& wkb) {
  WkbReader r{wkb};
  r.header(6);
  Envelope e;
  for (std::uint32_t p = 0, parts = r.u32(); p < parts; ++p) {
    r.header(3);
    for (std::uint32_t k = 0, rings = r.u32(); k < rings; ++k) {
      for (std::uint32_t i = 0, n = r.u32(); i < n; ++i) {
        const double x = r.real(), y = r.real();
        e.cover(x, y);
      }
    }
  }
  if (r.at != wkb.size()) throw std::logic_error("WKB MultiPolygon: bytes after the geometry");
  return e;
}

void appendGpkgGeometry(std::string& out, const std::string& wkb, const Envelope& envelope, std::int32_t srsId) {
  out += 'G';
  out += 'P';
  out += '\0';  // version 0
  // Flags: little-endian (bit 0); an XY envelope (bits 1-3 = 1), or none and
  // the empty bit (bit 4).
  out += static_cast<char>(envelope.empty ? 0x11 : 0x03);
  putU32(out, static_cast<std::uint32_t>(srsId));
  if (!envelope.empty) {
    putDouble(out, envelope.minx);
    putDouble(out, envelope.maxx);
    putDouble(out, envelope.miny);
    putDouble(out, envelope.maxy);
  }
  out += wkb;
}

void convertToColumns(const std::vector<Column>& columns, std::vector<Value>& row) {
  if (row.size() != columns.size()) throw std::logic_error("convertToColumns: a value per column");
  std::unique_ptr<OGRFeature> scratch;
  std::unique_ptr<OGRFeatureDefn, void (*)(OGRFeatureDefn*)> defn(nullptr, [](OGRFeatureDefn* d) { d->Release(); });
  for (std::size_t c = 0; c < row.size(); ++c) {
    Value& v = row[c];
    const Column::Type type = columns[c].type;
    const auto* d = std::get_if<double>(&v);
    if (d && std::isnan(*d)) continue;  // NULL whatever the field's type
    const bool matches = type == Column::Type::Integer ? std::holds_alternative<std::int64_t>(v)
                         : type == Column::Type::Real  ? d != nullptr
                                                       : std::holds_alternative<std::string>(v);
    if (matches) continue;
    // Another type: OGR's conversion, as when GDAL writes the feature.
    if (!scratch) {
      defn.reset(new OGRFeatureDefn());
      defn->Reference();
      for (const Column& col : columns) {
        OGRFieldDefn field(col.name.c_str(), ogrFieldType(col.type));
        defn->AddFieldDefn(&field);
      }
      scratch = std::make_unique<OGRFeature>(defn.get());
    }
    const int idx = static_cast<int>(c);
    if (const auto* n = std::get_if<std::int64_t>(&v)) {
      scratch->SetField(idx, static_cast<GIntBig>(*n));
    } else if (d) {
      scratch->SetField(idx, *d);
    } else {
      scratch->SetField(idx, std::get<std::string>(v).c_str());
    }
    if (type == Column::Type::Integer) {
      v = static_cast<std::int64_t>(scratch->GetFieldAsInteger64(idx));
    } else if (type == Column::Type::Real) {
      v = scratch->GetFieldAsDouble(idx);
    } else {
      v = std::string(scratch->GetFieldAsString(idx));
    }
  }
}

std::int32_t gpkgSrsId(const std::string& path, const std::string& table) {
  const Connection db(path, SQLITE_OPEN_READONLY, "");
  Stmt s = db.prepare("SELECT srs_id FROM gpkg_geometry_columns WHERE lower(table_name) = lower(" +
                      sqlQuoted(table, '\'') + ")");
  if (sqlite3_step(s.get()) != SQLITE_ROW) throw db.fail("no geometry column for " + table);
  return sqlite3_column_int(s.get(), 0);
}

GpkgInsert insertGpkgFeatures(const std::string& path, const std::string& table, const std::string& geometryColumn,
                              const std::vector<Column>& columns, const std::function<bool(GpkgRow&)>& next,
                              const std::function<void(std::int64_t fid, const GpkgRow&)>& inserted) {
  Connection db(path, SQLITE_OPEN_READWRITE, "");
  const std::string tableName = sqlQuoted(table, '\'');
  db.exec("BEGIN");
  // The triggers that count features row by row: the count is set once.
  const std::vector<std::string> countTriggers =
      takeTriggers(db, "lower(tbl_name) = lower(" + tableName + ") AND name LIKE 'trigger_%_feature_count_%'");
  GpkgInsert done;
  const std::string rtree = "rtree_" + table + "_" + geometryColumn;
  const std::vector<std::string> rtreeInsert = takeTriggers(db, "name = " + sqlQuoted(rtree + "_insert", '\''));
  if (!rtreeInsert.empty()) {
    done.rtreeName = rtree;
    done.rtreeInsertTrigger = rtreeInsert.front();
  }
  std::string sql = "INSERT INTO " + sqlQuoted(table, '"') + " (" + sqlQuoted(geometryColumn, '"');
  for (const Column& c : columns) sql += ", " + sqlQuoted(c.name, '"');
  sql += ") VALUES (?";
  for (std::size_t c = 0; c < columns.size(); ++c) sql += ", ?";
  sql += ")";
  Stmt insert = db.prepare(sql);
  GpkgRow row;
  std::int64_t count = 0;
  Envelope extent;
  while (next(row)) {
    sqlite3_stmt* s = insert.get();
    sqlite3_bind_blob(s, 1, row.geometry.data(), static_cast<int>(row.geometry.size()), SQLITE_STATIC);
    for (std::size_t c = 0; c < row.values.size(); ++c) {
      const int at = static_cast<int>(c) + 2;
      const Value& v = row.values[c];
      if (const auto* n = std::get_if<std::int64_t>(&v)) {
        sqlite3_bind_int64(s, at, *n);
      } else if (const auto* d = std::get_if<double>(&v)) {
        if (std::isnan(*d)) {
          sqlite3_bind_null(s, at);
        } else {
          sqlite3_bind_double(s, at, *d);
        }
      } else {
        const std::string& text = std::get<std::string>(v);
        // Up to its first NUL, as GDAL binds a C string.
        sqlite3_bind_text(s, at, text.c_str(), -1, SQLITE_STATIC);
      }
    }
    if (sqlite3_step(s) != SQLITE_DONE) throw db.fail("cannot write feature " + std::to_string(count));
    sqlite3_reset(s);
    const std::int64_t fid = sqlite3_last_insert_rowid(db.get());
    ++count;
    extent.merge(row.envelope);
    if (inserted) inserted(fid, row);
  }
  insert.reset();
  // As GDAL: a layer without features keeps its count (NULL) and its time.
  if (count > 0) {
    Stmt s =
        db.prepare("UPDATE gpkg_ogr_contents SET feature_count = ? WHERE lower(table_name) = lower(" + tableName + ")");
    sqlite3_bind_int64(s.get(), 1, count);
    if (sqlite3_step(s.get()) != SQLITE_DONE) throw db.fail("cannot record the feature count");
  }
  if (!extent.empty) {
    // As GDAL records it: the numbers printed by SQLite's printf (%.18g),
    // which does not always give back the same double.
    char* update = sqlite3_mprintf(
        "UPDATE gpkg_contents SET min_x = %.18g, min_y = %.18g, max_x = %.18g, max_y = %.18g "
        "WHERE lower(table_name) = lower('%q') AND lower(data_type) = 'features'",
        extent.minx, extent.miny, extent.maxx, extent.maxy, table.c_str());
    if (!update) throw db.fail("cannot record the layer's extent");
    const std::string text(update);
    sqlite3_free(update);
    db.exec(text);
  }
  if (count > 0) {
    // The time of the change, or the one GDAL is told to write (OGR_CURRENT_DATE).
    const char* fixed = CPLGetConfigOption("OGR_CURRENT_DATE", nullptr);
    db.exec("UPDATE gpkg_contents SET last_change = " +
            (fixed ? sqlQuoted(fixed, '\'') : std::string("strftime('%Y-%m-%dT%H:%M:%fZ', 'now')")) +
            " WHERE lower(table_name) = lower(" + tableName + ")");
  }
  for (const std::string& t : countTriggers) db.exec(t);
  db.exec("COMMIT");
  db.close("cannot close after writing features");
  return done;
}

}  // namespace parcelscope::io::detail
