#pragma once
// Parcel shape metrics. Each is a noun from the literature, with its formula,
// unit, range and source. All lengths in m, areas in m², angles in degrees,
// measured in the local metric plane.
#include <memory>
#include "parcelscope/core/Geometry.h"

namespace parcelscope::analysis {

struct ShapeMetrics {
  /// area = |outer ring| - sum |holes| (shoelace), m², > 0.
  double area = 0;
  /// perimeter = length of the outer ring plus the holes, m, > 0.
  double perimeter = 0;
  /// width = short side of the minimum-area bounding rectangle (MBR), m, >= 0.
  /// The "minimum width" W of Vanegas et al. 2012, section 6.
  double width = 0;
  /// length = long side of the MBR, m, >= width.
  double length = 0;
  /// aspect_ratio = length / width, dimensionless, [1, inf). The quantity of the
  /// colour maps of Vanegas et al. 2012 (Figure 1).
  double aspectRatio = 1;
  /// elongation = width / length of the MBR, dimensionless, (0, 1]; 1 is a square.
  /// As momepy.elongation (Gil et al. 2012).
  double elongation = 1;
  /// rectangularity = area / MBR area, dimensionless, (0, 1]; 1 is a rectangle.
  /// As momepy.rectangularity (Dibble et al. 2019).
  double rectangularity = 1;
  /// p_angle = mean over the corners of the outer ring of the deviation from a
  /// right angle, | |turn| - 90 | where turn is the exterior (turning) angle, so
  /// a convex 90-degree and a reflex 270-degree corner both count 0; degrees,
  /// [0, 90). Yang et al. 2013, section 6. A corner is a vertex where the boundary
  /// turns by more than kCornerTurnDegrees; a ring without corners gets 0.
  double pAngle = 0;
  /// p_area = MBR area / area, dimensionless, [1, inf). Yang et al. 2013, section 6
  /// (an "undesirable" parcel has p_angle > 15 or p_area > 1.2).
  double pArea = 1;
};

/// Vertices where the boundary turns by at most this many degrees are not
/// corners for p_angle (they are digitising noise or samples of a curve).
constexpr double kCornerTurnDegrees = 10.0;

/// All shape metrics of a normalised polygon. Precondition: area(polygon) > 0.
ShapeMetrics shapeMetrics(const Polygon& polygon);

/// p_angle of one ring (see ShapeMetrics::pAngle).
double cornerAngleDeviation(const Ring& ring);

/// Length in m of the boundary of `a` that runs along the boundary of `b`:
/// the parts of a's edges that lie within `tolerance` m of an edge of `b`
/// pointing the same or the opposite way (within 10 degrees). Symmetric up to
/// digitising differences. Used for shared boundaries (neighbours) and for
/// frontage (boundary on the block's outer contour).
double sharedBoundaryLength(const Polygon& a, const Polygon& b, double tolerance);

/// One polygon's edges prepared once for measuring many pieces against it (the
/// parts of a block against the block's outline):
/// `PreparedBoundary(reference, t).sharedLength(piece)` equals
/// `sharedBoundaryLength(piece, reference, t)`. It points into `reference`,
/// which must outlive it unchanged.
class PreparedBoundary {
public:
  PreparedBoundary(const Polygon& reference, double tolerance);
  ~PreparedBoundary();
  PreparedBoundary(const PreparedBoundary&) = delete;
  PreparedBoundary& operator=(const PreparedBoundary&) = delete;
  double sharedLength(const Polygon& piece) const;
  /// Whether `sharedLength(piece) >= length`, stopping at the first pair of
  /// edges that settles it (a street-access test).
  bool sharesAtLeast(const Polygon& piece, double length) const;

private:
  double measure(const Polygon& piece, double enough) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace parcelscope::analysis
