#pragma once
// Ear clipping of one small simple ring, for filling map shapes: VTK's ear cut
// (vtkPolygon::Triangulate) keeps a priority queue and allocates for every
// shape, and took most of the time of building a view's geometry.
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::viz::detail {

/// Rings up to this many vertices are clipped here (the clipping's cost grows
/// with the square of the count, or worse for spiral-like rings); larger ones
/// are left to VTK.
constexpr std::size_t kEarClipMaxVertices = 256;

/// Appends to `triangles` the ring's triangles as triples of vertex indices:
/// ring.size() - 2 triangles, none turning against the ring, together covering
/// it exactly once (collinear vertices may give triangles without area).
/// Returns false, leaving `triangles` as it was, when the ring has fewer than 3
/// or more than kEarClipMaxVertices vertices, no area, or a pass over its
/// vertices finds no ear (a ring that is not simple).
bool earClip(const Ring& ring, std::vector<int>& triangles);

}  // namespace parcelscope::viz::detail
