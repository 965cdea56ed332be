#pragma once
// Exact splitting of a polygon with holes by a line (CGAL Boolean set
// operations on the exact-constructions kernel). Pieces on the two sides share
// their cut vertices exactly, so after rounding to doubles they still tile.
#include <cmath>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation::detail {

/// True when the ring is simple: no two edges meet except neighbours at their
/// shared vertex (isClearlySimple first; else exact predicates on the doubles,
/// a sweep: fast on long rings).
bool isStrictlySimple(const Ring& ring);

/// True when CGAL accepts the polygon as a valid polygon with holes (simple
/// rings, outer counter-clockwise, holes clockwise and inside, not crossing).
bool isValidForSplit(const Polygon& polygon);

/// Pieces of `polygon` left and right of the line through `pivot` with
/// direction `dir` (non-zero). Every piece is normalised.
struct SplitPieces {
  std::vector<Polygon> left, right;
  /// splitByLineFast only: a vertex touching the line on a cut pinched its
  /// side's piece there, so two of that side's pieces meet at that point.
  /// (The exact split gives such pieces as one ring touching itself.)
  bool pinched = false;
};
SplitPieces splitByLine(const Polygon& polygon, const Point& pivot, const Point& dir);

/// The same split in floating point, for a polygon whose vertices on the
/// line (exactly: the side of every vertex is certain) are crossings between
/// opposite sides or touches from one side, and whose holes the line misses:
/// the crossing points are computed once and shared by the pieces on both
/// sides, and paired into cuts in their order along the line. A touch away
/// from the cuts stays a vertex of its side's piece; a touch on a cut ends one
/// of its side's pieces and begins the next (see SplitPieces::pinched) and is
/// a vertex of the other side's piece. Each hole, wholly on one side, goes to
/// the piece there that holds it. False, with `out` untouched, for anything
/// else (a hole the line meets, a hole vertex too close to a piece's boundary
/// to place it, an edge along the line, points on the line too close along it
/// to order, a piece pinched onto itself): then the exact `splitByLine` must
/// be used.
bool splitByLineFast(const Polygon& polygon, const Point& pivot, const Point& dir, SplitPieces& out);

/// The union of interior-disjoint counter-clockwise rings without holes that
/// meet along shared edges, in floating point: edges are split at every vertex
/// of the parts lying on them (within `tolerance` of the edge, further than it
/// from its ends: T-junctions), edges that coincide (same end points, bit for
/// bit) in opposite directions cancel, and the rest is linked into rings. The
/// union's components (counter-clockwise, sharing no vertex) go to `out`.
/// False, with `out` untouched, when the rest does not link into such rings (a
/// hole, two parts touching at a point, an edge repeated: overlapping parts)
/// or when the rings' area is not the parts' (to 1e-9): then the exact join
/// must be used.
bool joinRingsFast(const std::vector<const Ring*>& parts, double tolerance, std::vector<Ring>& out);

/// True when the edge y-z returns along the edge x-y (they overlap past y):
/// opposite directions, parallel to 1e-9 of their lengths' product.
inline bool foldsBack(const Point& x, const Point& y, const Point& z) {
  const Point e1{y.x - x.x, y.y - x.y}, e2{z.x - y.x, z.y - y.y};
  const double cr = e1.x * e2.y - e1.y * e2.x, dot = e1.x * e2.x + e1.y * e2.y;
  return dot < 0 && std::fabs(cr) <= 1e-9 * norm(e1.x, e1.y) * norm(e2.x, e2.y);
}

/// Proves strictly simple a ring of a piece that splitByLineFast(polygon,
/// pivot, dir) gave, when `polygon` has no holes and a strictly simple outer
/// ring, by looking only at the edges the split made or shortened: those with
/// an end on the line. False when it cannot prove it (the ring may still be
/// simple). `bounds` are the ring's. With `cutsClear`, the caller has
/// checked that the edges with both ends on the line keep 1e-6 of the ring's
/// size (bounds width + height) from every edge but their neighbours and do
/// not fold back (as the OBB split does for every part): they are not
/// checked again.
bool splitPieceIsSimple(const Ring& ring, const Box& bounds, const Point& pivot, const Point& dir,
                        bool cutsClear = false);

}  // namespace parcelscope::generation::detail
