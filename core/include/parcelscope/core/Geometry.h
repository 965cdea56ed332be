#pragma once
// Plain geometry types used across ParcelScope. Coordinates are metres in the
// local projected plane chosen at import (io/ does every reprojection), with the
// origin near the data so that exact-arithmetic libraries stay accurate.
#include <vector>

namespace parcelscope {

constexpr double kPi = 3.14159265358979323846;

struct Point {
  double x = 0;
  double y = 0;
};

/// A closed ring stored without repeating its first vertex.
using Ring = std::vector<Point>;

/// A polygon with holes. Normalised form (see `normalise`): outer ring
/// counter-clockwise, holes clockwise, no repeated consecutive vertices.
struct Polygon {
  Ring outer;
  std::vector<Ring> holes;
};

struct Box {
  double minX = 0, minY = 0, maxX = 0, maxY = 0;
  double width() const { return maxX - minX; }
  double height() const { return maxY - minY; }
  bool intersects(const Box& o) const { return minX <= o.maxX && o.minX <= maxX && minY <= o.maxY && o.minY <= maxY; }
  Box expanded(double d) const { return {minX - d, minY - d, maxX + d, maxY + d}; }
};

/// Length of the vector (dx, dy). Plain sqrt: local coordinates are small, and
/// std::hypot's overflow care costs several times more on hot paths.
inline double norm(double dx, double dy) { return __builtin_sqrt(dx * dx + dy * dy); }

/// Signed area of a ring in m² (positive when counter-clockwise), shoelace formula.
double signedArea(const Ring& ring);
/// Area in m²: outer area minus hole areas.
double area(const Polygon& polygon);
/// Length of a ring's boundary in m.
double ringLength(const Ring& ring);
/// Total boundary length in m, outer ring and holes.
double perimeter(const Polygon& polygon);
Box bounds(const Ring& ring);
Box bounds(const Polygon& polygon);
/// Area-weighted centroid of the polygon (holes subtracted).
Point centroid(const Polygon& polygon);

/// Removes repeated consecutive vertices and a closing vertex equal to the first,
/// makes the outer ring counter-clockwise and holes clockwise, and drops holes
/// with fewer than 3 vertices. Returns false if the outer ring is degenerate
/// (fewer than 3 distinct vertices or zero area).
bool normalise(Polygon& polygon);

/// True when `a` and `b` have the same rings with the same coordinates, vertex
/// for vertex (exact comparison: a result that may be reused for the other).
bool sameVertices(const Polygon& a, const Polygon& b);

/// Even-odd point-in-ring test; points on the boundary may go either way.
bool pointInRing(const Point& p, const Ring& ring);
/// True when `p` is inside the outer ring and outside every hole.
bool pointInPolygon(const Point& p, const Polygon& polygon);
/// A point strictly inside the polygon (not merely its centroid, which can lie
/// outside a concave shape). Falls back to the first vertex for degenerate input.
Point interiorPoint(const Polygon& polygon);

/// Distance in m from point p to segment [a, b].
double pointSegmentDistance(const Point& p, const Point& a, const Point& b);
/// Distance in m between segments [a, b] and [c, d] (0 when they cross).
double segmentDistance(const Point& a, const Point& b, const Point& c, const Point& d);

/// A fast, conservative validity test for one ring: true only when the ring
/// clearly is simple (no edge comes within 1e-9 of the ring's size of a
/// non-adjacent edge, no zero-length edge, no fold-back, non-zero area).
/// False means "not proven": ask GEOS or an exact test. Rings of more than 64
/// vertices are checked by a sweep over their edges' boxes.
bool isClearlySimple(const Ring& ring);
/// The same, given the ring's bounds and signedArea (computed already).
bool isClearlySimple(const Ring& ring, const Box& bounds, double signedArea);

/// Convex hull of a point set, counter-clockwise, without collinear points.
Ring convexHull(const std::vector<Point>& points);
/// The same into `hull` (its storage reused): no allocation once the
/// calling thread's scratch and `hull` have grown.
void convexHullInto(const std::vector<Point>& points, Ring& hull);
/// convexHullInto for a ring known to be simple (no two edges meet but
/// neighbours), counter-clockwise: Melkman's algorithm, one pass along the
/// ring without sorting. The same hull, starting at the same vertex, up to
/// the rounding of orientation tests on nearly collinear points.
void convexHullOfSimpleRing(const Ring& ring, Ring& hull);

/// An oriented rectangle: centre, unit axis `u` along the long side, and side lengths.
struct OrientedBox {
  Point center;
  Point u{1, 0};      ///< unit vector along the long side
  double length = 0;  ///< long side (m)
  double width = 0;   ///< short side (m)
  double area() const { return length * width; }
};

/// The smallest rectangle enclosing the convex ring `hull` that has a side
/// parallel to one of the edges of `edges` (closed ring, any orientation).
/// Ties go to the first such edge. With edges = hull this is the minimum-area
/// rectangle; with edges = a polygon's own ring it is the edge-aligned box of
/// Vanegas et al. 2012, 4.3.
OrientedBox smallestBoxAlongEdges(const Ring& hull, const Ring& edges);

/// Minimum-area enclosing rectangle of a ring: the optimum has a side on a hull
/// edge, and every hull edge is tried against every hull point (hulls of
/// parcels are small; rotating calipers saved under 2 % of the OBB style's
/// instructions on cambridge_ma). Ties are broken towards the first hull edge,
/// so the result is deterministic.
OrientedBox minimumAreaBox(const Ring& ring);

/// minimumAreaBox of a ring whose convex hull (as convexHull gives it) is `hull`.
OrientedBox minimumAreaBoxOfHull(const Ring& hull);

}  // namespace parcelscope
