#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <GeographicLib/Geodesic.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>

#include "OgrTestUtil.h"
#include "TestUtil.h"
#include "parcelscope/core/Error.h"
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

TEST(StagedFile, AppearsOnlyOnCommitAndNeverOverwritesAnInput) {
  TempDir dir;
  const std::string target = dir.file("figure.png");
  {
    StagedFile f(target, {});
    EXPECT_EQ(fs::path(f.path()).extension(), ".png");
    EXPECT_EQ(fs::path(f.path()).parent_path(), dir.path());
    std::ofstream(f.path()) << "half";
    EXPECT_FALSE(fs::exists(target));
  }  // not committed: nothing left behind
  EXPECT_FALSE(fs::exists(target));
  EXPECT_TRUE(fs::is_empty(dir.path()));
  {
    StagedFile f(target, {});
    std::ofstream(f.path()) << "whole";
    f.commit();
  }
  EXPECT_EQ(test::slurpFile(target), "whole");
  const std::string input = dir.write("input.geojson", "{}");
  EXPECT_THROW(StagedFile(input, {input}), Error);
  EXPECT_THROW(StagedFile(dir.path().string(), {}), Error);
  EXPECT_THROW(StagedFile(dir.file("missing/x.png"), {}), Error);
}

TEST(Writers, ReadJsonKeepsTypesAndOrderAndNamesTheFileOnError) {
  TempDir dir;
  const std::string path =
      dir.write("a.json", R"({"b": 1, "a": [2.5, "x", true, null], "c": {"d": -3}})");
  const Json j = readJson(path);
  const auto members = j.members();
  ASSERT_EQ(members.size(), 3u);
  EXPECT_EQ(members[0].first, "b");
  EXPECT_EQ(j.find("b")->number(), 1);
  const auto a = j.find("a")->elements();
  ASSERT_EQ(a.size(), 4u);
  EXPECT_EQ(a[0].number(), 2.5);
  EXPECT_EQ(a[1].string(), "x");
  EXPECT_TRUE(a[2].boolean());
  EXPECT_TRUE(a[3].isNull());
  EXPECT_EQ(j.find("c")->find("d")->number(), -3);
  EXPECT_EQ(j.find("z"), nullptr);
  const std::string bad = dir.write("bad.json", "{\"a\": ");
  try {
    readJson(bad);
    FAIL() << "expected Error(Input)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Input);
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos);
  }
  EXPECT_THROW(readJson(dir.file("none.json")), Error);
}

TEST(Writers, PolygonLayerAsGeoJson) {
  TempDir dir;
  const LocalFrame frame = LocalFrame::geographic(2.35, 48.85);
  CrsInfo crs;
  crs.assumedLonLat = true;
  Table attrs;
  attrs.columns = {{"block_id", Column::Type::Integer, ""}};
  attrs.rows = {{std::int64_t(3)}, {std::int64_t(4)}};
  const std::string path = dir.file("parcels.geojson");
  writePolygonLayer(path, "parcels", {{rect(0, 0, 10, 10)}, {rect(10, 0, 20, 10)}}, attrs, frame, crs);
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(ds);
  EXPECT_STREQ(ds->GetDriver()->GetDescription(), "GeoJSON");
  OGRLayer* layer = ds->GetLayer(0);
  ASSERT_EQ(layer->GetFeatureCount(), 2);
  auto f = std::unique_ptr<OGRFeature>(layer->GetNextFeature());
  EXPECT_EQ(f->GetFieldAsInteger64("block_id"), 3);
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

}  // namespace
}  // namespace parcelscope::io
