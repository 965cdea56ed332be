// The R-tree of a written GeoPackage layer, built in bulk: checked by SQLite,
// against the features' envelopes, and against GDAL's own index of the same
// features through spatial filters.
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>
#include <sqlite3.h>

#include <cmath>
#include <random>
#include <set>

#include "TestUtil.h"
#include "parcelscope/io/Writers.h"

namespace parcelscope::io {
namespace {

using test::TempDir;

// One SQL value of the file at `path` (a fresh connection, read-only).
std::string sqlValue(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  std::string value = "<error>";
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) == SQLITE_OK && sqlite3_step(s) == SQLITE_ROW) {
    const unsigned char* text = sqlite3_column_text(s, 0);
    value = text ? reinterpret_cast<const char*>(text) : "";
  } else {
    ADD_FAILURE() << sql << ": " << sqlite3_errmsg(db);
  }
  sqlite3_finalize(s);
  sqlite3_close(db);
  return value;
}

// `n` random polygons (rectangles and triangles, a few metres to a few hundred
// metres, some overlapping) over about 10 km, and `empty` features without a
// polygon, which the index leaves out (as GDAL's triggers do).
std::vector<std::vector<Polygon>> randomShapes(std::size_t n, std::size_t empty, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> at(-5000, 5000), size(2, 300), unit(0, 1);
  std::vector<std::vector<Polygon>> shapes;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = at(rng), y = at(rng), w = size(rng), h = size(rng);
    Polygon p;
    if (unit(rng) < 0.5) {
      p.outer = {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}};
    } else {
      p.outer = {{x, y}, {x + w, y + unit(rng) * h}, {x + unit(rng) * w, y + h}};
    }
    shapes.push_back({p});
  }
  for (std::size_t i = 0; i < empty; ++i) {
    shapes.insert(shapes.begin() + static_cast<std::ptrdiff_t>(i * 7 % (shapes.size() + 1)), std::vector<Polygon>{});
  }
  return shapes;
}

std::string writeShapes(const TempDir& dir, const std::string& name, const std::vector<std::vector<Polygon>>& shapes,
                        bool spatialIndex) {
  const LocalFrame frame = LocalFrame::geographic(-71.1, 42.37);
  CrsInfo crs;
  crs.assumedLonLat = true;
  Table attrs;
  attrs.columns = {{"n", Column::Type::Integer, ""}};
  for (std::size_t i = 0; i < shapes.size(); ++i) attrs.rows.push_back({static_cast<std::int64_t>(i)});
  const std::string path = dir.file(name);
  writePolygonLayer(path, "parcels", shapes, attrs, frame, crs, spatialIndex);
  return path;
}

// The fids GDAL returns for a rectangle filter.
std::set<GIntBig> filtered(const std::string& path, double x0, double y0, double x1, double y1) {
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  OGRLayer* layer = ds->GetLayerByName("parcels");
  layer->SetSpatialFilterRect(x0, y0, x1, y1);
  std::set<GIntBig> fids;
  for (const auto& f : *layer) fids.insert(f->GetFID());
  return fids;
}

class SpatialIndex : public ::testing::TestWithParam<std::size_t> {};

// Sizes around the node capacity (51 boxes a node): a root that is a leaf, two
// levels, three levels.
INSTANTIATE_TEST_SUITE_P(Sizes, SpatialIndex, ::testing::Values(1, 51, 52, 2601, 6000));

TEST_P(SpatialIndex, IsValidHoldsEveryEnvelopeAndAnswersFiltersAsGdalsOwn) {
  TempDir dir;
  const std::size_t n = GetParam();
  const auto shapes = randomShapes(n, n > 100 ? 5 : 0, static_cast<unsigned>(n));
  const std::string path = writeShapes(dir, "bulk.gpkg", shapes, true);

  EXPECT_EQ(sqlValue(path, "SELECT rtreecheck('rtree_parcels_geom')"), "ok");
  const auto indexed = static_cast<std::size_t>(std::stoll(sqlValue(path, "SELECT count(*) FROM rtree_parcels_geom")));
  EXPECT_EQ(indexed, n);
  // GDAL's triggers and extension entry are all there.
  EXPECT_EQ(
      sqlValue(path, "SELECT count(*) FROM sqlite_master WHERE type = 'trigger' AND name LIKE 'rtree_parcels_geom_%'"),
      "6");
  EXPECT_EQ(sqlValue(path,
                     "SELECT count(*) FROM gpkg_extensions WHERE table_name = 'parcels' AND "
                     "extension_name = 'gpkg_rtree_index'"),
            "1");

  // Each non-empty feature's box holds its envelope, within single-precision rounding.
  {
    GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
    OGRLayer* layer = ds->GetLayerByName("parcels");
    std::size_t checked = 0;
    for (const auto& f : *layer) {
      const OGRGeometry* g = f->GetGeometryRef();
      if (!g || g->IsEmpty()) continue;
      OGREnvelope e;
      g->getEnvelope(&e);
      OGRLayer* r = ds->ExecuteSQL(
          ("SELECT minx, maxx, miny, maxy FROM rtree_parcels_geom WHERE id = " + std::to_string(f->GetFID())).c_str(),
          nullptr, nullptr);
      ASSERT_NE(r, nullptr);
      auto box = std::unique_ptr<OGRFeature>(r->GetNextFeature());
      ASSERT_TRUE(box) << "feature " << f->GetFID() << " is not in the index";
      const double minx = box->GetFieldAsDouble(0), maxx = box->GetFieldAsDouble(1);
      const double miny = box->GetFieldAsDouble(2), maxy = box->GetFieldAsDouble(3);
      ds->ReleaseResultSet(r);
      EXPECT_LE(minx, e.MinX);
      EXPECT_GE(maxx, e.MaxX);
      EXPECT_LE(miny, e.MinY);
      EXPECT_GE(maxy, e.MaxY);
      EXPECT_LT(e.MinX - minx, 1e-5);  // a float step at 71 degrees is 7.6e-6
      EXPECT_LT(maxy - e.MaxY, 1e-5);
      ++checked;
      if (checked > 300) break;  // the SQL per feature is slow; the check above counts them all
    }
    EXPECT_GT(checked, 0u);
  }

  // The same features with GDAL's own index: every filter gives the same features.
  const std::string reference = writeShapes(dir, "gdal.gpkg", shapes, false);
  {
    GDALDatasetUniquePtr ds(GDALDataset::Open(reference.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE));
    ds->ExecuteSQL("SELECT CreateSpatialIndex('parcels', 'geom')", nullptr, nullptr);
  }
  ASSERT_EQ(sqlValue(reference, "SELECT count(*) FROM rtree_parcels_geom"), std::to_string(indexed));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> lon(-71.17, -71.03), lat(42.32, 42.42), span(0.0001, 0.05);
  std::size_t found = 0;
  for (int q = 0; q < 40; ++q) {
    const double x = lon(rng), y = lat(rng), x1 = x + span(rng), y1 = y + span(rng);
    const auto ours = filtered(path, x, y, x1, y1);
    EXPECT_EQ(ours, filtered(reference, x, y, x1, y1)) << "filter " << x << " " << y << " " << x1 << " " << y1;
    found += ours.size();
  }
  if (n > 1000) {
    EXPECT_GT(found, 40u);  // the filters are not all empty
  }
}

// After the bulk build, GDAL's insert trigger is back: a feature added later
// is found through the index.
TEST(SpatialIndexTrigger, AFeatureAddedLaterIsIndexed) {
  TempDir dir;
  const std::string path = writeShapes(dir, "bulk.gpkg", randomShapes(200, 0, 3), true);
  {
    GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE));
    OGRLayer* layer = ds->GetLayerByName("parcels");
    OGRFeature f(layer->GetLayerDefn());
    OGRPolygon square;
    OGRLinearRing ring;
    ring.addPoint(10.0, 10.0);
    ring.addPoint(10.001, 10.0);
    ring.addPoint(10.001, 10.001);
    ring.addPoint(10.0, 10.001);
    ring.closeRings();
    square.addRing(&ring);
    OGRMultiPolygon multi;
    multi.addGeometry(&square);
    f.SetGeometry(&multi);
    ASSERT_EQ(layer->CreateFeature(&f), OGRERR_NONE);
  }
  EXPECT_EQ(sqlValue(path, "SELECT count(*) FROM rtree_parcels_geom"), "201");
  EXPECT_EQ(sqlValue(path, "SELECT rtreecheck('rtree_parcels_geom')"), "ok");
  EXPECT_EQ(filtered(path, 9.99, 9.99, 10.01, 10.01).size(), 1u);
}

}  // namespace
}  // namespace parcelscope::io
