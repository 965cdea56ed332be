#pragma once
// Dissolving a coverage: the outline of polygons that meet along shared edges,
// as the parcels of one block do. Where the shared edges have the same
// vertices on both sides, the union is a matter of cancelling each edge with
// its reverse and chaining what is left into rings; no overlay is needed.
#include <optional>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope {

struct DissolveOptions {
  /// Split every edge at the other polygons' vertices lying within `snap`
  /// metres of it first (a vertex on a neighbour's edge, a T-junction). 0 keeps
  /// the edges as they are.
  double snap = 0;
};

/// The union of `polygons` (normalised, see `normalise`) when they form a
/// coverage: every edge two of them share appears in both, once each way.
/// Shared edges cancel; the edges left are chained into rings, counter-
/// clockwise ones outer rings and clockwise ones holes of the smallest outer
/// ring holding them. Rings start at their lowest (x, then y) vertex and parts
/// come in order of it, so the result does not depend on the input order.
///
/// Where polygons or holes touch at a vertex, the rings are kept apart there
/// (they touch, as a valid polygon's rings may).
///
/// Returns nothing when the edges left do not chain into rings: an edge present
/// twice in one direction (overlap), a vertex with more edges ending than
/// starting, a ring of zero area, or a hole outside every outer ring. A result
/// is not proven valid:
/// polygons that overlap without sharing edges give crossing rings, so check
/// it (GEOS) before use.
std::optional<std::vector<Polygon>> dissolveCoverage(const std::vector<const Polygon*>& polygons,
                                                     const DissolveOptions& options = {});

}  // namespace parcelscope
