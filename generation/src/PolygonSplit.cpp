#include "PolygonSplit.h"

#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polygon_with_holes_2.h>

#include <cmath>
#include <iterator>

namespace parcelscope::generation::detail {

namespace {
using K = CGAL::Exact_predicates_exact_constructions_kernel;
using P2 = CGAL::Polygon_2<K>;
using PWH = CGAL::Polygon_with_holes_2<K>;
using Traits = CGAL::Gps_segment_traits_2<K>;

P2 toCgal(const Ring& ring) {
  P2 p;
  for (const Point& v : ring) p.push_back(K::Point_2(v.x, v.y));
  return p;
}

PWH toCgal(const Polygon& polygon) {
  P2 outer = toCgal(polygon.outer);
  if (outer.orientation() != CGAL::COUNTERCLOCKWISE) outer.reverse_orientation();
  std::vector<P2> holes;
  for (const Ring& h : polygon.holes) {
    P2 hole = toCgal(h);
    if (hole.orientation() != CGAL::CLOCKWISE) hole.reverse_orientation();
    holes.push_back(std::move(hole));
  }
  return PWH(outer, holes.begin(), holes.end());
}

Ring fromCgal(const P2& p) {
  Ring r;
  r.reserve(p.size());
  for (auto v = p.vertices_begin(); v != p.vertices_end(); ++v) {
    r.push_back({CGAL::to_double(v->x()), CGAL::to_double(v->y())});
  }
  return r;
}

std::vector<Polygon> clip(const PWH& polygon, const P2& halfPlane) {
  // With explicit segment traits: the default for Epeck polygons converts to
  // polylines, a path that leaks in CGAL 5.5.
  std::vector<PWH> parts;
  Traits traits;
  CGAL::intersection(polygon, halfPlane, std::back_inserter(parts), traits);
  std::vector<Polygon> out;
  for (const PWH& part : parts) {
    Polygon p;
    p.outer = fromCgal(part.outer_boundary());
    for (auto h = part.holes_begin(); h != part.holes_end(); ++h) p.holes.push_back(fromCgal(*h));
    if (normalise(p)) out.push_back(std::move(p));
  }
  return out;
}
}  // namespace

bool isValidForSplit(const Polygon& polygon) {
  if (polygon.outer.size() < 3) return false;
  Traits traits;
  return CGAL::is_valid_polygon_with_holes(toCgal(polygon), traits);
}

SplitPieces splitByLine(const Polygon& polygon, const Point& pivot, const Point& dir) {
  const Box b = bounds(polygon);
  const double reach = 4.0 * (b.width() + b.height()) + 1.0 +
                       std::fabs(pivot.x - b.minX) + std::fabs(pivot.y - b.minY);
  const double len = norm(dir.x, dir.y);
  const double ux = dir.x / len, uy = dir.y / len;
  const K::Point_2 a(pivot.x - ux * reach, pivot.y - uy * reach);
  const K::Point_2 c(pivot.x + ux * reach, pivot.y + uy * reach);
  const K::Vector_2 n(-uy * reach, ux * reach);  // left normal
  P2 left, right;
  left.push_back(a);
  left.push_back(c);
  left.push_back(c + n);
  left.push_back(a + n);
  right.push_back(c);
  right.push_back(a);
  right.push_back(a - n);
  right.push_back(c - n);
  const PWH p = toCgal(polygon);
  return {clip(p, left), clip(p, right)};
}

}  // namespace parcelscope::generation::detail
