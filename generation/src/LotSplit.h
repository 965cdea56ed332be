#pragma once
// What the lot-splitting styles (parish, sexton) share: a lot's sides (runs
// of nearly collinear edges) and its split by a line into valid pieces.
#include <functional>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation::detail {

/// A straight run of a ring's edges.
struct Side {
  Point a, b;  ///< first and last vertex of the run
  double length = 0;
  Point dir;              ///< unit, a to b
  std::size_t first = 0;  ///< index in the ring of its first edge (edge i runs from vertex i to i + 1)
  std::size_t edges = 0;  ///< how many edges it holds
};

/// Unit vector from a to b ((1, 0) when they coincide).
Point unitFrom(const Point& a, const Point& b);
/// Angle between two unit vectors, radians in [0, pi].
double angleBetween(const Point& u, const Point& v);

/// Consecutive edges turning by less than this from the run they continue
/// are one side: real blocks carry many vertices along one straight street.
constexpr double kSideTurn = 10.0 * kPi / 180.0;

/// The sides of a ring: maximal runs of edges each within kSideTurn of the
/// run's chord so far, starting at the sharpest corner (so none wraps around).
std::vector<Side> sidesOf(const Ring& ring);

/// A straight line: a point on it and its direction.
struct SplitLine {
  Point through, dir;
};

/// The pieces of `lot` (area `lotArea`) on both sides of `line`, in floating
/// point when that split applies and keeps the lot's area, exactly (CGAL)
/// otherwise; empty when the line does not split the lot in two or more
/// pieces or a piece is not a valid polygon. Without `exact`, nothing where
/// the floating-point split does not apply (a line meeting a hole, a vertex
/// on the line): the exact split costs some hundred times more. With
/// `admissible`, pieces it refuses give nothing before their validity is
/// checked (the costly part when most random lines are refused).
std::vector<Polygon> splitLot(const Polygon& lot, double lotArea, const SplitLine& line, bool exact = true,
                              const std::function<bool(const std::vector<Polygon>&)>& admissible = {});

}  // namespace parcelscope::generation::detail
