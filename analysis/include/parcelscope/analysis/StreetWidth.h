#pragma once
// Street width along block edges, measured from the block layout: the distance
// from the middle of each edge, straight out (perpendicular to the edge), to
// the nearest edge of another block. It feeds the skeleton style's StreetWidth
// rule (Vanegas et al. 2012, 4.2.2: corner parcels face the wider street).
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::analysis {

/// widths[b][r][i]: for block b (normalised), ring r (0 the outer ring, then the
/// holes), the edge from vertex i to i+1: the street width in m, or NaN when no
/// other block lies within `maxWidth` straight out from the edge's middle.
/// Edges shorter than 1 mm get NaN.
std::vector<std::vector<std::vector<double>>> streetWidths(const std::vector<const Polygon*>& blocks,
                                                           double maxWidth = 60.0);

}  // namespace parcelscope::analysis
