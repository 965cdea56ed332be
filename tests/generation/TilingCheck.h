#pragma once
// What users rely on in generated parcels, checked as a polygonal coverage:
// they tile the block (areas sum to its area), do not overlap, and are valid.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "parcelscope/analysis/Metrics.h"
#include "parcelscope/core/Geometry.h"
#include "parcelscope/core/GeosOps.h"

namespace parcelscope::test {

struct TilingReport {
  double areaError = 0;   ///< |sum of parcel areas - block area| / block area
  double maxOverlap = 0;  ///< largest pairwise overlap / block area
  int invalid = 0;        ///< parcels GEOS finds invalid
  int outside = 0;        ///< parcels with an interior point outside the block
};

inline TilingReport checkTiling(const Polygon& block, const std::vector<Polygon>& parcels) {
  TilingReport r;
  const double blockArea = area(block);
  double sum = 0;
  std::vector<Box> boxes;
  for (const Polygon& p : parcels) {
    sum += area(p);
    boxes.push_back(bounds(p));
    if (!geos::isValid(p)) ++r.invalid;
    if (!pointInPolygon(interiorPoint(p), block)) ++r.outside;
  }
  r.areaError = std::fabs(sum - blockArea) / blockArea;
  for (std::size_t i = 0; i < parcels.size(); ++i) {
    for (std::size_t j = i + 1; j < parcels.size(); ++j) {
      if (!boxes[i].intersects(boxes[j])) continue;
      try {
        r.maxOverlap = std::max(r.maxOverlap, geos::intersectionArea(parcels[i], parcels[j]) / blockArea);
      } catch (const std::exception&) {
        r.maxOverlap = 1.0;  // GEOS could not intersect them: count as overlapping
      }
    }
  }
  return r;
}

/// Parcels that share less than `minFrontage` of the block's outer ring, as
/// measured (the OBB subdivision's access test, with its tolerance).
inline int measuredWithoutAccess(const Polygon& block, const std::vector<Polygon>& parcels, double minFrontage) {
  const Polygon outer{block.outer, {}};  // PreparedBoundary refers to it
  const Box b = bounds(outer);
  const analysis::PreparedBoundary outline(outer, std::max(1e-6, 1e-9 * (b.width() + b.height())));
  int without = 0;
  for (const Polygon& q : parcels) without += !outline.sharesAtLeast(q, minFrontage);
  return without;
}

/// Parcels narrower than `wMin`, width as the OBB style measures it (the short
/// side of the minimum-area box of the outer ring), to a relative 1e-9.
inline int narrowerThan(const std::vector<Polygon>& parcels, double wMin) {
  int narrow = 0;
  for (const Polygon& q : parcels) narrow += minimumAreaBox(q.outer).width < wMin * (1 - 1e-9);
  return narrow;
}

#define EXPECT_TILES(block, parcels, what)                                 \
  do {                                                                     \
    const auto report_ = ::parcelscope::test::checkTiling(block, parcels); \
    EXPECT_LE(report_.areaError, 1e-6) << what;                            \
    EXPECT_LE(report_.maxOverlap, 1e-6) << what;                           \
    EXPECT_EQ(report_.invalid, 0) << what;                                 \
    EXPECT_EQ(report_.outside, 0) << what;                                 \
  } while (0)

}  // namespace parcelscope::test
