// Generated parcels as users read them: written in a geographic CRS (where
// edges straight in metres are not straight, and points closer than about
// 1e-9 m merge), read back with GDAL, every one valid with a positive area,
// and together still the block's area. Randomised shapes (convex, star, L, U,
// comb, holes, near-degenerate) at several latitudes, every style.
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <cmath>
#include <random>

#include "TestUtil.h"
#include "generation/RandomShapes.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/io/LocalFrame.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/StatsJob.h"

namespace parcelscope {
namespace {

using namespace generation;

// Area in square degrees of a polygon mapped to lon/lat vertex by vertex, as a
// GIS computes it from the file.
double mappedArea(const Polygon& p, const io::LocalFrame& frame) {
  auto ringArea = [&](const Ring& r) {
    Ring m;
    for (const Point& q : r) m.push_back(frame.toSource(q));
    return std::fabs(signedArea(m));
  };
  double a = ringArea(p.outer);
  for (const Ring& h : p.holes) a -= ringArea(h);
  return a;
}

TEST(WrittenParcels, RandomShapesStayValidThroughAGeographicCrs) {
  constexpr std::uint64_t kSeed = 20261125;
  std::mt19937_64 rng(kSeed);
  const ParameterValues defaults = defaultValues(generationParameterDescriptions());
  int shapes = 0, repaired = 0;
  for (const double lat : {0.0, 42.38, 61.2, -33.9}) {
    const io::LocalFrame frame = io::LocalFrame::geographic(lat * 1.7, lat);
    io::CrsInfo crs;
    crs.assumedLonLat = true;
    for (int k = 0; k < 21 / test::kSanitizerDivisor; ++k, ++shapes) {
      const Polygon block = test::randomShape(rng, k % test::kShapeKinds);
      const ObbParameters b = test::randomBounds(rng, area(block));
      ParameterValues values = defaults;
      values["a-min"] = b.aMin;
      values["a-max"] = b.aMax;
      values["w-min"] = b.wMin;
      values["w-max"] = b.wMax;
      values["omega"] = b.omega;
      const std::uint64_t seed = rng();
      for (const char* name : {"obb", "skeleton", "offset", "parish", "sexton", "template"}) {
        SCOPED_TRACE(testing::Message() << "seed " << kSeed << ", latitude " << lat << ", shape " << k << ", style "
                                        << name);
        const Style& s = style(name);
        const Subdivision out = s.subdivide({block, styleValues(s, values), seed, {}});
        ASSERT_FALSE(out.parcels.empty());
        std::vector<std::vector<Polygon>> geometries;
        Table attributes;
        attributes.columns = {{"i", Column::Type::Integer, ""}};
        for (const Polygon& p : out.parcels) {
          EXPECT_GE(2 * area(p) / perimeter(p), 1e-3) << "a sliver";
          attributes.rows.push_back({static_cast<std::int64_t>(geometries.size())});
          geometries.push_back({p});
        }
        test::TempDir dir;
        const std::string path = dir.file("parcels.gpkg");
        const io::LayerWrite written = io::writePolygonLayer(path, "parcels", geometries, attributes, frame, crs);
        repaired += static_cast<int>(written.repaired);
        EXPECT_EQ(written.emptied, 0);

        GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
        ASSERT_TRUE(ds);
        OGRLayer* layer = ds->GetLayer(0);
        ASSERT_EQ(layer->GetFeatureCount(), static_cast<GIntBig>(geometries.size()));
        double sum = 0;
        for (auto& f : *layer) {
          const OGRGeometry* g = f->GetGeometryRef();
          ASSERT_NE(g, nullptr);
          const double a = g->toMultiPolygon()->get_Area();
          EXPECT_GT(a, 0) << "parcel " << f->GetFieldAsInteger64("i");
          EXPECT_TRUE(g->IsValid()) << "parcel " << f->GetFieldAsInteger64("i");
          sum += a;
        }
        // Shared vertices map to the same point: the written parcels still
        // tile the block's written outline, up to where a parcel puts a vertex
        // on a block's edge: the parcels follow the edge's image there, the
        // block's chord does not (a 300 m edge bows by about 2 mm at 60
        // degrees, 1e-5 of a block 300 m deep).
        const double blockArea = mappedArea(block, frame);
        EXPECT_NEAR(sum, blockArea, 1e-4 * blockArea);
      }
    }
  }
  std::printf("%d shapes x 3 styles at 4 latitudes: %d parcels repaired in the CRS written\n", shapes, repaired);
}

// Self-intersecting parcels (the reader repairs them into their parts) that
// overlap their neighbours: block outlines are unions and closings of such
// parts, whose crumbs merge in degrees. Every outline is valid in metres, and
// in the file `stats` writes.
TEST(WrittenBlocks, OutlinesOfRepairedParcelsAreValidInTheFile) {
  constexpr std::uint64_t kSeed = 5;
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> u(0, 1);
  std::string features;
  for (int i = 0; i < 150; ++i) {
    const double cx = -71.1 + 0.01 * u(rng), cy = 42.38 + 0.01 * u(rng), size = 5e-5 + 4.5e-4 * u(rng);
    const int n = 4 + static_cast<int>(9 * u(rng));
    std::string ring;
    char first[64] = "";
    for (int k = 0; k < n; ++k) {
      char xy[64];
      std::snprintf(xy, sizeof xy, "[%.9f,%.9f]", cx + size * (2 * u(rng) - 1), cy + size * (2 * u(rng) - 1));
      if (k == 0) std::snprintf(first, sizeof first, "%s", xy);
      ring += std::string(xy) + ",";
    }
    features += std::string(i ? "," : "") + R"({"type":"Feature","properties":{"id":)" + std::to_string(i) +
                R"(},"geometry":{"type":"Polygon","coordinates":[[)" + ring + first + "]]}}";
  }
  test::TempDir dir;
  io::ReadOptions input;
  input.path = dir.write("random.geojson", R"({"type":"FeatureCollection","features":[)" + features + "]}");
  const ParameterValues values = defaultValues(analysis::analysisParameters());

  const pipeline::ObservedData observed = pipeline::loadObserved(input, values);
  int invalidInMetres = 0;
  for (const Block& b : observed.analysis.blocks)
    for (const Polygon& part : b.parts) invalidInMetres += !geos::isValid(part);
  EXPECT_EQ(invalidInMetres, 0);

  const std::string out = (dir.path() / "stats").string();
  pipeline::runStats(input, values, out);
  GDALDatasetUniquePtr ds(GDALDataset::Open((out + "/blocks.gpkg").c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(ds);
  OGRLayer* layer = ds->GetLayer(0);
  ASSERT_EQ(layer->GetFeatureCount(), static_cast<GIntBig>(observed.analysis.blocks.size()));
  int invalidWritten = 0, emptyWritten = 0;
  for (auto& f : *layer) {
    const OGRGeometry* g = f->GetGeometryRef();
    const bool empty = !g || g->IsEmpty() || g->toMultiPolygon()->get_Area() <= 0;
    emptyWritten += empty;
    invalidWritten += !empty && !g->IsValid();
  }
  EXPECT_EQ(invalidWritten, 0);
  EXPECT_EQ(emptyWritten, 0);
}

}  // namespace
}  // namespace parcelscope
