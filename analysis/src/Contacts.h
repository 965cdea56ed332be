#pragma once
// Where parcel boundaries meet: candidate polygon pairs from their boxes
// (CGAL's box_intersection_d), then edge by edge within each pair, only over
// the edges that reach the other polygon's box, so that cost grows with the
// number of nearby edge pairs, not with the product of polygon sizes (a street
// network stored as one parcel has tens of thousands of edges).
#include <cmath>
#include <memory>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::analysis::detail {

struct Contact {
  int a = -1, b = -1;  ///< polygon indices, a < b
  double shared = 0;   ///< m of boundary running along each other (see sharedBoundaryLength)
  bool close = false;  ///< some pair of edges lies within the tolerance
};

/// The bounds of all of `polygon`'s rings grown by half of `tolerance`: two
/// polygons can be in contact only when these meet.
Box contactBox(const Polygon& polygon, double tolerance);

/// Contacts between every pair of `polygons` whose boundaries come within
/// `closeTolerance` m, sorted by (a, b). Shared lengths count edges within
/// `sharedTolerance` (<= closeTolerance; negative means the same). With a
/// finite `enough` (for counting neighbours), a pair stops being measured once
/// one pair of its edges covers `enough` m on both sides; its `shared` is then
/// `enough`, which the whole shared length reaches too. Otherwise `shared` is
/// the whole length.
std::vector<Contact> contacts(const std::vector<const Polygon*>& polygons, double closeTolerance,
                              double sharedTolerance = -1, double enough = HUGE_VAL);
/// The same, given the candidate pairs: every pair (i, j), i < j, sorted,
/// whose contact boxes meet, at least (intersectingPairs of the contactBox
/// of each polygon); pairs are measured in parallel.
std::vector<Contact> contacts(const std::vector<const Polygon*>& polygons,
                              const std::vector<std::pair<int, int>>& candidates, double closeTolerance,
                              double sharedTolerance = -1, double enough = HUGE_VAL);

/// The shared length `contacts({&a, &b}, tolerance)` gives for the pair
/// (min of both sides' covered lengths), computed directly: the same edge pairs
/// (boxes grown by half the tolerance), the same intervals, summed in the same
/// order, without the closeness test (a pair with a covered interval is within
/// the tolerance) and without building the general search. 0 when nothing is
/// covered.
double sharedLength(const Polygon& a, const Polygon& b, double tolerance);

/// For each polygon, the length in m of its boundary running along `rings`
/// (within `tolerance`, parallel within 10 degrees).
std::vector<double> lengthAlong(const std::vector<const Polygon*>& polygons, const std::vector<Ring>& rings,
                                double tolerance);

/// The part of edge [p, q] (as an interval of distances from p) covered by edge
/// [r, s] lying parallel to it within `tolerance`; false when none is.
bool coveredInterval(const Point& p, const Point& q, const Point& r, const Point& s, double tolerance, double& lo,
                     double& hi);

/// Length of the union of intervals (sorted in place).
double unionLength(std::vector<std::pair<double, double>>& intervals);

}  // namespace parcelscope::analysis::detail
