#pragma once
// Moving a block next to the origin for exact computation (CGAL's exact kernel
// and straight skeletons both work best there), and back.
#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation::detail {

/// The offset to subtract from `block`'s coordinates: its bounding-box centre,
/// per axis, where that shift is exact both ways (by Sterbenz's lemma x - o is
/// exact when o/2 <= x <= 2o, and then (x - o) + o == x), and 0 where it is not
/// (blocks already near the origin, as io/'s local frame puts them, stay put).
inline Point exactShiftOrigin(const Polygon& block) {
  const Box b = bounds(block);
  Point o{0.5 * (b.minX + b.maxX), 0.5 * (b.minY + b.maxY)};
  auto exact = [](double lo, double hi, double c) {
    return (c > 0 && lo >= 0.5 * c && hi <= 2 * c) || (c < 0 && hi <= 0.5 * c && lo >= 2 * c);
  };
  if (!exact(b.minX, b.maxX, o.x)) o.x = 0;
  if (!exact(b.minY, b.maxY, o.y)) o.y = 0;
  return o;
}

inline void translate(Polygon& r, double dx, double dy) {
  for (Point& q : r.outer) q = {q.x + dx, q.y + dy};
  for (Ring& h : r.holes)
    for (Point& q : h) q = {q.x + dx, q.y + dy};
}

inline Polygon translated(const Polygon& in, double dx, double dy) {
  Polygon r = in;
  translate(r, dx, dy);
  return r;
}

}  // namespace parcelscope::generation::detail
