#pragma once
// R-trees of axis-aligned boxes (Boost.Geometry's rtree), for finding the
// shapes near a shape: the street network's segments and faces, the blocks a
// parcel may overlap. Header-only; query with boost::geometry::index::intersects.
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <utility>

#include "parcelscope/core/Geometry.h"

namespace parcelscope {

using IndexPoint = boost::geometry::model::point<double, 2, boost::geometry::cs::cartesian>;
using IndexBox = boost::geometry::model::box<IndexPoint>;

/// `b` grown by `pad` on every side, as an index box.
inline IndexBox indexBox(const Box& b, double pad = 0) {
  return {IndexPoint(b.minX - pad, b.minY - pad), IndexPoint(b.maxX + pad, b.maxY + pad)};
}

/// An R-tree of (box, value) entries.
template <typename Value>
using BoxTree = boost::geometry::index::rtree<std::pair<IndexBox, Value>, boost::geometry::index::quadratic<16>>;

}  // namespace parcelscope
