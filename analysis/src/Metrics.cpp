#include "parcelscope/analysis/Metrics.h"

#include <algorithm>
#include <cmath>

#include "Contacts.h"

namespace parcelscope::analysis {

namespace {
constexpr double kDeg = 180.0 / kPi;
}  // namespace

double cornerAngleDeviation(const Ring& ring) {
  const std::size_t n = ring.size();
  if (n < 3) return 0.0;
  double sum = 0;
  int corners = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point& prev = ring[(i + n - 1) % n];
    const Point& cur = ring[i];
    const Point& next = ring[(i + 1) % n];
    const double ax = cur.x - prev.x, ay = cur.y - prev.y;
    const double bx = next.x - cur.x, by = next.y - cur.y;
    if ((ax == 0 && ay == 0) || (bx == 0 && by == 0)) continue;
    // Turn angle at the vertex; a right-angled corner turns by 90 degrees whether
    // it is convex (interior 90) or reflex (interior 270).
    const double turn = std::fabs(std::atan2(ax * by - ay * bx, ax * bx + ay * by)) * kDeg;
    if (turn <= kCornerTurnDegrees) continue;
    sum += std::fabs(turn - 90.0);
    ++corners;
  }
  return corners ? sum / corners : 0.0;
}

ShapeMetrics shapeMetrics(const Polygon& polygon) {
  ShapeMetrics m;
  m.area = area(polygon);
  m.perimeter = perimeter(polygon);
  const OrientedBox box = minimumAreaBox(polygon.outer);
  m.width = box.width;
  m.length = box.length;
  m.aspectRatio = box.width > 0 ? box.length / box.width : HUGE_VAL;
  m.elongation = box.length > 0 ? box.width / box.length : 1.0;
  m.rectangularity = box.area() > 0 ? m.area / box.area() : 1.0;
  m.pArea = m.area > 0 ? box.area() / m.area : HUGE_VAL;
  m.pAngle = cornerAngleDeviation(polygon.outer);
  return m;
}

double sharedBoundaryLength(const Polygon& a, const Polygon& b, double tolerance) {
  if (!bounds(a).expanded(tolerance).intersects(bounds(b))) return 0.0;
  return detail::sharedLength(a, b, tolerance);
}

}  // namespace parcelscope::analysis
