#pragma once
// Pairs of overlapping boxes (CGAL's box_intersection_d), kept out of headers
// that other modules include.
#include <utility>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::analysis::detail {

/// Every pair (i, j), i < j, of boxes that intersect (closed boxes), sorted.
std::vector<std::pair<int, int>> intersectingPairs(const std::vector<Box>& boxes);

}  // namespace parcelscope::analysis::detail
