// Blocks from a real street network (cambridge_ma's 2,614 centre lines, no
// widths: measured from the parcels): they match the blocks grouped from the
// observed parcels, and every style keeps its invariants in them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>

#include "TestUtil.h"
#include "generation/TilingCheck.h"
#include "parcelscope/core/BoxIndex.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/GenerateJob.h"
#include "parcelscope/pipeline/StreetsJob.h"

namespace parcelscope::pipeline {
namespace {

namespace bgi = boost::geometry::index;

io::ReadOptions cambridgeParcels() {
  io::ReadOptions o;
  o.path = test::sharedDataset("cambridge_ma/ASSESSING_ParcelsFY2014.topojson");
  o.where = "ML <> 'ROAD'";
  return o;
}

io::StreetReadOptions cambridgeStreets() {
  io::StreetReadOptions o;
  o.path = test::sharedDataset("cambridge_ma/TRANS_Centerlines.geojson");
  o.nameField = "Street";
  return o;
}

ParameterValues defaults() {
  ParameterValues v = defaultValues(analysis::analysisParameters());
  for (const auto& [name, value] : defaultValues(streetParameters())) v[name] = value;
  return v;
}

// Of each parcel block, the best intersection over union with a street block.
std::vector<double> bestIou(const std::vector<Polygon>& parcelBlocks, const std::vector<const Polygon*>& street) {
  std::vector<std::pair<IndexBox, int>> boxes;
  for (std::size_t i = 0; i < street.size(); ++i) boxes.push_back({indexBox(bounds(*street[i])), static_cast<int>(i)});
  const BoxTree<int> tree(boxes.begin(), boxes.end());
  std::vector<double> iou(parcelBlocks.size(), 0);
  parallelFor(parcelBlocks.size(), [&](std::size_t k) {
    const Polygon& p = parcelBlocks[k];
    for (auto it = tree.qbegin(bgi::intersects(indexBox(bounds(p)))); it != tree.qend(); ++it) {
      const Polygon& s = *street[static_cast<std::size_t>(it->second)];
      const double i = geos::intersectionArea(p, s);
      iou[k] = std::max(iou[k], i / (area(p) + area(s) - i));
    }
  });
  return iou;
}

// Every flag names one parameter: the street network's parameters do not
// share a name with the analysis, generator or comparison parameters (the
// street snap once did with obb's snap).
TEST(StreetParameters, NamesAreTheirOwn) {
  std::map<std::string, int> seen;
  for (const auto& d : compareParameters()) ++seen[d.name];
  for (const auto& d : streetParameters()) {
    EXPECT_EQ(seen.count(d.name), 0u) << d.name << " is a compare parameter too";
    ++seen[d.name];
  }
  EXPECT_EQ(seen.count("street-snap"), 1u);
}

TEST(StreetBlocks, CambridgeStreetBlocksMatchTheParcelBlocks) {
  PARCELSCOPE_REQUIRE_SHARED_DATASETS();
  const ObservedData observed = loadObserved(cambridgeParcels(), defaults());
  const StreetNetwork network = buildStreetNetwork(cambridgeStreets(), defaults(), &observed);
  std::vector<Polygon> parcelBlocks;
  for (const Block& b : observed.analysis.blocks) {
    for (const Polygon& part : b.parts) parcelBlocks.push_back(part);
  }
  std::vector<const Polygon*> street;
  for (const auto& b : network.blocks.blocks) street.push_back(&b.shape);
  std::vector<double> iou = bestIou(parcelBlocks, street);
  const auto matched = std::count_if(iou.begin(), iou.end(), [](double v) { return v >= 0.8; });
  std::nth_element(iou.begin(), iou.begin() + static_cast<long>(iou.size() / 2), iou.end());
  const double share = static_cast<double>(matched) / static_cast<double>(iou.size());
  std::printf(
      "cambridge_ma: %zu street blocks (%lld widths measured, %lld default), %zu parcel block parts; "
      "IoU >= 0.8: %.1f %%, median IoU %.3f\n",
      street.size(), static_cast<long long>(network.widthsMeasured), static_cast<long long>(network.widthsDefault),
      parcelBlocks.size(), 100 * share, iou[iou.size() / 2]);
  EXPECT_GE(share, 0.85);
  EXPECT_GE(iou[iou.size() / 2], 0.93);
  for (const auto& b : network.blocks.blocks) EXPECT_TRUE(geos::isValid(b.shape)) << keyText(b.key);
}

// Every style keeps its invariants in street blocks: parcels tile each block
// (valid, no overlap, no gap), each has street access in obb at xi = 1, and
// the same seed gives the same parcels.
class StreetBlockStyles : public ::testing::TestWithParam<const char*> {};

TEST_P(StreetBlockStyles, CambridgeStreetBlocksAreTiledValidlyWithStreetAccess) {
  PARCELSCOPE_REQUIRE_SHARED_DATASETS();
  GenerateRequest request;
  request.input = cambridgeParcels();
  request.fromParcels = true;
  request.streets = cambridgeStreets();
  request.style = GetParam();
  request.parameters = defaults();
  for (const auto& [name, value] : defaultValues(generation::generationParameterDescriptions())) {
    request.parameters[name] = value;
  }
  const GeneratedParcels g = generate(request);
  ASSERT_TRUE(g.streets);
  ASSERT_EQ(g.blocks.size(), g.streets->blocks.blocks.size());
  int failed = 0, withoutAccess = 0;
  for (std::size_t b = 0; b < g.blocks.size(); ++b) {
    std::vector<Polygon> parcels;
    for (int p : g.blocks[b].parcels) parcels.push_back(g.parcels[static_cast<std::size_t>(p)]);
    const test::TilingReport r = test::checkTiling(g.blocks[b].parts.front(), parcels);
    const std::string what = std::string(GetParam()) + " street block " + keyText(g.blockKeys[b]);
    EXPECT_LE(r.areaError, 1e-6) << what;
    EXPECT_LE(r.maxOverlap, 1e-6) << what;
    EXPECT_EQ(r.invalid, 0) << what;
    EXPECT_EQ(r.outside, 0) << what;
  }
  for (const auto& m : g.metrics) withoutAccess += !m.streetAccess;
  failed = static_cast<int>(g.failedBlocks);
  std::printf(
      "cambridge_ma street blocks, %s: %zu blocks, %zu parcels, %d without street access, %lld fell back to "
      "obb, %d failed\n",
      GetParam(), g.blocks.size(), g.parcels.size(), withoutAccess, static_cast<long long>(g.fallbackBlocks), failed);
  EXPECT_EQ(failed, 0);
  if (std::string(GetParam()) == "obb") EXPECT_EQ(g.withoutAccess, 0);
  const GeneratedParcels again = generate(request);
  ASSERT_EQ(again.parcels.size(), g.parcels.size());
  for (std::size_t i = 0; i < g.parcels.size(); ++i) {
    ASSERT_TRUE(sameVertices(again.parcels[i], g.parcels[i])) << "parcel " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Styles, StreetBlockStyles, ::testing::Values("obb", "skeleton"),
                         [](const auto& param) { return std::string(param.param); });

}  // namespace
}  // namespace parcelscope::pipeline
