// Blocks from a real street network (cambridge_ma's 2,614 centre lines, no
// widths: measured from the parcels): they match the blocks grouped from the
// observed parcels, and every style keeps its invariants in them.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <cstdio>
#include <cstdlib>

#include "TestUtil.h"
#include "generation/TilingCheck.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/pipeline/GenerateJob.h"
#include "parcelscope/pipeline/StreetsJob.h"

namespace parcelscope::pipeline {
namespace {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using BPoint = bg::model::point<double, 2, bg::cs::cartesian>;
using BBox = bg::model::box<BPoint>;

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
  std::vector<std::pair<BBox, int>> boxes;
  for (std::size_t i = 0; i < street.size(); ++i) {
    const Box b = bounds(*street[i]);
    boxes.push_back({BBox(BPoint(b.minX, b.minY), BPoint(b.maxX, b.maxY)), static_cast<int>(i)});
  }
  const bgi::rtree<std::pair<BBox, int>, bgi::quadratic<16>> tree(boxes.begin(), boxes.end());
  std::vector<double> iou(parcelBlocks.size(), 0);
  parallelFor(parcelBlocks.size(), [&](std::size_t k) {
    const Polygon& p = parcelBlocks[k];
    const Box b = bounds(p);
    for (auto it = tree.qbegin(bgi::intersects(BBox(BPoint(b.minX, b.minY), BPoint(b.maxX, b.maxY))));
         it != tree.qend(); ++it) {
      const Polygon& s = *street[static_cast<std::size_t>(it->second)];
      const double i = geos::intersectionArea(p, s);
      iou[k] = std::max(iou[k], i / (area(p) + area(s) - i));
    }
  });
  return iou;
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
  if (std::getenv("PARCELSCOPE_DIAG")) {
    for (std::size_t k = 0; k < iou.size(); ++k) {
      if (iou[k] >= 0.8) continue;
      const Polygon& p = parcelBlocks[k];
      double covered = 0;
      int pieces = 0;
      double bestArea = 0, bestI = 0;
      for (const Polygon* s : street) {
        const double i = geos::intersectionArea(p, *s);
        if (i > 0.05 * area(p)) ++pieces;
        covered += i;
        if (i > bestI) {
          bestI = i;
          bestArea = area(*s);
        }
      }
      const Point c = centroid(p);
      const Point g = observed.layer.frame.toSource(c);
      std::printf("DIAG iou %.3f area %.0f covered %.3f pieces %d best street area %.0f at %.6f,%.6f\n", iou[k],
                  area(p), covered / area(p), pieces, bestArea, g.x, g.y);
    }
  }
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

}  // namespace
}  // namespace parcelscope::pipeline
