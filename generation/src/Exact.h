#pragma once
// Exact polygon operations shared by the subdivision styles (CGAL Boolean set
// operations on the exact-constructions kernel). Private to generation/: only
// .cpp files include this header, so CGAL stays out of public headers.
#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polygon_with_holes_2.h>

#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation::detail {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using P2 = CGAL::Polygon_2<K>;
using PWH = CGAL::Polygon_with_holes_2<K>;
/// Explicit segment traits: the default for Epeck polygons converts to
/// polylines, a path that leaks in CGAL 5.5.
using Traits = CGAL::Gps_segment_traits_2<K>;
/// A region of the plane: disjoint polygons with holes.
using Region = std::vector<PWH>;

P2 toExact(const Ring& ring);
/// Outer ring counter-clockwise, holes clockwise.
PWH toExact(const Polygon& polygon);
/// Rounded to doubles and normalised; false when nothing of it is left.
bool toDouble(const PWH& exact, Polygon& out);

/// The half-plane left of the directed line through `through` along `dir`, as a
/// quadrilateral reaching `reach` (m) from `through` in every direction.
P2 leftHalfPlane(const K::Point_2& through, const K::Vector_2& dir, double reach);

/// The part of `p` left of the directed line through `through` along `dir`
/// (a half-plane reaching `reach` m). A polygon without holes that the line
/// crosses twice is clipped directly (Sutherland-Hodgman on exact points);
/// anything else goes through CGAL's Boolean operations.
Region clipLeft(const PWH& p, const K::Point_2& through, const K::Vector_2& dir, double reach);
Region clipLeft(const Region& r, const K::Point_2& through, const K::Vector_2& dir, double reach);

Region intersect(const PWH& a, const P2& b);
Region subtract(const Region& a, const PWH& b);
/// Union of interior-disjoint parts; its disjoint components. Parts that meet
/// along shared edges (T-junctions allowed) into one polygon without holes are
/// dissolved directly: coinciding edges cancel; anything else goes through
/// CGAL's Boolean operations.
Region join(const Region& parts);

bool isValidExact(const PWH& p);

}  // namespace parcelscope::generation::detail
