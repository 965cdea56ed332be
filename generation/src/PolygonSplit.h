#pragma once
// Exact splitting of a polygon with holes by a line (CGAL Boolean set
// operations on the exact-constructions kernel). Pieces on the two sides share
// their cut vertices exactly, so after rounding to doubles they still tile.
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation::detail {

/// True when CGAL accepts the polygon as a valid polygon with holes (simple
/// rings, outer counter-clockwise, holes clockwise and inside, not crossing).
bool isValidForSplit(const Polygon& polygon);

/// Pieces of `polygon` left and right of the line through `pivot` with
/// direction `dir` (non-zero). Every piece is normalised.
struct SplitPieces {
  std::vector<Polygon> left, right;
};
SplitPieces splitByLine(const Polygon& polygon, const Point& pivot, const Point& dir);

/// The same split in floating point, for the common case only: a polygon
/// without holes that the line crosses exactly twice, every vertex clearly on
/// one side (the sign of its offset from the line is certain despite rounding).
/// The two crossing points are computed once and shared by both pieces.
/// False, with `out` untouched, when the case is not that one: then the exact
/// `splitByLine` must be used.
bool splitByLineFast(const Polygon& polygon, const Point& pivot, const Point& dir, SplitPieces& out);

}  // namespace parcelscope::generation::detail
