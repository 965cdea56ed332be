#pragma once
// Where parcel boundaries meet, computed edge by edge with CGAL's
// box_intersection_d so that cost grows with the number of nearby edge pairs,
// not with the product of polygon sizes (a street network stored as one
// parcel has tens of thousands of edges).
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::analysis::detail {

struct Contact {
  int a = -1, b = -1;   ///< polygon indices, a < b
  double shared = 0;    ///< m of boundary running along each other (see sharedBoundaryLength)
  bool close = false;   ///< some pair of edges lies within the tolerance
};

/// Contacts between every pair of `polygons` whose boundaries come within
/// `closeTolerance` m, sorted by (a, b). Shared lengths count edges within
/// `sharedTolerance` (<= closeTolerance; negative means the same).
std::vector<Contact> contacts(const std::vector<const Polygon*>& polygons, double closeTolerance,
                              double sharedTolerance = -1);

/// For each polygon, the length in m of its boundary running along `rings`
/// (within `tolerance`, parallel within 10 degrees).
std::vector<double> lengthAlong(const std::vector<const Polygon*>& polygons, const std::vector<Ring>& rings,
                                double tolerance);

/// The part of edge [p, q] (as an interval of distances from p) covered by edge
/// [r, s] lying parallel to it within `tolerance`; false when none is.
bool coveredInterval(const Point& p, const Point& q, const Point& r, const Point& s, double tolerance,
                     double& lo, double& hi);

/// Length of the union of intervals (sorted in place).
double unionLength(std::vector<std::pair<double, double>>& intervals);

}  // namespace parcelscope::analysis::detail
