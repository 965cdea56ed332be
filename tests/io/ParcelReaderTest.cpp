#include "parcelscope/io/ParcelReader.h"

#include <gdal_priv.h>
#include <gdal_utils.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <sstream>

#include <fstream>
#include <functional>
#include <random>
#include <set>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <cmath>

#include "TestUtil.h"
#include "io/Fixtures.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::io {
namespace {

using test::TempDir;

ReadOptions options(std::string path, std::string layer = "", std::string where = "", std::string crs = "") {
  ReadOptions o;
  o.path = std::move(path);
  o.layer = std::move(layer);
  o.where = std::move(where);
  o.crsOverride = std::move(crs);
  return o;
}

double totalArea(const ParcelLayer& l) {
  double a = 0;
  for (const auto& p : l.parcels) a += area(p.shape);
  return a;
}

// Expects readParcels to throw an Error of `kind` whose one-line message holds every `part`.
void expectError(const ReadOptions& options, Error::Kind kind, std::initializer_list<std::string> parts) {
  try {
    readParcels(options);
    ADD_FAILURE() << "no error for " << options.path;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    for (const auto& p : parts) EXPECT_NE(m.find(p), std::string::npos) << "'" << p << "' not in: " << m;
  }
}

// Converts `source` to `format` with GDAL's own translator (as ogr2ogr would).
std::string convert(const std::string& source, const std::string& target, const char* format) {
  GDALAllRegister();
  GDALDatasetH src = GDALOpenEx(source.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
  EXPECT_NE(src, nullptr);
  const char* argv[] = {"-f", format, "-skipfailures", "-nlt", "PROMOTE_TO_MULTI", nullptr};
  GDALVectorTranslateOptions* o = GDALVectorTranslateOptionsNew(const_cast<char**>(argv), nullptr);
  int usageError = 0;
  GDALDatasetH out = GDALVectorTranslate(target.c_str(), nullptr, 1, &src, o, &usageError);
  EXPECT_NE(out, nullptr) << format;
  GDALClose(out);
  GDALVectorTranslateOptionsFree(o);
  GDALClose(src);
  return target;
}

// 100 x 100 US survey feet in Washington State Plane South (EPSG:2286), stored
// without a CRS, so GeoJSON readers take it for lon/lat.
std::string feetGeoJson() {
  return test::collection(test::feature(
      R"({"type":"Polygon","coordinates":[[[1195000,565000],[1195100,565000],[1195100,565100],[1195000,565100],[1195000,565000]]]})",
      1));
}

TEST(ParcelReader, CleaningCountsEveryRepairSplitCollapseAndSkip) {
  TempDir dir;
  const auto path = dir.write("quirks.geojson", test::quirksGeoJson());
  const ParcelLayer l = readParcels(options(path, "", "", ""));
  const CleaningReport& r = l.report;
  EXPECT_EQ(r.features, 7);
  EXPECT_EQ(r.nullOrEmpty, 1);
  EXPECT_EQ(r.nonPolygonal, 1);
  EXPECT_EQ(r.duplicatesCollapsed, 1);
  EXPECT_EQ(r.duplicateStacks, 1);
  EXPECT_EQ(r.invalidRepaired, 1);    // the bow-tie, made valid as two triangles
  EXPECT_EQ(r.multipartFeatures, 1);  // the MultiPolygon; the repaired bow-tie is not one
  EXPECT_EQ(r.partsFromMultipart, 2);
  EXPECT_EQ(r.withHoles, 1);
  EXPECT_EQ(r.parcels, 6);
  ASSERT_EQ(l.parcels.size(), 6u);
  EXPECT_EQ(l.parcels[0].stackCount, 2);
  EXPECT_TRUE(l.crs.name.find("4326") != std::string::npos) << l.crs.name;
  for (const auto& p : l.parcels) {
    EXPECT_GT(signedArea(p.shape.outer), 0);
    for (const auto& h : p.shape.holes) EXPECT_LT(signedArea(h), 0);
  }
}

// A polygon with many holes (a street network stored as a parcel, its blocks
// the holes) is made valid without GEOS's union of the holes where they are
// disjoint polygons inside their shell, and as GEOS makes it valid otherwise:
// the same parts, holes and areas as GDAL's make-valid (structure method)
// gives, in each case.
TEST(ParcelReader, APolygonWithManyHolesIsMadeValidAsGeosWould) {
  const double lon = 2.35, lat = 48.85, d = 0.01, h = 0.0008;
  // 20 square holes in a 5 x 4 grid; `hole` may replace the ring of one.
  auto polygonWith = [&](const std::function<std::string(int, double, double)>& hole) {
    std::string rings = test::squareRing(lon, lat, d);
    for (int k = 0; k < 20; ++k) {
      const double x = lon + 0.001 + (k % 5) * 0.0018, y = lat + 0.001 + (k / 5) * 0.0022;
      rings += "," + hole(k, x, y);
    }
    return R"({"type":"Polygon","coordinates":[)" + rings + "]}";
  };
  auto ring = [](std::initializer_list<std::pair<double, double>> points) {
    std::ostringstream s;
    s.precision(12);
    s << "[";
    for (const auto& [x, y] : points) s << (s.tellp() > 1 ? "," : "") << "[" << x << "," << y << "]";
    return s.str() + "]";
  };
  struct Case {
    const char* what;
    std::string geometry;
  };
  const std::vector<Case> cases = {
      // A bow-tie hole: its two triangles, disjoint from the rest (the shortcut).
      {"bow-tie hole", polygonWith([&](int k, double x, double y) {
         return k == 7 ? ring({{x, y}, {x + h, y + h}, {x + h, y}, {x, y + h}, {x, y}})
                       : test::squareRing(x, y, h, true);
       })},
      // Two holes sharing an edge: GEOS unites them into one hole.
      {"holes sharing an edge", polygonWith([&](int k, double x, double y) {
         return k == 3 ? test::squareRing(x - 0.001, y, h, true) : test::squareRing(x, y, h, true);
       })},
      // A hole outside its shell: GEOS makes it a polygon of its own.
      {"hole outside", polygonWith([&](int k, double x, double y) {
         return k == 19 ? test::squareRing(lon + d + 0.001, lat, h, true) : test::squareRing(x, y, h, true);
       })},
      // A hole across the shell's edge: it cuts the shell.
      {"hole across the edge", polygonWith([&](int k, double x, double y) {
         return k == 0 ? test::squareRing(lon - h / 2, lat + 0.002, h, true) : test::squareRing(x, y, h, true);
       })},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    TempDir dir;
    const std::string path = dir.write("many.geojson", test::collection(test::feature(c.geometry, 1)));
    const ParcelLayer l = readParcels(options(path));
    // GDAL's own make-valid of the same feature, in lon/lat.
    GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
    ASSERT_TRUE(ds);
    OGRFeatureUniquePtr f(ds->GetLayer(0)->GetNextFeature());
    ASSERT_TRUE(f && f->GetGeometryRef());
    EXPECT_FALSE(f->GetGeometryRef()->IsValid());
    const char* const method[] = {"METHOD=STRUCTURE", nullptr};
    std::unique_ptr<OGRGeometry> fixed(f->GetGeometryRef()->MakeValid(method));
    ASSERT_TRUE(fixed);
    std::vector<const OGRPolygon*> parts;
    if (wkbFlatten(fixed->getGeometryType()) == wkbPolygon) {
      parts.push_back(fixed->toPolygon());
    } else {
      ASSERT_EQ(wkbFlatten(fixed->getGeometryType()), wkbMultiPolygon);
      for (const OGRPolygon* p : *fixed->toMultiPolygon()) parts.push_back(p);
    }
    ASSERT_EQ(l.parcels.size(), parts.size());
    const double shellArea =
        std::fabs(dynamic_cast<const OGRPolygon*>(f->GetGeometryRef())->getExteriorRing()->get_Area());
    // Parts match in order of area; areas as shares of the shell's (lon/lat
    // against local metres: equal to a few parts per million over 1 km).
    std::vector<std::pair<double, int>> expected, got;
    for (const OGRPolygon* p : parts) expected.emplace_back(p->get_Area() / shellArea, p->getNumInteriorRings());
    double total = 0;
    for (const Parcel& p : l.parcels) total += area(p.shape);
    for (const Parcel& p : l.parcels) {
      EXPECT_TRUE(p.repaired);
      got.emplace_back(area(p.shape), static_cast<int>(p.shape.holes.size()));
    }
    std::sort(expected.begin(), expected.end());
    std::sort(got.begin(), got.end());
    double expectedTotal = 0;
    for (const auto& e : expected) expectedTotal += e.first;
    for (std::size_t k = 0; k < got.size(); ++k) {
      EXPECT_EQ(got[k].second, expected[k].second) << k;
      EXPECT_NEAR(got[k].first / total, expected[k].first / expectedTotal, 1e-5) << k;
    }
  }
}

TEST(ParcelReader, StrayAndNonFiniteFeaturesDoNotMoveTheFrame) {
  TempDir dir;
  const double lon = 127.08, lat = 37.51, d = 0.0002;
  const std::string square = R"({"type":"Polygon","coordinates":[)" + test::squareRing(lon, lat, d) + "]}";
  const auto alone = dir.write("alone.geojson", test::collection(test::feature(square, 1)));
  // The same square, plus a stray record at 0, 0 and one with an absurd coordinate.
  const auto stray =
      dir.write("stray.geojson",
                test::collection(
                    test::feature(square, 1) + "," +
                    test::feature(R"({"type":"Polygon","coordinates":[)" + test::squareRing(0, 0, d) + "]}", 5) + "," +
                    test::feature(R"({"type":"Polygon","coordinates":[[[1e300,0],[1e300,1],[0,1],[1e300,0]]]})", 7)));
  const double a = area(readParcels(options(alone)).parcels[0].shape);
  const ParcelLayer l = readParcels(options(stray));
  EXPECT_EQ(l.report.nonFiniteSkipped, 1);
  EXPECT_NEAR(area(l.parcels[0].shape), a, 1e-6 * a);
}

// GDAL's GeoJSON reader takes the token NaN; OGR's envelope of such a geometry
// passes over the NaN and looks finite, so the coordinates themselves are checked.
TEST(ParcelReader, AFeatureWithANaNCoordinateIsSkippedAndCounted) {
  TempDir dir;
  const double lon = 2.35, lat = 48.85, d = 0.0001;
  const std::string square = R"({"type":"Polygon","coordinates":[)" + test::squareRing(lon, lat, d) + "]}";
  const auto path = dir.write(
      "nan.geojson",
      test::collection(
          test::feature(square, 1) + "," +
          test::feature(R"({"type":"Polygon","coordinates":[[[2.3503,48.85],[2.3504,48.85],[2.3504,NaN],)"
                        R"([2.3503,48.8501],[2.3503,48.85]]]})",
                        3) +
          "," +
          test::feature(R"({"type":"Polygon","coordinates":[[[NaN,NaN],[2.3506,48.85],[2.3506,48.8501],[NaN,NaN]]]})",
                        5)));
  const ParcelLayer l = readParcels(options(path));
  EXPECT_EQ(l.report.features, 3);
  EXPECT_EQ(l.report.nonFiniteSkipped, 2);
  ASSERT_EQ(l.parcels.size(), 1u);
  EXPECT_EQ(l.parcels[0].sourceFid, 0);  // the finite square
  for (const auto& p : l.parcels) {
    EXPECT_TRUE(std::isfinite(area(p.shape)));
    for (const Point& v : p.shape.outer) EXPECT_TRUE(std::isfinite(v.x) && std::isfinite(v.y));
  }
}

// Every feature skipped for its coordinates is said to be so, not "no polygon geometry".
TEST(ParcelReader, ALayerOfOnlyAbsurdCoordinatesSaysSo) {
  TempDir dir;
  const auto absurd = dir.write(
      "absurd.geojson",
      test::collection(
          test::feature(R"({"type":"Polygon","coordinates":[[[1e300,0],[1e300,1],[0,1],[1e300,0]]]})", 1) + "," +
          test::feature(
              R"({"type":"Polygon","coordinates":[[[1e300,1e300],[2e300,1e300],[2e300,2e300],[1e300,1e300]]]})", 3)));
  expectError(options(absurd), Error::Kind::Input,
              {"absurd.geojson", "every feature was skipped for non-finite or absurd coordinates"});
  const auto withNull = dir.write(
      "absurd_and_null.geojson",
      test::collection(test::feature(R"({"type":"Polygon","coordinates":[[[1e300,0],[1e300,1],[0,1],[1e300,0]]]})", 1) +
                       R"(,{"type":"Feature","properties":{"pid":2},"geometry":null})"));
  expectError(options(withNull), Error::Kind::Input,
              {"absurd_and_null.geojson", "every feature was skipped", "1 for non-finite or absurd coordinates",
               "1 for a null or empty geometry"});
}

// A read error in the middle of the layer (a corrupt page of a GeoPackage) ends
// GDAL's feature loop as if the layer had ended; it must be an error, not a
// silently truncated layer.
TEST(ParcelReader, ACorruptGeoPackageIsAnErrorNotATruncatedLayer) {
  TempDir dir;
  std::string features;
  const int n = 600;
  for (int i = 0; i < n; ++i) {
    const std::string square = R"({"type":"Polygon","coordinates":[)" +
                               test::squareRing(2.35 + (i % 30) * 0.0002, 48.85 + (i / 30) * 0.0002, 0.00015) + "]}";
    features += (i ? "," : "") + test::feature(square, i + 1);
  }
  const auto gpkg = convert(dir.write("many.geojson", test::collection(features)), dir.file("many.gpkg"), "GPKG");
  ASSERT_EQ(readParcels(options(gpkg)).parcels.size(), static_cast<std::size_t>(n));
  // Overwrite the 4 KiB page in the middle of the file (one of the table's pages) with garbage.
  const auto size = std::filesystem::file_size(gpkg);
  constexpr std::uintmax_t kPage = 4096;
  ASSERT_GT(size / kPage, 20u) << "the table spans too few pages";
  std::string garbage(kPage, '\0');
  std::minstd_rand bytes(1);
  for (char& c : garbage) c = static_cast<char>(bytes() & 0xff);
  {
    std::fstream f(gpkg, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size / kPage / 2 * kPage));
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
    ASSERT_TRUE(f.good());
  }
  expectError(options(gpkg), Error::Kind::Input, {"many.gpkg", "reading layer many failed", "malformed"});
}

// What GDAL cannot read is named for what it is, not "unknown GDAL error".
TEST(ParcelReader, EmptyFilesFoldersDevicesAndGarbageAreNamedForWhatTheyAre) {
  TempDir dir;
  expectError(options(dir.write("empty.geojson", "")), Error::Kind::Input, {"empty.geojson", "is empty"});
  std::filesystem::create_directory(dir.file("folder"));
  expectError(options(dir.file("folder")), Error::Kind::Input, {"folder", "is a folder, not a file"});
  expectError(options("/dev/zero"), Error::Kind::Input, {"/dev/zero", "is a character device"});
  const auto garbage = dir.write("garbage.dat", std::string("\x01\x02 garbage \xff\xfe", 14));
  expectError(options(garbage), Error::Kind::Input, {"garbage.dat", "is not a file format GDAL reads"});
  for (const char* path : {"empty.geojson", "folder", "garbage.dat"}) {
    try {
      readParcels(options(dir.file(path)));
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find("unknown GDAL error"), std::string::npos) << e.what();
    }
  }
  // A folder GDAL reads (one of shapefiles) is still read.
  std::filesystem::create_directory(dir.file("shapefiles"));
  convert(dir.write("sq.geojson", test::quirksGeoJson()), dir.file("shapefiles/sq.shp"), "ESRI Shapefile");
  EXPECT_EQ(readParcels(options(dir.file("shapefiles"))).parcels.size(), 6u);
}

TEST(ParcelReader, GeographicCrsInGradsIsConverted) {
  TempDir dir;
  // 0.001 grad squares near Paris, read as NTF (Paris) in grads and as the same square in degrees.
  const std::string g = R"({"type":"Polygon","coordinates":[)" + test::squareRing(0.0, 54.27, 0.001) + "]}";
  const std::string deg = R"({"type":"Polygon","coordinates":[)" + test::squareRing(0.0, 54.27 * 0.9, 0.0009) + "]}";
  const auto grads = dir.write("grads.geojson", test::collection(test::feature(g, 1)));
  const auto degrees = dir.write("degrees.geojson", test::collection(test::feature(deg, 1)));
  const double inGrads = area(readParcels(options(grads, "", "", "EPSG:4807")).parcels[0].shape);
  const double inDegrees = area(readParcels(options(degrees)).parcels[0].shape);
  EXPECT_NEAR(inGrads / inDegrees, 1.0, 1e-3);  // same square; ellipsoids differ slightly
}

TEST(ParcelReader, ProjectedAreaMatchesGeodesicArea) {
  TempDir dir;
  const double lon = 2.35, lat = 48.85, d = 0.001;
  const auto path =
      dir.write("sq.geojson", test::collection(test::feature(
                                  R"({"type":"Polygon","coordinates":[)" + test::squareRing(lon, lat, d) + "]}", 1)));
  const ParcelLayer l = readParcels(options(path, "", "", ""));
  GeographicLib::PolygonArea geodesic(GeographicLib::Geodesic::WGS84());
  for (auto [x, y] : {std::pair{lon, lat}, {lon + d, lat}, {lon + d, lat + d}, {lon, lat + d}}) {
    geodesic.AddPoint(y, x);
  }
  double perimeterM = 0, areaM2 = 0;
  geodesic.Compute(false, true, perimeterM, areaM2);
  EXPECT_NEAR(totalArea(l) / std::fabs(areaM2), 1.0, 1e-5);
  // The frame is centred on the data, so coordinates are small.
  EXPECT_LT(std::fabs(l.parcels[0].shape.outer[0].x), 100.0);
}

TEST(ParcelReader, ReadsEveryFormatWithTheSameParcels) {
  TempDir dir;
  const auto geojson = dir.write("quirks.geojson", test::quirksGeoJson());
  const ParcelLayer reference = readParcels(options(geojson, "", "", ""));
  for (auto [format, name] : {std::pair{"GPKG", "q.gpkg"}, {"ESRI Shapefile", "q.shp"}, {"FlatGeobuf", "q.fgb"}}) {
    SCOPED_TRACE(format);
    const auto path = convert(geojson, dir.file(name), format);
    const ParcelLayer l = readParcels(options(path, "", "", ""));
    EXPECT_EQ(l.parcels.size(), reference.parcels.size());
    EXPECT_NEAR(totalArea(l), totalArea(reference), 1e-6 * totalArea(reference));
  }
  const auto topo = dir.write("t.topojson", R"({"type":"Topology",
    "arcs":[[[2.35,48.85],[2.3501,48.85],[2.3501,48.8501],[2.35,48.8501],[2.35,48.85]],
            [[2.3501,48.85],[2.3502,48.85],[2.3502,48.8501],[2.3501,48.8501],[2.3501,48.85]]],
    "objects":{"parcels":{"type":"GeometryCollection","geometries":[
      {"type":"Polygon","arcs":[[0]],"properties":{"id":1}},
      {"type":"Polygon","arcs":[[1]],"properties":{"id":2}}]}}})");
  const ParcelLayer t = readParcels(options(topo, "", "", ""));
  EXPECT_EQ(t.parcels.size(), 2u);
  EXPECT_TRUE(t.crs.assumedLonLat || t.crs.name.find("4326") != std::string::npos) << t.crs.name;
  EXPECT_NEAR(totalArea(t), 2 * 0.0001 * 111195.0 * 0.0001 * 111195.0 * std::cos(48.85 * M_PI / 180), 2.0);
}

TEST(ParcelReader, WhereFilterAndLayerSelection) {
  TempDir dir;
  const auto path = dir.write("quirks.geojson", test::quirksGeoJson());
  const ParcelLayer l = readParcels(options(path, "quirks", "use = 'lot'", ""));
  EXPECT_EQ(l.report.features, 6);  // every feature but the null one has use = 'lot' (odd pid)
  expectError(options(path, "nope", "", ""), Error::Kind::Input, {path, "nope", "quirks"});
  expectError(options(path, "", "use ===", ""), Error::Kind::Input, {path, "--where"});
}

TEST(ParcelReader, RefusesMissingUnreadableAndPolygonFreeInput) {
  TempDir dir;
  expectError(options(dir.file("absent.geojson"), "", "", ""), Error::Kind::Input, {"absent.geojson", "no such file"});
  const auto garbage = dir.write("garbage.geojson", "this is not { json");
  expectError(options(garbage, "", "", ""), Error::Kind::Input, {"garbage.geojson", "not a vector format"});
  const auto points =
      dir.write("points.geojson", test::collection(test::feature(R"({"type":"Point","coordinates":[2.35,48.85]})", 1)));
  expectError(options(points, "", "", ""), Error::Kind::Input, {"points.geojson", "no usable polygon"});
}

// Bug: a parcel around the North Pole was written back empty, a block across
// the antimeridian round the whole globe, and a parcel a continent away from the
// others measured 46 % too large, all with exit 0. Lon/lat that one local
// frame cannot hold is refused, with the way out.
TEST(ParcelReader, RefusesLonLatNearAPoleOrSpreadOverMoreThanHalfTheGlobe) {
  TempDir dir;
  const auto square = [](double x, double y, double d) {
    std::ostringstream s;
    s.precision(12);
    s << R"({"type":"Polygon","coordinates":[[[)" << x << "," << y << "],[" << x + d << "," << y << "],[" << x + d
      << "," << y + d << "],[" << x << "," << y + d << "],[" << x << "," << y << "]]]}";
    return s.str();
  };
  const auto pole = dir.write("pole.geojson", test::collection(test::feature(square(0, 89.9995, 0.0002), 1)));
  expectError(options(pole, "", "", ""), Error::Kind::Input, {"pole.geojson", "pole", "reproject"});
  const auto across = dir.write("across.geojson", test::collection(test::feature(square(179.9998, 0, 0.0001), 1) + "," +
                                                                   test::feature(square(-179.9999, 0, 0.0001), 2)));
  expectError(options(across, "", "", ""), Error::Kind::Input, {"across.geojson", "antimeridian", "reproject"});
  // Parcels near each other in the far north or east are taken.
  const auto north = dir.write("north.geojson", test::collection(test::feature(square(25, 89.0, 0.0005), 1)));
  EXPECT_EQ(readParcels(options(north, "", "", "")).parcels.size(), 1u);
  const auto east = dir.write("east.geojson", test::collection(test::feature(square(179.99, 0, 0.0005), 1)));
  EXPECT_EQ(readParcels(options(east, "", "", "")).parcels.size(), 1u);
}

// Bug: lon/lat given --crs EPSG:3857 (metres) made every parcel a speck, and
// the error said only "all skipped". It says why, and asks about the CRS.
TEST(ParcelReader, AllSkippedSaysWhyAndAsksAboutTheCrsWhenEveryPartIsASpeck) {
  TempDir dir;
  const auto path = dir.write(
      "lonlat.geojson",
      test::collection(test::feature(
          R"({"type":"Polygon","coordinates":[[[-71.1,42.37],[-71.0999,42.37],[-71.0999,42.3701],[-71.1,42.3701],[-71.1,42.37]]]})",
          1)));
  EXPECT_EQ(readParcels(options(path, "", "", "")).parcels.size(), 1u);
  expectError(options(path, "", "", "EPSG:3857"), Error::Kind::Input,
              {"lonlat.geojson", "all skipped: 1 degenerate", "is --crs EPSG:3857 the data's CRS?"});
}

// Bug: a VRT whose source file is missing said only "no polygon geometry".
TEST(ParcelReader, AVrtWhoseSourceIsMissingSaysSo) {
  TempDir dir;
  const auto vrt = dir.write("missing.vrt", R"(<OGRVRTDataSource><OGRVRTLayer name="x">
      <SrcDataSource>nonexistent.geojson</SrcDataSource></OGRVRTLayer></OGRVRTDataSource>)");
  expectError(options(vrt, "", "", ""), Error::Kind::Input, {"missing.vrt", "nonexistent.geojson"});
}

TEST(ParcelReader, RefusesLonLatClaimForCoordinatesThatCannotBeDegrees) {
  TempDir dir;
  const auto path = dir.write("feet.geojson", feetGeoJson());
  expectError(options(path, "", "", ""), Error::Kind::Input, {"feet.geojson", "cannot be degrees", "--crs"});
  const ParcelLayer l = readParcels(options(path, "", "", "EPSG:2286"));
  EXPECT_TRUE(l.crs.overridden);
  EXPECT_NEAR(totalArea(l), 100 * 100 * 0.3048006096 * 0.3048006096, 1e-6);
  expectError(options(path, "", "", "EPSG:99999999"), Error::Kind::Usage, {"--crs", "EPSG:99999999"});
  // A CRS that exists but has no plane to measure in (geocentric).
  expectError(options(path, "", "", "EPSG:4978"), Error::Kind::Input,
              {"feet.geojson", "neither geographic nor projected"});
}

TEST(ParcelReader, RefusesProjectedCoordinatesWithoutCrs) {
  TempDir dir;
  const auto geojson = dir.write("feet.geojson", feetGeoJson());
  // A shapefile without .prj declares no CRS at all.
  const auto shp = convert(geojson, dir.file("feet.shp"), "ESRI Shapefile");
  std::filesystem::remove(dir.file("feet.prj"));
  expectError(options(shp, "", "", ""), Error::Kind::Input, {"feet.shp", "declares no CRS", "--crs"});
}

}  // namespace
}  // namespace parcelscope::io

namespace parcelscope::io {
namespace {

// Keys come from the geometry as read, or from a key field: a value of 16
// hexadecimal digits is the key itself, any other value is hashed; parts of a
// multipart feature get distinct keys; a missing key field is named.
TEST(ParcelReaderKeys, KeysComeFromGeometriesOrFromTheKeyField) {
  test::TempDir dir;
  const double lon = 2.35, lat = 48.85, d = 0.0001;
  auto square = [&](double x) {
    return std::string(R"({"type":"Polygon","coordinates":[)") + test::squareRing(lon + x * d, lat, d) + "]}";
  };
  const std::string two = R"({"type":"MultiPolygon","coordinates":[[)" + test::squareRing(lon + 4 * d, lat, d) + "],[" +
                          test::squareRing(lon + 6 * d, lat, d) + "]]}";
  const auto path = dir.write(
      "keys.geojson",
      test::collection(test::feature(square(0), 1) + "," + test::feature(square(2), 2) + "," + test::feature(two, 3)));
  ReadOptions o;
  o.path = path;
  const ParcelLayer byGeometry = readParcels(o);
  ASSERT_EQ(byGeometry.parcels.size(), 4u);
  std::set<Key> keys;
  for (const Parcel& p : byGeometry.parcels) keys.insert(parcelKey(p));
  EXPECT_EQ(keys.size(), 4u);
  EXPECT_EQ(byGeometry.parcels[2].featureKey, byGeometry.parcels[3].featureKey);      // one feature, two parts
  EXPECT_EQ(readParcels(o).parcels[1].featureKey, byGeometry.parcels[1].featureKey);  // reproducible

  o.keyField = "pid";
  const ParcelLayer byField = readParcels(o);
  EXPECT_EQ(byField.parcels[0].featureKey, hashBytes("1"));
  EXPECT_EQ(byField.parcels[1].featureKey, hashBytes("2"));

  const auto hex = dir.write("hex.geojson", R"({"type":"FeatureCollection","features":[{"type":"Feature",)"
                                            R"("properties":{"block_key":"00000000000000ff"},"geometry":)" +
                                                square(0) + "}]}");
  o.path = hex;
  o.keyField = "block_key";
  EXPECT_EQ(readParcels(o).parcels[0].featureKey, Key{255});

  // Bug: two geometries with one key field value were taken, their parcels
  // then sharing a key. Copies of one geometry (a condominium stack) may share it.
  const auto twice = dir.write(
      "twice.geojson", R"({"type":"FeatureCollection","features":[)"
                       R"({"type":"Feature","properties":{"pid":"7"},"geometry":)" +
                           square(0) + R"(},{"type":"Feature","properties":{"pid":"7"},"geometry":)" + square(0) +
                           R"(},{"type":"Feature","properties":{"pid":"7"},"geometry":)" + square(20) + "}]}");
  o.path = twice;
  o.keyField = "pid";
  try {
    readParcels(o);
    FAIL() << "one key field value on two geometries is an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Input);
    EXPECT_NE(std::string(e.what()).find("twice.geojson: features 0 and 2 have the same value in --key-field pid"),
              std::string::npos)
        << e.what();
  }

  o.path = path;
  o.keyField = "nothing";
  try {
    readParcels(o);
    FAIL() << "a missing key field is an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'nothing'"), std::string::npos) << e.what();
  }
  o.keyFieldOptional = true;
  EXPECT_EQ(readParcels(o).parcels[1].featureKey, byGeometry.parcels[1].featureKey);
}

}  // namespace
}  // namespace parcelscope::io

namespace parcelscope::io {
namespace {

// Bug: a file (or list file) the user may not read was told as "not a file
// format GDAL reads", or as a list naming no file. Run as another user when
// the tests run as root (root reads mode 000 files).
TEST(ParcelReader, AFileThatMayNotBeReadIsToldAsSuch) {
  TempDir dir;
  const std::string file = dir.write("parcels.geojson", test::quirksGeoJson());
  const std::string list = dir.write("communes.txt", "parcels.geojson\n");
  ::chmod(file.c_str(), 0);
  ::chmod(list.c_str(), 0);
  ::chmod(dir.path().c_str(), 0755);
  for (const std::string& input : {file, list}) {
    SCOPED_TRACE(input);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) ::_exit(77);
      if (::access(input.c_str(), R_OK) == 0) ::_exit(77);  // readable after all: nothing to test
      ReadOptions options;
      options.path = input;
      try {
        readParcels(options);
      } catch (const Error& e) {
        const std::string what = e.what();
        ::_exit(what == input + ": cannot be read (Permission denied)" ? 0 : 1);
      }
      ::_exit(2);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    if (WEXITSTATUS(status) == 77) GTEST_SKIP() << "cannot run as a user who may not read the file";
    EXPECT_EQ(WEXITSTATUS(status), 0) << "another message, or none";
  }
}

}  // namespace
}  // namespace parcelscope::io
