#pragma once
// Street access of generated parcels measured independently of the library's
// own access test (analysis::PreparedBoundary, sharedBoundaryLength): with
// GEOS, as the length of a parcel's boundary lying within a tolerance of the
// block's outer ring. Tests that include this link GEOS::geos_c.
#include <geos_c.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::test {

class GeosFrontage {
public:
  /// The outer ring of `block`, widened by `tolerance` metres on both sides.
  GeosFrontage(const Polygon& block, double tolerance) : ctx_(GEOS_init_r()) {
    GEOSGeometry* ring = makeRing(block.outer);
    street_ = ring ? GEOSBuffer_r(ctx_, ring, tolerance, 2) : nullptr;
    if (ring) GEOSGeom_destroy_r(ctx_, ring);
    if (!street_) throw std::runtime_error("GEOS could not buffer the block's outer ring");
  }
  ~GeosFrontage() {
    if (street_) GEOSGeom_destroy_r(ctx_, street_);
    GEOS_finish_r(ctx_);
  }
  GeosFrontage(const GeosFrontage&) = delete;
  GeosFrontage& operator=(const GeosFrontage&) = delete;

  /// Length in m of the parcel's boundary (every ring) within the tolerance of
  /// the block's outer ring; -1 when GEOS fails.
  double length(const Polygon& parcel) const {
    double total = 0;
    std::vector<const Ring*> rings{&parcel.outer};
    for (const Ring& h : parcel.holes) rings.push_back(&h);
    for (const Ring* r : rings) {
      GEOSGeometry* ring = makeRing(*r);
      if (!ring) return -1;
      GEOSGeometry* near = GEOSIntersection_r(ctx_, ring, street_);
      GEOSGeom_destroy_r(ctx_, ring);
      if (!near) return -1;
      double l = 0;
      const bool ok = GEOSLength_r(ctx_, near, &l) == 1;
      GEOSGeom_destroy_r(ctx_, near);
      if (!ok) return -1;
      total += l;
    }
    return total;
  }

private:
  // A closed line string through the ring's vertices (null for fewer than 3).
  GEOSGeometry* makeRing(const Ring& r) const {
    if (r.size() < 3) return nullptr;
    GEOSCoordSequence* seq = GEOSCoordSeq_create_r(ctx_, static_cast<unsigned>(r.size() + 1), 2);
    for (unsigned i = 0; i <= r.size(); ++i) {
      const Point& p = r[i % r.size()];
      GEOSCoordSeq_setXY_r(ctx_, seq, i, p.x, p.y);
    }
    return GEOSGeom_createLineString_r(ctx_, seq);
  }

  GEOSContextHandle_t ctx_;
  GEOSGeometry* street_ = nullptr;
};

/// Parcels of `parcels` sharing less than `minFrontage` of the block's outer
/// ring, measured with GEOS within a
/// tolerance of max(1 um, 1e-9 of the block's size); -1 when GEOS fails.
inline int geosWithoutAccess(const Polygon& block, const std::vector<Polygon>& parcels, double minFrontage) {
  const Box b = bounds(block);
  const GeosFrontage street(block, std::max(1e-6, 1e-9 * (b.width() + b.height())));
  int without = 0;
  for (const Polygon& q : parcels) {
    const double l = street.length(q);
    if (l < 0) return -1;
    without += l < minFrontage;
  }
  return without;
}

}  // namespace parcelscope::test
