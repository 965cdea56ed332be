// `parcelscope blocks` and `generate --streets` as a user runs them, on a
// street network written here in lon/lat: a grid of named streets with a
// width field for some, a viaduct marked as a bridge and a cul-de-sac. The
// written layers are read back with GDAL: valid, keyed, the same whatever the
// order of the input's features; generated parcels tile their street blocks.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "OgrTestUtil.h"
#include "TestUtil.h"
#include "cli/CliRun.h"

namespace parcelscope {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::slurp;
using test::TempDir;

CliRun run(const std::string& args) { return test::runCli(args); }

struct Line {
  std::vector<Point> lonLat;
  std::string name;
  std::string width;  // JSON value: a number or null
  std::string bridge;
};

// A grid of 5 x 5 streets about 100 m apart near lon -71.1, lat 42.37, the
// east-west ones 20 m wide (width field), a viaduct crossing the grid without
// meeting it, and a cul-de-sac.
std::vector<Line> network() {
  const double lon0 = -71.1, lat0 = 42.37, dLon = 100 / 82200.0, dLat = 100 / 111050.0;
  std::vector<Line> lines;
  for (int i = 0; i < 5; ++i) {
    lines.push_back({{{lon0 - dLon / 2, lat0 + i * dLat}, {lon0 + 4.5 * dLon, lat0 + i * dLat}},
                     "East " + std::to_string(i),
                     "20",
                     "N"});
    lines.push_back({{{lon0 + i * dLon, lat0 - dLat / 2}, {lon0 + i * dLon, lat0 + 4.5 * dLat}},
                     "North " + std::to_string(i),
                     "null",
                     "N"});
  }
  lines.push_back(
      {{{lon0 - dLon / 2, lat0 + 2.5 * dLat}, {lon0 + 4.5 * dLon, lat0 + 2.5 * dLat}}, "Viaduct", "12", "Y"});
  lines.push_back({{{lon0 + 0.5 * dLon, lat0}, {lon0 + 0.5 * dLon, lat0 + 0.6 * dLat}}, "Court", "8", "N"});
  return lines;
}

std::string geojson(std::vector<Line> lines, bool shuffled) {
  if (shuffled) {
    std::reverse(lines.begin(), lines.end());
    for (std::size_t i = 0; i < lines.size(); i += 3) std::reverse(lines[i].lonLat.begin(), lines[i].lonLat.end());
  }
  std::ostringstream s;
  s.precision(12);
  s << "{\"type\": \"FeatureCollection\", \"features\": [";
  for (std::size_t i = 0; i < lines.size(); ++i) {
    s << (i ? "," : "") << "\n{\"type\": \"Feature\", \"properties\": {\"NAME\": \"" << lines[i].name
      << "\", \"W\": " << lines[i].width << ", \"BR\": \"" << lines[i].bridge
      << "\"}, \"geometry\": {\"type\": \"LineString\", \"coordinates\": [";
    for (std::size_t k = 0; k < lines[i].lonLat.size(); ++k) {
      s << (k ? "," : "") << "[" << lines[i].lonLat[k].x << "," << lines[i].lonLat[k].y << "]";
    }
    s << "]}}";
  }
  s << "]}\n";
  return s.str();
}

const std::string kFlags = " --width-field W --name-field NAME --no-node-where \"BR = 'Y'\" --default-width 10 --quiet";

std::map<std::string, double> blockAreas(const test::ReadLayer& layer) {
  std::map<std::string, double> m;
  for (const auto& f : layer.features) m[f->GetFieldAsString("block_key")] = f->GetFieldAsDouble("area");
  return m;
}

TEST(BlocksCommand, WritesValidKeyedBlocksAndTheGraphWhateverTheFeatureOrder) {
  TempDir dir;
  const std::string streets = dir.write("streets.geojson", geojson(network(), false));
  const std::string shuffled = dir.write("shuffled.geojson", geojson(network(), true));
  const CliRun a = run("blocks '" + streets + "'" + kFlags + " --out '" + dir.file("a") + "'");
  ASSERT_EQ(a.code, 0) << a.output;
  for (const char* f : {"blocks.gpkg", "streets.gpkg", "street_surface.gpkg", "run.json"}) {
    EXPECT_TRUE(fs::exists(dir.file("a") + "/" + f)) << f;
  }
  // 16 cells; the viaduct cuts the four it crosses in two.
  const OGRSpatialReference crs = test::layerCrs(streets);
  const test::ReadLayer blocks = test::expectValidPolygonLayer(
      dir.file("a") + "/blocks.gpkg", 20, {"blocks", {"block_key", "area", "streets", "edge_keys"}, &crs});
  test::expectValidPolygonLayer(dir.file("a") + "/street_surface.gpkg", 1, {"surface", {}, &crs});
  // Blocks between two 20 m streets and two 10 m ones: 80 x 90 m, less the
  // cul-de-sac's slot or the viaduct where they lie.
  int full = 0;
  for (const auto& f : blocks.features) full += std::fabs(f->GetFieldAsDouble("area") - 80 * 90) < 0.01 * 80 * 90;
  EXPECT_EQ(full, 16 - 4 - 1);
  const std::string names = [&] {
    std::string all;
    for (const auto& f : blocks.features) all += std::string(f->GetFieldAsString("streets")) + "|";
    return all;
  }();
  EXPECT_NE(names.find("Court"), std::string::npos);
  EXPECT_NE(names.find("Viaduct"), std::string::npos);

  auto ds = test::openVectorFile(dir.file("a") + "/streets.gpkg");
  ASSERT_TRUE(ds);
  OGRLayer* nodes = ds->GetLayerByName("nodes");
  OGRLayer* edges = ds->GetLayerByName("edges");
  ASSERT_TRUE(nodes && edges);
  // 25 crossings and 20 grid ends; the viaduct's 2 ends and the court's far end.
  EXPECT_EQ(nodes->GetFeatureCount(), 25 + 20 + 2 + 1 + 1);  // and the court's junction
  int viaduct = 0;
  for (auto& e : *edges) viaduct += std::string(e->GetFieldAsString("name")) == "Viaduct";
  EXPECT_EQ(viaduct, 1);  // it crosses the grid without a node
  const std::string record = slurp(dir.file("a") + "/run.json");
  EXPECT_NE(record.find("\"lines_not_noded\": 1"), std::string::npos) << record;
  EXPECT_NE(record.find("\"widths_given\""), std::string::npos) << record;

  ASSERT_EQ(run("blocks '" + shuffled + "'" + kFlags + " --out '" + dir.file("b") + "'").code, 0);
  const test::ReadLayer again =
      test::expectValidPolygonLayer(dir.file("b") + "/blocks.gpkg", 20, {"blocks", {"block_key"}, &crs});
  const auto areasA = blockAreas(blocks), areasB = blockAreas(again);
  ASSERT_EQ(areasA.size(), 20u);  // keys distinct
  for (const auto& [key, area] : areasA) {
    ASSERT_TRUE(areasB.count(key)) << "block " << key << " lost its key when the features were reordered";
    EXPECT_NEAR(areasB.at(key), area, 1e-6 * area);
  }
}

TEST(GenerateCommand, ParcelsTileTheStreetBlocksAndRepeatWithTheSeed) {
  TempDir dir;
  const std::string streets = dir.write("streets.geojson", geojson(network(), false));
  ASSERT_EQ(run("blocks '" + streets + "'" + kFlags + " --out '" + dir.file("blocks") + "'").code, 0);
  const test::ReadLayer blocks = test::expectValidPolygonLayer(dir.file("blocks") + "/blocks.gpkg", 20);
  for (const char* style : {"obb", "skeleton"}) {
    const std::string base = "generate --streets '" + streets + "'" + kFlags + " --style " + style +
                             " --a-min 150 --a-max 600 --w-min 10 --w-max 25";
    const CliRun a = run(base + " --seed 3 --out '" + dir.file(std::string(style) + "a") + "'");
    ASSERT_EQ(a.code, 0) << a.output;
    const std::string csv = slurp(dir.file(std::string(style) + "a") + "/parcels.csv");
    const auto rows = std::count(csv.begin(), csv.end(), '\n') - 1;
    ASSERT_GT(rows, 100) << style;
    const OGRSpatialReference crs = test::layerCrs(streets);
    const test::ReadLayer parcels = test::expectValidPolygonLayer(dir.file(std::string(style) + "a") + "/parcels.gpkg",
                                                                  rows, {"parcels", {"block_key"}, &crs});
    // Each street block's parcels add up to it (areas in square degrees, as
    // written: edges straight in metres bow by about 0.2 mm over 100 m there).
    std::map<std::string, double> byBlock;
    for (std::size_t i = 0; i < parcels.features.size(); ++i) {
      for (const Polygon& p : parcels.geometries[i])
        byBlock[parcels.features[i]->GetFieldAsString("block_key")] += area(p);
    }
    ASSERT_EQ(byBlock.size(), 20u) << style;
    for (std::size_t i = 0; i < blocks.features.size(); ++i) {
      double blockArea = 0;
      for (const Polygon& p : blocks.geometries[i]) blockArea += area(p);
      const std::string key = blocks.features[i]->GetFieldAsString("block_key");
      ASSERT_TRUE(byBlock.count(key)) << style << ": block " << key << " has no parcels";
      EXPECT_NEAR(byBlock[key], blockArea, 1e-5 * blockArea) << style << ": block " << key;
    }
    const std::string record = slurp(dir.file(std::string(style) + "a") + "/run.json");
    EXPECT_NE(record.find("\"street-network\""), std::string::npos) << record.substr(0, 400);
    ASSERT_EQ(run(base + " --seed 3 --out '" + dir.file(std::string(style) + "b") + "'").code, 0);
    EXPECT_TRUE(test::sameGeometries(
        test::expectValidPolygonLayer(dir.file(std::string(style) + "b") + "/parcels.gpkg", rows), parcels))
        << style;
  }
}

// Widths in a text field are numbers or empty (no width), and in the unit of a
// projected CRS: 40 US survey feet in EPSG:2286 are 12.19 m.
TEST(BlocksCommand, WidthsInATextFieldAndInFeetAreRead) {
  TempDir dir;
  auto layer = [](const std::vector<std::string>& widths) {
    // A 2 x 2 grid of streets 400 ft apart in Washington State Plane South (US feet).
    const double x0 = 1160000, y0 = 680000;
    const double lines[4][4] = {{x0 - 200, y0, x0 + 600, y0},
                                {x0 - 200, y0 + 400, x0 + 600, y0 + 400},
                                {x0, y0 - 200, x0, y0 + 600},
                                {x0 + 400, y0 - 200, x0 + 400, y0 + 600}};
    std::ostringstream s;
    s.precision(12);
    s << "{\"type\": \"FeatureCollection\", \"crs\": {\"type\": \"name\", \"properties\": {\"name\": "
         "\"urn:ogc:def:crs:EPSG::2286\"}}, \"features\": [";
    for (int i = 0; i < 4; ++i) {
      s << (i ? "," : "") << "{\"type\": \"Feature\", \"properties\": {\"W\": \"" << widths[i]
        << "\"}, \"geometry\": {\"type\": \"LineString\", \"coordinates\": [[" << lines[i][0] << "," << lines[i][1]
        << "],[" << lines[i][2] << "," << lines[i][3] << "]]}}";
    }
    s << "]}\n";
    return s.str();
  };
  const std::string good = dir.write("feet.geojson", layer({"40", "40", " 40 ", ""}));
  const CliRun r = run("blocks '" + good + "' --width-field W --default-width 5 --quiet --out '" + dir.file("o") + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string record = slurp(dir.file("o") + "/run.json");
  EXPECT_NE(record.find("\"widths_given\": 9"), std::string::npos) << record;  // 3 lines of 3 edges each
  auto ds = test::openVectorFile(dir.file("o") + "/streets.gpkg");
  ASSERT_TRUE(ds);
  std::map<std::string, int> widths;
  for (auto& e : *ds->GetLayerByName("edges")) {
    std::ostringstream w;
    w.precision(4);
    w << e->GetFieldAsDouble("width");
    ++widths[w.str()];
  }
  EXPECT_EQ(widths["12.19"], 9);  // 40 ft
  EXPECT_EQ(widths["5"], 3);      // the empty one: the default
  const std::string bad = dir.write("bad.geojson", layer({"40", "wide", "40", "40"}));
  const CliRun b = run("blocks '" + bad + "' --width-field W --quiet --out '" + dir.file("b") + "'");
  EXPECT_EQ(b.code, 1) << b.output;
  EXPECT_NE(b.output.find("has width 'wide' in field 'W'"), std::string::npos) << b.output;
  EXPECT_NE(b.output.find("bad.geojson: feature 1"), std::string::npos) << b.output;
  // Bug: a width of 1e300 emptied the street surface and every block, exit 0.
  const std::string huge = dir.write("huge.geojson", layer({"40", "40", "1e300", "40"}));
  const CliRun h = run("blocks '" + huge + "' --width-field W --quiet --out '" + dir.file("h") + "'");
  EXPECT_EQ(h.code, 1) << h.output;
  EXPECT_NE(h.output.find("huge.geojson: feature 2 has width '1e300'"), std::string::npos) << h.output;
  EXPECT_FALSE(std::filesystem::exists(dir.file("h")));
}

TEST(BlocksCommand, BadStreetInputsAreOneLineErrors) {
  TempDir dir;
  const std::string streets = dir.write("streets.geojson", geojson(network(), false));
  const std::string sample = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
  struct Case {
    std::string args;
    int code;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"blocks '" + sample + "' --out '" + dir.file("o1") + "'", 1, "holds no line"},
      {"blocks '" + streets + "' --width-field NOPE --out '" + dir.file("o2") + "'", 1,
       "no field 'NOPE' (--width-field)"},
      {"blocks '" + streets + "' --class-field NAME --class-widths 'East 0=abc' --out '" + dir.file("o3") + "'", 2,
       "--class-widths"},
      {"blocks '" + streets + "' --class-widths 'a=3' --out '" + dir.file("o4") + "'", 2, "needs --class-field"},
      {"blocks '" + streets + "' --class-field NAME --class-widths 'a=0x10' --out '" + dir.file("o7") + "'", 2,
       "decimal width"},
      {"blocks '" + streets + "' --class-field NAME --class-widths 'a=3,b=4,a=5' --out '" + dir.file("o8") + "'", 2,
       "class 'a' is given twice"},
      {"generate --width-field W --out '" + dir.file("o5") + "'", 2, "needs --streets"},
      {"blocks '" + streets + "' --no-node-where 'NO SUCH' --out '" + dir.file("o6") + "'", 1, "--no-node-where"},
  };
  for (const Case& c : cases) {
    const CliRun r = run(c.args + " --quiet");
    EXPECT_EQ(r.code, c.code) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
    // One line; a usage error adds where to find the usage.
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), c.code == 2 ? 2 : 1) << r.output;
  }
  // Blanks around a class and its width are not part of them.
  const CliRun spaced =
      run("blocks '" + streets + "' --class-field NAME --class-widths ' East 0 = 12 , x=3' --quiet --out '" +
          dir.file("o9") + "'");
  EXPECT_EQ(spaced.code, 0) << spaced.output;
  // run.json records the street options, the classes as read.
  std::ifstream in(dir.file("o9") + "/run.json");
  const std::string record((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* text : {"\"class_widths\": {", "\"East 0\": 12", "\"x\": 3"}) {
    EXPECT_NE(record.find(text), std::string::npos) << text << "\n" << record;
  }
  EXPECT_NE(record.find("\"class_field\": \"NAME\""), std::string::npos) << record;
}

// Streets read in the parcels' frame: 6,000 km away they are refused, naming
// the feature (the frame's projection folded such lines onto the parcels);
// where the parcels are, the summary counts the parcels in no street block.
TEST(CompareCommand, StreetsAwayFromTheParcelsAreTold) {
  TempDir dir;
  const std::string sample = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
  const auto moved = [](double dLon) {
    std::vector<Line> lines = network();
    for (Line& l : lines) {
      for (Point& p : l.lonLat) p.x += dLon;
    }
    return lines;
  };
  const std::string flags = " --width-field W --name-field NAME --default-width 10";  // not quiet: the summary
  const std::string far = dir.write("far.geojson", geojson(moved(73.4), false));
  const CliRun f =
      run("compare '" + sample + "' --streets '" + far + "' --figures 0 --quiet --out '" + dir.file("f") + "'");
  EXPECT_EQ(f.code, 1) << f.output;
  EXPECT_NE(f.output.find("far.geojson: feature 0 lies "), std::string::npos) << f.output;
  EXPECT_NE(f.output.find("the streets are not where the parcels are"), std::string::npos) << f.output;
  EXPECT_FALSE(fs::exists(dir.file("f")));
  const std::string same = dir.write("same.geojson", geojson(network(), false));
  const CliRun s =
      run("compare '" + sample + "' --streets '" + same + "'" + flags + " --figures 0 --out '" + dir.file("s") + "'");
  ASSERT_EQ(s.code, 0) << s.output;
  EXPECT_NE(s.output.find(" parcels lie in no street block (left out of the comparison)"), std::string::npos)
      << s.output;
}

// `parcelscope edit`: edits in the input's CRS (lon/lat here) by the keys
// streets.gpkg gives; the parcels written are valid, keyed and labelled, and
// persistence.csv counts what each edit kept. A bad edit writes nothing.
TEST(EditCommand, EditsByKeyInTheInputsCrsAndWritesValidParcelsAndPersistence) {
  TempDir dir;
  const std::string streets = dir.write("streets.geojson", geojson(network(), false));
  ASSERT_EQ(run("blocks '" + streets + "'" + kFlags + " --out '" + dir.file("net") + "'").code, 0);
  auto ds = test::openVectorFile(dir.file("net") + "/streets.gpkg");
  ASSERT_TRUE(ds);
  std::string node, edge;
  double lon = 0, lat = 0;
  for (auto& f : *ds->GetLayerByName("nodes")) {
    if (f->GetFieldAsInteger("degree") == 4 && node.empty()) {
      node = f->GetFieldAsString("node_key");
      const OGRPoint* p = f->GetGeometryRef()->toPoint();
      lon = p->getX();
      lat = p->getY();
    }
  }
  for (auto& f : *ds->GetLayerByName("edges")) {
    if (std::string(f->GetFieldAsString("kind")) == "street" && edge.empty()) edge = f->GetFieldAsString("edge_key");
  }
  ASSERT_FALSE(node.empty());
  ASSERT_FALSE(edge.empty());
  // The network as built (no edit) gives the parcels' keys; one gets a label.
  const std::string none = dir.write("none.json", "[]");
  ASSERT_EQ(run("edit '" + streets + "'" + kFlags + " --style skeleton --edits '" + none + "' --out '" +
                dir.file("built") + "'")
                .code,
            0);
  std::string labelled;
  {
    auto built = test::openVectorFile(dir.file("built") + "/parcels.gpkg");
    ASSERT_TRUE(built);
    labelled = built->GetLayer(0)->GetNextFeature()->GetFieldAsString("parcel_key");
  }
  std::ostringstream edits;
  edits.precision(12);
  edits << R"([{"op": "set_label", "parcel": ")" << labelled << R"(", "label": "blue house"},)"
        << R"({"op": "move_node", "node": ")" << node << R"(", "to": [)" << lon + 2 / 82200.0 << ", " << lat
        << R"(]}, {"op": "set_width", "edge": ")" << edge << R"(", "width": 14}])";
  const std::string editsFile = dir.write("edits.json", edits.str());
  const CliRun r = run("edit '" + streets + "'" + kFlags + " --style skeleton --edits '" + editsFile + "' --out '" +
                       dir.file("edited") + "'");
  ASSERT_EQ(r.code, 0) << r.output;
  const OGRSpatialReference crs = test::layerCrs(streets);
  const test::ReadLayer blocks =
      test::expectValidPolygonLayer(dir.file("edited") + "/blocks.gpkg", 20, {"blocks", {"block_key"}, &crs});
  const std::string csv = slurp(dir.file("edited") + "/persistence.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4) << csv;
  EXPECT_NE(csv.find("move_node"), std::string::npos);
  EXPECT_NE(csv.find("set_width"), std::string::npos);
  auto parcels = test::openVectorFile(dir.file("edited") + "/parcels.gpkg");
  ASSERT_TRUE(parcels);
  const std::int64_t n = parcels->GetLayer(0)->GetFeatureCount();
  ASSERT_GT(n, 20);
  const test::ReadLayer written = test::expectValidPolygonLayer(dir.file("edited") + "/parcels.gpkg", n,
                                                                {"parcels", {"parcel_key", "label"}, &crs});
  std::set<std::string> keys;
  int labels = 0;
  for (const auto& f : written.features) {
    keys.insert(f->GetFieldAsString("parcel_key"));
    if (std::string(f->GetFieldAsString("label")) == "blue house") {
      ++labels;
      EXPECT_EQ(f->GetFieldAsString("parcel_key"), labelled) << "the label stays with its parcel's key";
    }
  }
  EXPECT_EQ(static_cast<std::int64_t>(keys.size()), n);  // unique
  EXPECT_EQ(labels, 1);

  // A session with streets: its streets, style and parameters; the same edits give the same parcels.
  const std::string session = dir.write(
      "session.json", "{\"parcelscope_session\": 2, \"input\": {\"path\": \"" + streets +
                          "\"}, \"streets\": {\"path\": \"" + streets +
                          "\", \"width_field\": \"W\", \"name_field\": \"NAME\", \"no_node_where\": \"BR = 'Y'\"}, "
                          "\"style\": \"skeleton\", \"parameters\": {\"default-width\": 10}}");
  const CliRun fromSession =
      run("edit '" + session + "' --quiet --edits '" + editsFile + "' --out '" + dir.file("from-session") + "'");
  ASSERT_EQ(fromSession.code, 0) << fromSession.output;
  // Every edit's counts (the columns before the seconds) are the same.
  auto counts = [](const std::string& text) {
    std::string out;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
      std::size_t at = 0;
      for (int field = 0; field < 8 && at != std::string::npos; ++field) at = line.find(',', at + 1);
      out += line.substr(0, at) + "\n";
    }
    return out;
  };
  EXPECT_EQ(counts(slurp(dir.file("from-session") + "/persistence.csv")), counts(csv));
  {
    auto a = test::openVectorFile(dir.file("from-session") + "/parcels.gpkg");
    ASSERT_TRUE(a);
    EXPECT_EQ(a->GetLayer(0)->GetFeatureCount(), n);
  }

  // An edit naming a node the network does not have: one line naming the file and the edit, nothing written.
  const std::string bad = dir.write("bad.json", R"([{"op": "move_node", "node": "0123456789abcdef", "to": [0, 0]}])");
  const CliRun b = run("edit '" + streets + "'" + kFlags + " --edits '" + bad + "' --out '" + dir.file("bad") + "'");
  EXPECT_EQ(b.code, 1);  // bad content of the edits file, not a usage error
  EXPECT_NE(b.output.find("bad.json: edit 0 (move_node): the network has no node 0123456789abcdef"), std::string::npos)
      << b.output;
  EXPECT_EQ(b.output.find("--help"), std::string::npos) << b.output;
  EXPECT_FALSE(fs::exists(dir.file("bad")));
}

}  // namespace
}  // namespace parcelscope
