#pragma once
// The inner part of a polygon's straight skeleton (CGAL, with the skeleton
// style's guard against broken constructions and its work budget), for styles
// that need a block's medial spine (sexton).
#include <cstddef>
#include <utility>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation::detail {

/// The skeleton nodes that are not contour vertices, each with its distance to
/// the contour (its time), and the skeleton edges joining two of them.
struct InnerSkeleton {
  std::vector<Point> nodes;
  std::vector<double> time;
  std::vector<std::pair<int, int>> edges;  ///< indices into nodes, each edge once
};

/// The inner skeleton of a counter-clockwise ring without repeated vertices,
/// near the origin. Throws StyleFailure when CGAL cannot build the skeleton or
/// it makes more than `maxEvents` events.
InnerSkeleton innerSkeleton(const Ring& ring, std::size_t maxEvents);

}  // namespace parcelscope::generation::detail
