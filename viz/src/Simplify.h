#pragma once
// Shapes with fewer vertices for drawing a map at a coarse scale, keeping the
// boundaries that shapes share shared: no gap opens between neighbours.
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::viz::detail {

/// Copies of `shapes` without the vertices that lie within `tolerance` of the
/// simplified boundary (Douglas-Peucker on each run of boundary between
/// junctions). A junction is a vertex that some ring holding it does not see
/// between the same two neighbours as another ring holding it (where shared
/// boundaries meet, begin or end): it is always kept. A run is simplified the
/// same way from either end, so two shapes sharing a run keep the same
/// vertices of it. A ring without junctions keeps its smallest vertex (by x,
/// then y) and the vertex farthest from it. Rings left with fewer than three
/// vertices are kept empty (shapes thinner than the tolerance); holes are
/// simplified like outer rings. tolerance <= 0 copies the shapes. `out` is
/// resized to one shape per input shape and its rings are overwritten (their
/// memory reused).
void simplifyShared(const std::vector<const Polygon*>& shapes, double tolerance, std::vector<Polygon>& out);

}  // namespace parcelscope::viz::detail
