// GeoPackage rows written through SQLite (io/src/GpkgFeatures): the bytes and
// values GDAL writes for the same features, feature by feature.
#include "GpkgFeatures.h"

#include <cpl_conv.h>
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>
#include <sqlite3.h>

#include <cmath>
#include <limits>
#include <random>

#include "OgrConvert.h"
#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/io/Writers.h"

namespace parcelscope::io {
namespace {

using test::TempDir;

// Random features: one to three parts, some with holes, some empty.
std::vector<std::vector<Polygon>> randomFeatures(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> at(-3000, 3000), size(5, 200), unit(0, 1);
  std::vector<std::vector<Polygon>> features;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<Polygon> parts;
    const int count = unit(rng) < 0.1 ? 0 : 1 + static_cast<int>(unit(rng) * 3);
    for (int k = 0; k < count; ++k) {
      const double x = at(rng), y = at(rng), w = size(rng), h = size(rng);
      Polygon p;
      p.outer = {{x, y}, {x + w, y + 0.1 * h * unit(rng)}, {x + w, y + h}, {x + 0.3 * w * unit(rng), y + h}};
      if (unit(rng) < 0.3) {
        p.holes.push_back({{x + 0.4 * w, y + 0.4 * h}, {x + 0.4 * w, y + 0.6 * h}, {x + 0.6 * w, y + 0.6 * h}});
      }
      parts.push_back(p);
    }
    features.push_back(parts);
  }
  return features;
}

TEST(GpkgFeatures, WkbAndEnvelopeAreOgrsOwn) {
  const auto features = randomFeatures(300, 3);
  std::size_t withHoles = 0, empty = 0;
  for (const auto& parts : features) {
    std::string wkb;
    detail::appendMultiPolygonWkb(wkb, parts);
    const auto ogr = detail::toOgr(parts);
    std::string expected(static_cast<std::size_t>(ogr->WkbSize()), '\0');
    ogr->exportToWkb(wkbNDR, reinterpret_cast<unsigned char*>(expected.data()), wkbVariantIso);
    EXPECT_EQ(wkb, expected);
    const detail::Envelope e = detail::multiPolygonWkbEnvelope(wkb);
    EXPECT_EQ(e.empty, ogr->IsEmpty() == TRUE);
    if (!e.empty) {
      OGREnvelope o;
      ogr->getEnvelope(&o);
      EXPECT_EQ(e.minx, o.MinX);
      EXPECT_EQ(e.maxx, o.MaxX);
      EXPECT_EQ(e.miny, o.MinY);
      EXPECT_EQ(e.maxy, o.MaxY);
    }
    empty += parts.empty();
    for (const Polygon& p : parts) withHoles += !p.holes.empty();
  }
  EXPECT_GT(withHoles, 10u);
  EXPECT_GT(empty, 10u);
  EXPECT_THROW(detail::multiPolygonWkbEnvelope(std::string("\x01\x03\x00\x00\x00\x00\x00\x00\x00", 9)),
               std::logic_error);
  EXPECT_THROW(detail::multiPolygonWkbEnvelope(std::string("\x01\x06\x00\x00\x00\x01\x00\x00", 8)), std::logic_error);
}

// Every row of `table` (fid, geometry blob, fields with their storage class),
// gpkg_contents' extent and gpkg_ogr_contents' count, as text.
std::vector<std::string> dump(const std::string& path, const std::string& table) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  std::vector<std::string> rows;
  auto query = [&](const std::string& sql) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) != SQLITE_OK) {
      ADD_FAILURE() << sql << ": " << sqlite3_errmsg(db);
      return;
    }
    while (sqlite3_step(s) == SQLITE_ROW) {
      std::string row;
      for (int c = 0; c < sqlite3_column_count(s); ++c) {
        const int type = sqlite3_column_type(s, c);
        row += std::to_string(type) + ":";
        if (type == SQLITE_FLOAT) {
          char buf[40];
          std::snprintf(buf, sizeof buf, "%a", sqlite3_column_double(s, c));  // every bit
          row += buf;
        } else if (type != SQLITE_NULL) {
          row += std::string(static_cast<const char*>(sqlite3_column_blob(s, c)),
                             static_cast<std::size_t>(sqlite3_column_bytes(s, c)));
        }
        row += "|";
      }
      rows.push_back(row);
    }
    sqlite3_finalize(s);
  };
  query("SELECT * FROM \"" + table + "\" ORDER BY fid");
  query("SELECT min_x, min_y, max_x, max_y, srs_id, last_change FROM gpkg_contents WHERE table_name = '" + table + "'");
  query("SELECT feature_count FROM gpkg_ogr_contents WHERE table_name = '" + table + "'");
  sqlite3_close(db);
  return rows;
}

// Writes `features` with writePolygonLayer and, feature by feature, with
// GDAL's CreateFeature; returns both files' dumps. The time of the change is
// fixed (OGR_CURRENT_DATE) so that it is compared too.
std::pair<std::vector<std::string>, std::vector<std::string>> writeBoth(
    const TempDir& dir, const std::vector<std::vector<Polygon>>& features) {
  CPLSetConfigOption("OGR_CURRENT_DATE", "2000-01-02T03:04:05.000Z");
  const LocalFrame frame = LocalFrame::geographic(2.35, 48.89);
  CrsInfo crs;
  crs.assumedLonLat = true;
  // Values of every kind in every column, including those OGR converts.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Value> ints = {std::int64_t{7}, std::int64_t{-3}, 3.7, -2.5e30, std::string("17"), nan,
                                   std::string("x")};
  const std::vector<Value> reals = {0.1, 1e300, -0.0, std::int64_t{5}, std::string("2.5"), nan};
  const std::vector<Value> texts = {
      std::string("a,\"b\""),  std::string("\xc3\xa9t\xc3\xa9"), std::string(), 0.1, std::int64_t{12}, nan,
      std::string("ab\0cd", 5)};
  RowSource rows;
  rows.columns = {{"n", Column::Type::Integer, ""}, {"x", Column::Type::Real, ""}, {"s", Column::Type::String, ""}};
  rows.rows = features.size();
  rows.row = [&](std::size_t i, std::vector<Value>& out) {
    out = {ints[i % ints.size()], reals[i % reals.size()], texts[i % texts.size()]};
  };
  const std::string ours = dir.file("ours.gpkg");
  const LayerWrite written = writePolygonLayer(
      ours, "parcels", [&](std::size_t i, std::vector<Polygon>& parts) { parts = features[i]; }, rows, frame, crs);
  EXPECT_EQ(written.features, static_cast<std::int64_t>(features.size()));

  // The same features through OGR, one CreateFeature each.
  const std::string gdals = dir.file("gdal.gpkg");
  {
    GDALDatasetUniquePtr ds(
        GetGDALDriverManager()->GetDriverByName("GPKG")->Create(gdals.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    EXPECT_TRUE(ds);
    OGRSpatialReference srs;
    srs.SetFromUserInput("OGC:CRS84");
    srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    OGRLayer* layer = ds->CreateLayer("parcels", &srs, wkbMultiPolygon, nullptr);
    EXPECT_NE(layer, nullptr);
    for (const auto& [name, type] : {std::pair{"n", OFTInteger64}, {"x", OFTReal}, {"s", OFTString}}) {
      OGRFieldDefn field(name, type);
      EXPECT_EQ(layer->CreateField(&field), OGRERR_NONE);
    }
    EXPECT_EQ(ds->StartTransaction(), OGRERR_NONE);
    std::vector<Value> row;
    for (std::size_t i = 0; i < features.size(); ++i) {
      OGRFeature f(layer->GetLayerDefn());
      rows.row(i, row);
      for (int c = 0; c < 3; ++c) {
        const Value& v = row[static_cast<std::size_t>(c)];
        if (const auto* n = std::get_if<std::int64_t>(&v)) {
          f.SetField(c, static_cast<GIntBig>(*n));
        } else if (const auto* d = std::get_if<double>(&v)) {
          if (std::isnan(*d)) {
            f.SetFieldNull(c);
          } else {
            f.SetField(c, *d);
          }
        } else {
          f.SetField(c, std::get<std::string>(v).c_str());
        }
      }
      const FileGeometry g = fileGeometry(features[i], frame);
      OGRGeometry* geometry = nullptr;
      EXPECT_EQ(OGRGeometryFactory::createFromWkb(g.wkb.data(), nullptr, &geometry, g.wkb.size()), OGRERR_NONE);
      f.SetGeometryDirectly(geometry);
      EXPECT_EQ(layer->CreateFeature(&f), OGRERR_NONE);
    }
    EXPECT_EQ(ds->CommitTransaction(), OGRERR_NONE);
  }
  CPLSetConfigOption("OGR_CURRENT_DATE", nullptr);
  return {dump(ours, "parcels"), dump(gdals, "parcels")};
}

TEST(GpkgFeatures, RowsAreTheOnesGdalWritesFeatureByFeature) {
  TempDir dir;
  const auto features = randomFeatures(700, 11);
  const auto [a, b] = writeBoth(dir, features);
  ASSERT_EQ(a.size(), features.size() + 2);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << "row " << i;
  EXPECT_NE(a.back().find("700"), std::string::npos);  // the feature count
}

TEST(GpkgFeatures, ALayerWithoutFeaturesIsLeftAsGdalLeavesIt) {
  TempDir dir;
  const auto [a, b] = writeBoth(dir, {});
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a, b);  // no extent, the time of its making, a NULL count
}

TEST(GpkgFeatures, AFailureWhilePreparingComesOutAsThrown) {
  TempDir dir;
  const auto features = randomFeatures(20000, 5);
  RowSource rows;
  rows.columns = {{"n", Column::Type::Integer, ""}};
  rows.rows = features.size();
  rows.row = [](std::size_t i, std::vector<Value>& out) {
    if (i == 9000) throw inputError("row 9000 cannot be made");
    out = {static_cast<std::int64_t>(i)};
  };
  CrsInfo crs;
  crs.assumedLonLat = true;
  try {
    writePolygonLayer(
        dir.file("failed.gpkg"), "parcels", [&](std::size_t i, std::vector<Polygon>& parts) { parts = features[i]; },
        rows, LocalFrame::geographic(2.35, 48.89), crs);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("row 9000 cannot be made"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace parcelscope::io
