// A run split into shards and merged gives the observed data, and so the
// tables, of one process: on the sample (right-of-way, a null geometry,
// duplicates, a multipart feature), on a layer whose long block crosses every
// strip, with both ways of reading (every feature, or a spatial filter with the
// frame sample exchanged between shards running at once), and on cambridge_ma.
#include <gdal_utils.h>
#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "SampleRequest.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/Shards.h"

namespace parcelscope::pipeline {
namespace {

namespace fs = std::filesystem;

void expectSameRing(const Ring& a, const Ring& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(Point)));
}

void expectSamePolygon(const Polygon& a, const Polygon& b) {
  expectSameRing(a.outer, b.outer);
  ASSERT_EQ(a.holes.size(), b.holes.size());
  for (std::size_t h = 0; h < a.holes.size(); ++h) expectSameRing(a.holes[h], b.holes[h]);
}

// Every field of the observed data, to the bit (timings aside).
void expectSameObserved(const ObservedData& one, const ObservedData& merged) {
  EXPECT_EQ(one.layer.frame.state(), merged.layer.frame.state());
  EXPECT_EQ(one.layer.crs.name, merged.layer.crs.name);
  const io::CleaningReport &r = one.layer.report, &m = merged.layer.report;
  EXPECT_EQ(0, std::memcmp(&r, &m, sizeof r)) << "cleaning report: features " << r.features << " / " << m.features
                                              << ", parcels " << r.parcels << " / " << m.parcels;
  ASSERT_EQ(one.layer.parcels.size(), merged.layer.parcels.size());
  for (std::size_t i = 0; i < one.layer.parcels.size(); ++i) {
    const Parcel &a = one.layer.parcels[i], &b = merged.layer.parcels[i];
    EXPECT_EQ(a.sourceFid, b.sourceFid) << i;
    EXPECT_EQ(a.part, b.part) << i;
    EXPECT_EQ(a.stackCount, b.stackCount) << i;
    EXPECT_EQ(a.repaired, b.repaired) << i;
    EXPECT_EQ(a.featureKey, b.featureKey) << i;
    expectSamePolygon(a.shape, b.shape);
  }
  const analysis::ObservedAnalysis &x = one.analysis, &y = merged.analysis;
  ASSERT_EQ(x.metrics.size(), y.metrics.size());
  for (std::size_t i = 0; i < x.metrics.size(); ++i) {
    const analysis::ParcelMetrics &p = x.metrics[i], &q = y.metrics[i];
    EXPECT_EQ(p.area, q.area) << i;
    EXPECT_EQ(p.width, q.width) << i;
    EXPECT_EQ(p.perimeter, q.perimeter) << i;
    EXPECT_EQ(p.pAngle, q.pAngle) << i;
    EXPECT_EQ(p.neighbours, q.neighbours) << i;
    EXPECT_EQ(p.frontage, q.frontage) << i;
    EXPECT_EQ(p.streetAccess, q.streetAccess) << i;
  }
  EXPECT_EQ(x.rightOfWay, y.rightOfWay);
  EXPECT_EQ(x.blockOf, y.blockOf);
  EXPECT_EQ(x.rightOfWayCount, y.rightOfWayCount);
  EXPECT_EQ(x.multipartBlocks, y.multipartBlocks);
  EXPECT_EQ(x.clampedAMin, y.clampedAMin);
  EXPECT_EQ(x.clampedWMin, y.clampedWMin);
  ASSERT_EQ(x.blocks.size(), y.blocks.size());
  for (std::size_t b = 0; b < x.blocks.size(); ++b) {
    EXPECT_EQ(x.blocks[b].id, y.blocks[b].id);
    EXPECT_EQ(x.blocks[b].key, y.blocks[b].key) << b;
    EXPECT_EQ(x.blocks[b].parcels, y.blocks[b].parcels) << b;
    ASSERT_EQ(x.blocks[b].parts.size(), y.blocks[b].parts.size()) << b;
    for (std::size_t k = 0; k < x.blocks[b].parts.size(); ++k)
      expectSamePolygon(x.blocks[b].parts[k], y.blocks[b].parts[k]);
    EXPECT_EQ(0, std::memcmp(&x.statistics[b], &y.statistics[b], sizeof x.statistics[b]))
        << "statistics of block " << b;
  }
}

// The same generated parcels, metrics and per-entry record, to the bit.
void expectSameGenerated(const GeneratedParcels& one, const GeneratedParcels& sharded) {
  ASSERT_EQ(one.parcels.size(), sharded.parcels.size());
  for (std::size_t i = 0; i < one.parcels.size(); ++i) expectSamePolygon(one.parcels[i], sharded.parcels[i]);
  ASSERT_EQ(one.metrics.size(), sharded.metrics.size());
  for (std::size_t i = 0; i < one.metrics.size(); ++i) {
    const analysis::ParcelMetrics &p = one.metrics[i], &q = sharded.metrics[i];
    const double a[] = {p.area,       p.perimeter,      p.width,  p.length, p.aspectRatio,
                        p.elongation, p.rectangularity, p.pAngle, p.pArea,  p.frontage};
    const double b[] = {q.area,       q.perimeter,      q.width,  q.length, q.aspectRatio,
                        q.elongation, q.rectangularity, q.pAngle, q.pArea,  q.frontage};
    EXPECT_EQ(0, std::memcmp(a, b, sizeof a)) << "metrics of parcel " << i;
    EXPECT_EQ(p.neighbours, q.neighbours) << i;
    EXPECT_EQ(p.streetAccess, q.streetAccess) << i;
  }
  EXPECT_EQ(one.blockKeys, sharded.blockKeys);
  EXPECT_EQ(one.blockStyles, sharded.blockStyles);
  EXPECT_EQ(one.failures, sharded.failures);
  EXPECT_EQ(one.oversize, sharded.oversize);
  EXPECT_EQ(one.withoutAccess, sharded.withoutAccess);
  EXPECT_EQ(one.unassigned, sharded.unassigned);
  EXPECT_EQ(one.blocksAtTarget, sharded.blocksAtTarget);
  EXPECT_EQ(one.clampedBounds, sharded.clampedBounds);
}

// Shards running at once in threads, their frame samples exchanged as MPI
// ranks exchange them (every shard waits for all, then takes the union).
class Exchange {
public:
  explicit Exchange(int count) : count_(count) {}
  void operator()(io::FrameSample& sample) {
    std::unique_lock<std::mutex> lock(mutex_);
    all_.extent = {std::min(all_.extent.minX, sample.extent.minX), std::min(all_.extent.minY, sample.extent.minY),
                   std::max(all_.extent.maxX, sample.extent.maxX), std::max(all_.extent.maxY, sample.extent.maxY)};
    all_.centresX.insert(all_.centresX.end(), sample.centresX.begin(), sample.centresX.end());
    all_.centresY.insert(all_.centresY.end(), sample.centresY.begin(), sample.centresY.end());
    if (++arrived_ == count_) done_.notify_all();
    done_.wait(lock, [&] { return arrived_ == count_ || failed_; });
    if (arrived_ != count_) throw std::runtime_error("another shard failed before the exchange");
    sample = all_;
  }
  // A shard that failed: the others stop waiting for it.
  void fail() {
    std::lock_guard<std::mutex> lock(mutex_);
    failed_ = true;
    done_.notify_all();
  }

private:
  int count_, arrived_ = 0;
  bool failed_ = false;
  std::mutex mutex_;
  std::condition_variable done_;
  io::FrameSample all_;
};

std::vector<ShardPart> analyseFiltered(const CompareRequest& request, int count) {
  Exchange exchange(count);
  std::vector<ShardPart> parts(count);
  std::vector<std::string> errors(count);
  std::vector<std::thread> threads;
  for (int i = 0; i < count; ++i) {
    threads.emplace_back([&, i] {
      ShardReading reading;
      reading.spatialFilter = true;
      reading.exchange = [&](io::FrameSample& s) { exchange(s); };
      try {
        parts[i] = analyseShard(request, i, count, reading);
      } catch (const std::exception& e) {
        errors[i] = e.what();
        exchange.fail();
      }
    });
  }
  for (auto& t : threads) t.join();
  for (const auto& e : errors) EXPECT_EQ("", e);
  return parts;
}

std::vector<ShardPart> analyseWhole(const CompareRequest& request, int count) {
  std::vector<ShardPart> parts;
  for (int i = 0; i < count; ++i) parts.push_back(analyseShard(request, i, count, ShardReading{}));
  return parts;
}

// `source`'s features whose id passes `where`, copied into a new file (GDAL's ogr2ogr).
void copyFeatures(const std::string& source, const std::string& where, const std::string& format,
                  const fs::path& target) {
  GDALAllRegister();
  GDALDatasetH in = GDALOpenEx(source.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
  ASSERT_NE(in, nullptr);
  const char* argv[] = {"-f", format.c_str(), "-where", where.c_str(), nullptr};
  GDALVectorTranslateOptions* options = GDALVectorTranslateOptionsNew(const_cast<char**>(argv), nullptr);
  int failed = 0;
  GDALDatasetH out = GDALVectorTranslate(target.c_str(), nullptr, 1, &in, options, &failed);
  GDALVectorTranslateOptionsFree(options);
  ASSERT_NE(out, nullptr);
  GDALClose(out);
  GDALClose(in);
}

CompareRequest sampleWithRightOfWay() {
  CompareRequest r = test::sampleCompareRequest("obb");
  r.input.where.clear();  // the right-of-way feature, a null geometry, duplicates, a multipart feature
  return r;
}

// The shards subdivide their blocks as one process does: with obb every
// block entry is made in its shard; the skeleton reads street widths from the
// neighbouring blocks, so its entries are left to the merged run; auto mixes
// them. Each way, the generated parcels and metrics of one process.
TEST(Shards, ShardsSubdivideTheirBlocksAsOneProcessDoes) {
  for (const char* style : {"obb", "skeleton", "auto", "sexton"}) {
    SCOPED_TRACE(style);
    CompareRequest request = sampleWithRightOfWay();
    request.style = style;
    auto one = std::make_shared<const ObservedData>(loadObserved(request.input, request.parameters));
    const CompareResult single = compare(request, one);
    for (int count : {2, 3}) {
      SCOPED_TRACE("shards: " + std::to_string(count));
      const PreparedObserved merged = prepareMerged(analyseWhole(request, count), count, request.input);
      const CompareResult sharded = compare(request, merged.data, {}, merged.premade.get());
      std::int64_t widthStyle = 0;
      for (const std::string& s : single.generated.blockStyles) widthStyle += s == "skeleton" || s == "offset";
      const auto entries = static_cast<std::int64_t>(single.generated.blocks.size());
      if (std::string(style) == "skeleton") {
        EXPECT_EQ(sharded.generated.premadeBlocks, 0);
      } else {
        EXPECT_GT(sharded.generated.premadeBlocks, 0);
        EXPECT_LE(sharded.generated.premadeBlocks, entries - widthStyle);
      }
      expectSameGenerated(single.generated, sharded.generated);
    }
  }
}

// A premade entry whose plan is not the run's (another seed) is subdivided
// again: the parcels are the run's own.
TEST(Shards, AnEntryMadeUnderAnotherPlanIsMadeAgain) {
  const CompareRequest request = sampleWithRightOfWay();
  auto one = std::make_shared<const ObservedData>(loadObserved(request.input, request.parameters));
  const CompareResult single = compare(request, one);
  PreparedObserved merged = prepareMerged(analyseWhole(request, 2), 2, request.input);
  ASSERT_GT(merged.premade->size(), 2u);
  std::vector<PremadeBlock>& made = *merged.premade;
  ASSERT_TRUE(made[1].made);
  made[1].plan ^= 1;
  made[1].outcome.subdivision.parcels.front().outer.front().x += 1.0;  // would show if taken
  const CompareResult sharded = compare(request, merged.data, {}, merged.premade.get());
  EXPECT_EQ(sharded.generated.premadeBlocks, static_cast<std::int64_t>(single.generated.blocks.size()) - 1);
  expectSameGenerated(single.generated, sharded.generated);
}

// The merge takes a shard's entry by its plan's key: any field of the plan
// changes the key.
TEST(Shards, PlanKeysTellPlansApart) {
  BlockPlan a;
  a.style = "obb";
  a.values = {{"a-max", 500.0}, {"w-min", 8.0}};
  a.seed = 7;
  BlockPlan b = a;
  EXPECT_EQ(planKey(a), planKey(b));
  b.seed = 8;
  EXPECT_NE(planKey(a), planKey(b));
  b = a;
  b.values["a-max"] = std::nextafter(500.0, 1e9);
  EXPECT_NE(planKey(a), planKey(b));
  b = a;
  b.style = "sexton";
  EXPECT_NE(planKey(a), planKey(b));
  b = a;
  b.values["a-min"] = 0.0;
  EXPECT_NE(planKey(a), planKey(b));
  b = a;  // a value under another name
  b.values.erase("w-min");
  b.values["w-max"] = 8.0;
  EXPECT_NE(planKey(a), planKey(b));
}

TEST(Shards, MergedShardsGiveTheObservedDataOfOneProcess) {
  const CompareRequest request = sampleWithRightOfWay();
  const ObservedData one = loadObserved(request.input, request.parameters);
  ASSERT_GT(one.layer.report.duplicatesCollapsed, 0);
  ASSERT_GT(one.layer.report.nullOrEmpty, 0);
  for (int count : {1, 2, 3, 5}) {
    SCOPED_TRACE("shards: " + std::to_string(count));
    expectSameObserved(one, mergeShards(analyseWhole(request, count)));
  }
}

TEST(Shards, ShardsWithASpatialFilterAndAnExchangedFrameAgreeWithOneProcess) {
  CompareRequest request = test::sampleCompareRequest("obb");
  const ObservedData one = loadObserved(request.input, request.parameters);
  for (int count : {2, 4}) {
    SCOPED_TRACE("shards: " + std::to_string(count));
    std::vector<ShardPart> parts = analyseFiltered(request, count);
    std::int64_t read = 0;
    for (const ShardPart& p : parts) read += p.parcelsRead;
    EXPECT_GT(read, 0);
    expectSameObserved(one, mergeShards(std::move(parts)));
  }
}

// A layer (local metres) of 3 x 3 lot blocks on a grid, and one long block of
// lots in a row across the whole extent, which every strip cuts.
std::string writeLongBlockLayer(const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path file = dir / "long_block.geojson";
  std::ofstream out(file);
  out.precision(12);
  out << "{\"type\":\"FeatureCollection\",\"crs\":{\"type\":\"name\",\"properties\":{\"name\":"
         "\"urn:ogc:def:crs:EPSG::32631\"}},\"features\":[";
  bool first = true;
  // Ids counting down: the features' ids are not in the file's order.
  int id = 1000;
  auto lot = [&](double x, double y, double w, double h) {
    out << (first ? "" : ",") << "{\"type\":\"Feature\",\"id\":" << id--
        << ",\"properties\":{},\"geometry\":{\"type\":\"Polygon\","
        << "\"coordinates\":[[[" << x << "," << y << "],[" << x + w << "," << y << "],[" << x + w << "," << y + h
        << "],[" << x << "," << y + h << "],[" << x << "," << y << "]]]}}";
    first = false;
  };
  const double x0 = 500000, y0 = 5000000;
  for (int bx = 0; bx < 8; ++bx) {
    for (int by = 0; by < 3; ++by) {
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) lot(x0 + bx * 90 + i * 20, y0 + by * 90 + j * 20, 20, 20);
      }
    }
  }
  for (int i = 0; i < 36; ++i) lot(x0 + i * 20, y0 - 60, 20, 30);  // 720 m long
  // An invalid lot (a bow tie, as a multipolygon) 700 m wide, across the
  // strips' edges: GDAL's spatial filter tests such a geometry against the
  // window with GEOS, which finds no intersection, and drops it.
  out << ",{\"type\":\"Feature\",\"properties\":{},\"geometry\":{\"type\":\"MultiPolygon\",\"coordinates\":[[[[" << x0
      << "," << y0 - 200 << "],[" << x0 + 700 << "," << y0 - 150 << "],[" << x0 + 700 << "," << y0 - 200 << "],[" << x0
      << "," << y0 - 150 << "],[" << x0 << "," << y0 - 200 << "]]]]}}";
  // A feature without geometry, and one far beyond any city (skipped as absurd).
  out << ",{\"type\":\"Feature\",\"id\":" << id-- << ",\"properties\":{},\"geometry\":null}";
  lot(x0 + 300, 5e12, 20, 20);
  out << "]}";
  return file.string();
}

TEST(Shards, ABlockCrossingEveryStripIsReadWholeByOneShard) {
  const fs::path dir = fs::temp_directory_path() / "parcelscope-shards-long-block";
  CompareRequest request = test::sampleCompareRequest("obb");
  request.input.path = writeLongBlockLayer(dir);
  request.input.where.clear();
  // The same as a GeoPackage, read through its R-tree.
  const std::string gpkg = (dir / "long_block.gpkg").string();
  copyFeatures(request.input.path, "1 = 1", "GPKG", gpkg);
  for (const std::string& input : {request.input.path, gpkg}) {
    SCOPED_TRACE(input);
    request.input.path = input;
    const ObservedData one = loadObserved(request.input, request.parameters);
    ASSERT_EQ(one.analysis.blocks.size(), 26u);
    ASSERT_EQ(one.layer.report.invalidRepaired, 1);
    ASSERT_EQ(one.layer.report.nullOrEmpty, 1);
    ASSERT_EQ(one.layer.report.nonFiniteSkipped, 1);
    for (int count : {2, 3, 4}) {
      SCOPED_TRACE("shards: " + std::to_string(count));
      std::vector<ShardPart> parts = analyseFiltered(request, count);
      int widened = 0;
      for (const ShardPart& p : parts) widened += p.reads > 1;
      EXPECT_GE(widened, 1) << "the long block's shard read a wider window";
      expectSameObserved(one, mergeShards(std::move(parts)));
      expectSameObserved(one, mergeShards(analyseWhole(request, count)));
    }
  }
  fs::remove_all(dir);
}

TEST(Shards, APartSurvivesEncodingAndBrokenBytesAreNamed) {
  const CompareRequest request = sampleWithRightOfWay();
  std::vector<ShardPart> parts = analyseWhole(request, 2);
  const std::string bytes = encodeShard(parts[1]);
  const ShardPart back = decodeShard(bytes, "part");
  EXPECT_EQ(encodeShard(back), bytes);
  parts[1] = back;
  expectSameObserved(loadObserved(request.input, request.parameters), mergeShards(std::move(parts)));
  // A part that breaks its own rules (a lot in no block) is refused, not merged.
  ShardPart broken = back;
  ASSERT_FALSE(broken.blocks.empty());
  broken.blocks.pop_back();
  broken.statistics.pop_back();
  EXPECT_THROW(decodeShard(encodeShard(broken), "broken.bin"), Error);
  try {
    decodeShard(bytes.substr(0, bytes.size() / 2), "half.bin");
    FAIL() << "a truncated part was decoded";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Input);
    EXPECT_NE(std::string(e.what()).find("half.bin"), std::string::npos) << e.what();
  }
  // A byte changed anywhere (a coordinate, a parcel as written, the
  // checksum itself) is refused, naming the file.
  for (const std::size_t at : {bytes.size() / 3, bytes.size() / 2, 3 * bytes.size() / 4, bytes.size() - 1}) {
    std::string damaged = bytes;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x10);
    try {
      decodeShard(damaged, "damaged.bin");
      FAIL() << "a part with byte " << at << " changed was decoded";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), Error::Kind::Input);
      EXPECT_NE(std::string(e.what()).find("damaged.bin: a damaged shard"), std::string::npos) << e.what();
    }
  }
}

TEST(Shards, AMissingOrRepeatedShardIsRefused) {
  const CompareRequest request = sampleWithRightOfWay();
  std::vector<ShardPart> parts = analyseWhole(request, 3);
  std::vector<ShardPart> missing = {parts[0], parts[2]};
  try {
    mergeShards(missing);
    FAIL() << "two of three shards merged";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing: 1"), std::string::npos) << e.what();
  }
  std::vector<ShardPart> twice = {parts[0], parts[1], parts[1]};
  EXPECT_THROW(mergeShards(twice), Error);
  EXPECT_THROW(parseShard("3/3"), Error);
  EXPECT_THROW(parseShard("1"), Error);
  EXPECT_EQ(parseShard("2/5"), std::make_pair(2, 5));
}

TEST(Shards, StreetBlocksAreNotSplit) {
  CompareRequest request = test::sampleCompareRequest("obb");
  request.streets = io::StreetReadOptions{};
  request.streets->path = request.input.path;
  EXPECT_THROW(analyseShard(request, 0, 2, ShardReading{}), Error);
}

// Bug: a layer without a usable polygon was told, in shards, as "no block to
// compare" or with GDAL's warning about an unclosed ring.
TEST(Shards, ALayerWithoutAUsablePolygonIsToldAsOneProcessTellsIt) {
  const fs::path dir = fs::temp_directory_path() / "parcelscope-shards-unusable";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "points.geojson")
      << R"({"type":"FeatureCollection","features":[)"
      << R"({"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[2.3,48.8]}},)"
      << R"({"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[2.4,48.9]}}]})";
  std::ofstream(dir / "nan.geojson")
      << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":)"
      << R"({"type":"Polygon","coordinates":[[[NaN,48.8],[2.31,48.8],[2.31,48.81],[NaN,48.8]]]}}]})";
  for (const char* name : {"points.geojson", "nan.geojson"}) {
    SCOPED_TRACE(name);
    CompareRequest request = test::sampleCompareRequest("obb");
    request.input.path = (dir / name).string();
    request.input.where.clear();
    std::string one;
    try {
      io::readParcels(request.input);
    } catch (const Error& e) {
      one = e.what();
    }
    ASSERT_NE(one.find("no usable polygon"), std::string::npos) << one;
    try {
      prepareMerged(analyseWhole(request, 2), 2, request.input);
      ADD_FAILURE() << "shards of an unusable layer were merged";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), one);
    }
  }
  fs::remove_all(dir);
}

TEST(ManyFiles, AFolderOrAListOfFilesIsReadAsOneLayer) {
  const fs::path dir = fs::temp_directory_path() / "parcelscope-many-files";
  fs::remove_all(dir);
  fs::create_directories(dir / "communes");
  CompareRequest request = sampleWithRightOfWay();
  const std::string sample = request.input.path;
  copyFeatures(sample, "FID < 60", "GeoJSON", dir / "communes" / "a.geojson");
  copyFeatures(sample, "FID >= 60 AND FID < 120", "GeoJSON", dir / "communes" / "b.geojson");
  copyFeatures(sample, "FID >= 120", "GeoJSON", dir / "communes" / "c.geojson");
  std::ofstream(dir / "communes.txt") << "# one file per commune\ncommunes/a.geojson\n\ncommunes/b.geojson\n"
                                      << (dir / "communes" / "c.geojson").string() << "\n";
  // An OGR VRT of the three, as a user writes one.
  {
    std::ofstream vrt(dir / "communes.vrt");
    vrt << "<OGRVRTDataSource><OGRVRTUnionLayer name=\"parcels\">";
    for (const char* name : {"a", "b", "c"}) {
      vrt << "<OGRVRTLayer name=\"" << name << "\"><SrcDataSource relativeToVRT=\"1\">communes/" << name
          << ".geojson</SrcDataSource><SrcLayer>" << io::layerNames((dir / "communes" / "a.geojson").string()).front()
          << "</SrcLayer></OGRVRTLayer>";
    }
    vrt << "</OGRVRTUnionLayer></OGRVRTDataSource>\n";
  }
  const ObservedData one = loadObserved(request.input, request.parameters);
  // Bug: with --where, the files' features were numbered among those that pass
  // the filter only, not as in the file they were split from.
  CompareRequest filtered = request;
  filtered.input.where = "use <> 'ROW' AND FID % 3 <> 1";
  const ObservedData oneFiltered = loadObserved(filtered.input, filtered.parameters);
  ASSERT_LT(oneFiltered.layer.parcels.size(), one.layer.parcels.size());
  for (const fs::path& input : {dir / "communes", dir / "communes.txt"}) {
    SCOPED_TRACE(input.string());
    filtered.input.path = input.string();
    expectSameObserved(oneFiltered, loadObserved(filtered.input, filtered.parameters));
    expectSameObserved(oneFiltered, mergeShards(analyseWhole(filtered, 2)));
  }
  for (const fs::path& input : {dir / "communes", dir / "communes.txt", dir / "communes.vrt"}) {
    SCOPED_TRACE(input.string());
    request.input.path = input.string();
    const bool vrt = input.extension() == ".vrt";
    EXPECT_EQ(io::inputFiles(request.input.path).size(), vrt ? 0u : 3u);
    // Features numbered in turn across the files: the ids, and so every table, of the single file.
    expectSameObserved(one, loadObserved(request.input, request.parameters));
    // In shards too: GDAL's union numbers them in turn, in every shard alike.
    expectSameObserved(one, mergeShards(analyseWhole(request, 2)));
    expectSameObserved(one, mergeShards(analyseFiltered(request, 3)));
  }
  // Files that cannot make one layer are named.
  copyFeatures(sample, "FID < 5", "GPKG", dir / "communes" / "d.gpkg");
  request.input.path = (dir / "communes").string();
  try {
    loadObserved(request.input, request.parameters);
    FAIL() << "a GeoPackage and GeoJSON files read as one layer";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("d.gpkg"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "broken.txt") << "communes/a.geojson\ncommunes/missing.geojson\n";
  request.input.path = (dir / "broken.txt").string();
  try {
    loadObserved(request.input, request.parameters);
    FAIL() << "a list naming a missing file was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
  // A list saved with a byte order mark reads; a folder or a list in a list is named.
  std::ofstream(dir / "bom.txt") << "\xEF\xBB\xBF"
                                 << "communes/a.geojson\n";
  EXPECT_EQ(io::inputFiles((dir / "bom.txt").string()).front(), (dir / "communes" / "a.geojson").string());
  std::ofstream(dir / "nested.txt") << "communes\ncommunes.txt\n";
  std::ofstream(dir / "lists.txt") << "communes.txt\n";
  for (const auto& [list, what] :
       {std::pair<const char*, const char*>{"nested.txt", "is a folder"}, {"lists.txt", "lists do not nest"}}) {
    try {
      io::inputFiles((dir / list).string());
      ADD_FAILURE() << list << " was read";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("line 1: ") + (dir / "communes").string()), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  }
  fs::remove_all(dir);
}

const std::string kCambridge =
    std::string(PARCELSCOPE_SHARED_DATASETS) + "/cambridge_ma/ASSESSING_ParcelsFY2014.topojson";

// The sample's obb request on a shared dataset (its path under
// ../shared/datasets), without a filter; empty when the dataset is absent.
std::optional<CompareRequest> obbRequestOn(const std::string& dataset) {
  const std::string path = std::string(PARCELSCOPE_SHARED_DATASETS) + "/" + dataset;
  if (!fs::exists(path)) return std::nullopt;
  CompareRequest request = test::sampleCompareRequest("obb");
  request.input.path = path;
  request.input.where.clear();
  return request;
}

// malibu_ca holds invalid multipolygons (feature 8419, for one) across the
// edges of four strips' windows, which GDAL's spatial filter drops.
TEST(SharedDatasetShards, MalibuInFourShardsGivesTheObservedDataOfOneProcess) {
  const auto request = obbRequestOn("malibu_ca/parcels.geojson");
  if (!request) GTEST_SKIP() << "shared dataset not found: malibu_ca/parcels.geojson";
  const ObservedData one = loadObserved(request->input, request->parameters);
  expectSameObserved(one, mergeShards(analyseFiltered(*request, 4)));
}

// seoul_jamsil's street net is stored as parcels, one of them thin and long
// (feature 2247): in a window that holds only part of what touches it, it
// does not count enough neighbours to be a right-of-way and joins the blocks
// around it into one; the shard whose strip it starts in then took those
// blocks for another shard's, and no shard kept it (with three shards).
TEST(SharedDatasetShards, SeoulInThreeShardsGivesTheObservedDataOfOneProcess) {
  const auto request = obbRequestOn("seoul_jamsil/parcels.geojson");
  if (!request) GTEST_SKIP() << "shared dataset not found: seoul_jamsil/parcels.geojson";
  const ObservedData one = loadObserved(request->input, request->parameters);
  ASSERT_GT(one.analysis.rightOfWayCount, 0);
  for (int count : {3, 5}) {
    SCOPED_TRACE("shards: " + std::to_string(count));
    expectSameObserved(one, mergeShards(analyseWhole(*request, count)));
  }
}

TEST(SharedDatasetShards, CambridgeInThreeShardsGivesTheTablesOfOneProcess) {
  if (!fs::exists(kCambridge)) GTEST_SKIP() << "shared dataset not found: " << kCambridge;
  CompareRequest request = test::sampleCompareRequest("obb");
  request.input.path = kCambridge;
  request.input.where = "ML <> 'ROAD'";
  auto one = std::make_shared<const ObservedData>(loadObserved(request.input, request.parameters));
  const PreparedObserved merged = prepareMerged(analyseFiltered(request, 3), 3, request.input);
  expectSameObserved(*one, *merged.data);
  const CompareResult single = compare(request, one);
  const CompareResult sharded = compare(request, merged.data, {}, merged.premade.get());
  // Every block was subdivided in its shard.
  EXPECT_EQ(sharded.generated.premadeBlocks, static_cast<std::int64_t>(sharded.generated.blocks.size()));
  expectSameGenerated(single.generated, sharded.generated);
  const auto a = comparisonTables(single);
  const auto b = comparisonTables(sharded);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t t = 0; t < a.size(); ++t) {
    EXPECT_EQ(a[t].second.rows, b[t].second.rows) << a[t].first;
  }
}

}  // namespace
}  // namespace parcelscope::pipeline
