#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <GeographicLib/Geodesic.hpp>
#include <filesystem>
#include <fstream>

#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/io/GeometryOps.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"

namespace parcelscope::io {
namespace {

using test::rect;
using test::TempDir;
namespace fs = std::filesystem;

TEST(OutputDirectory, FilesAppearOnlyOnCommit) {
  TempDir dir;
  const std::string target = dir.file("out");
  {
    OutputDirectory out(target, {});
    std::ofstream(out.stage("a.csv")) << "x\n";
    EXPECT_FALSE(fs::exists(target));
  }  // no commit: nothing appears, staging removed
  EXPECT_FALSE(fs::exists(target));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 0);
  {
    OutputDirectory out(target, {});
    std::ofstream(out.stage("a.csv")) << "x\n";
    out.commit();
  }
  EXPECT_TRUE(fs::exists(target + "/a.csv"));
  {
    OutputDirectory again(target, {});  // existing folder: files move in one by one
    std::ofstream(again.stage("b.csv")) << "y\n";
    again.commit();
  }
  EXPECT_TRUE(fs::exists(target + "/a.csv"));
  EXPECT_TRUE(fs::exists(target + "/b.csv"));
}

TEST(OutputDirectory, FilesInSubfoldersMoveIntoNewAndExistingTargets) {
  TempDir dir;
  const std::string target = dir.file("out");
  for (const char* name : {"figures/a.png", "figures/b.png"}) {
    OutputDirectory out(target, {});  // first run: the folder is renamed; second: files move one by one
    std::ofstream(out.stage(name)) << name;
    out.commit();
  }
  EXPECT_TRUE(fs::exists(target + "/figures/a.png"));
  EXPECT_TRUE(fs::exists(target + "/figures/b.png"));
}

TEST(OutputDirectory, StagingOfAKilledRunIsRemovedByTheNext) {
  TempDir dir;
  const fs::path stale = dir.path() / ".out.partial-999999999";  // no such process
  fs::create_directories(stale);
  std::ofstream((stale / "parcels.csv").string()) << "x\n";
  {
    OutputDirectory out(dir.file("out"), {});
    out.commit();
  }
  EXPECT_FALSE(fs::exists(stale));
}

TEST(OutputDirectory, NeverOverwritesAnInput) {
  TempDir dir;
  const auto input = dir.write("parcels.csv", "x\n");
  EXPECT_THROW(OutputDirectory(input, {input}), Error);
  OutputDirectory out(dir.path().string(), {input});
  EXPECT_THROW(out.stage("parcels.csv"), Error);
}

TEST(Writers, PolygonLayerGoesBackToTheInputCrs) {
  TempDir dir;
  const LocalFrame frame = LocalFrame::geographic(2.35, 48.85);
  CrsInfo crs;
  crs.assumedLonLat = true;  // no WKT: written as OGC:CRS84
  Table attrs;
  attrs.columns = {{"block_id", Column::Type::Integer, ""}, {"area", Column::Type::Real, "m2"}};
  attrs.rows = {{std::int64_t(7), 100.0}};
  const std::string path = dir.file("blocks.gpkg");
  writePolygonLayer(path, "blocks", {{rect(0, 0, 10, 10)}}, attrs, frame, crs);

  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(ds);
  OGRLayer* layer = ds->GetLayerByName("blocks");
  ASSERT_NE(layer, nullptr);
  ASSERT_EQ(layer->GetFeatureCount(), 1);
  auto f = std::unique_ptr<OGRFeature>(layer->GetNextFeature());
  EXPECT_EQ(f->GetFieldAsInteger64("block_id"), 7);
  OGREnvelope e;
  f->GetGeometryRef()->getEnvelope(&e);
  EXPECT_NEAR(e.MinX, 2.35, 1e-9);
  EXPECT_NEAR(e.MinY, 48.85, 1e-9);
  double lat2 = 0, lon2 = 0;  // 10 m east of the frame's centre along a geodesic
  GeographicLib::Geodesic::WGS84().Direct(48.85, 2.35, 90.0, 10.0, lat2, lon2);
  EXPECT_NEAR(e.MaxX - e.MinX, lon2 - 2.35, 1e-9);  // 0.07 mm
  ASSERT_NE(layer->GetSpatialRef(), nullptr);
  EXPECT_TRUE(layer->GetSpatialRef()->IsGeographic());
}

TEST(GeometryOps, UnionClosesGapsNarrowerThanTheTolerance) {
  const Polygon a = rect(0, 0, 10, 10), b = rect(10.4, 0, 20, 10), c = rect(30, 0, 40, 10);
  const auto joined = unionAndClose({&a, &b}, 1.0);
  ASSERT_EQ(joined.size(), 1u);
  EXPECT_NEAR(area(joined[0]), 100.0 + 96.0 + 0.4 * 10, 1e-6);  // both lots and the closed gap
  EXPECT_EQ(unionAndClose({&a, &c}, 1.0).size(), 2u);
  // Holes wider than the tolerance are kept.
  const Polygon ring1 = rect(0, 0, 30, 10), ring2 = rect(0, 20, 30, 30), ring3 = rect(0, 10, 10, 20),
                ring4 = rect(20, 10, 30, 20);
  const auto courtyard = unionAndClose({&ring1, &ring2, &ring3, &ring4}, 1.0);
  ASSERT_EQ(courtyard.size(), 1u);
  EXPECT_EQ(courtyard[0].holes.size(), 1u);
  EXPECT_NEAR(area(courtyard[0]), 800.0, 1e-6);
}

TEST(GeometryOps, ValidityAndIntersection) {
  EXPECT_TRUE(isValid(rect(0, 0, 1, 1)));
  EXPECT_FALSE(isValid(test::poly({{0, 0}, {1, 1}, {1, 0}, {0, 1}})));
  EXPECT_NEAR(intersectionArea(rect(0, 0, 2, 2), rect(1, 1, 3, 3)), 1.0, 1e-12);
}

}  // namespace
}  // namespace parcelscope::io
