#pragma once
// Exact splitting of a polygon with holes by a line (CGAL Boolean set
// operations on the exact-constructions kernel). Pieces on the two sides share
// their cut vertices exactly, so after rounding to doubles they still tile.
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation::detail {

/// True when the ring is simple: no two edges meet except neighbours at their
/// shared vertex (exact predicates on the doubles, a sweep: fast on long rings).
bool isStrictlySimple(const Ring& ring);

/// True when CGAL accepts the polygon as a valid polygon with holes (simple
/// rings, outer counter-clockwise, holes clockwise and inside, not crossing).
bool isValidForSplit(const Polygon& polygon);

/// Pieces of `polygon` left and right of the line through `pivot` with
/// direction `dir` (non-zero). Every piece is normalised.
struct SplitPieces {
  std::vector<Polygon> left, right;
};
SplitPieces splitByLine(const Polygon& polygon, const Point& pivot, const Point& dir);

/// The same split in floating point, for a polygon without holes whose
/// vertices on the line (exactly: the side of every vertex is certain) are
/// crossings between opposite sides or touches from one side away from every
/// cut: the crossing points are computed once and shared by the pieces on
/// both sides, and paired into cuts in their order along the line. False, with
/// `out` untouched, for anything else (holes, a touch on a cut, an edge along
/// the line, crossings too close along the line to order): then the exact
/// `splitByLine` must be used.
bool splitByLineFast(const Polygon& polygon, const Point& pivot, const Point& dir, SplitPieces& out);

}  // namespace parcelscope::generation::detail
