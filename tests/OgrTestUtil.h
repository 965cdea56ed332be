#pragma once
// ParcelScope polygons as OGR geometries, for tests that compare results with
// GDAL/GEOS directly (the library's own conversion is private to io/).
#include <ogr_geometry.h>

#include <memory>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::test {

inline std::unique_ptr<OGRPolygon> toOgr(const Polygon& p) {
  auto ring = [](const Ring& r) {
    auto o = std::make_unique<OGRLinearRing>();
    for (const Point& v : r) o->addPoint(v.x, v.y);
    o->addPoint(r.front().x, r.front().y);
    return o;
  };
  auto polygon = std::make_unique<OGRPolygon>();
  polygon->addRingDirectly(ring(p.outer).release());
  for (const Ring& h : p.holes) polygon->addRingDirectly(ring(h).release());
  return polygon;
}

inline std::unique_ptr<OGRMultiPolygon> toOgr(const std::vector<Polygon>& parts) {
  auto multi = std::make_unique<OGRMultiPolygon>();
  for (const Polygon& p : parts) multi->addGeometryDirectly(toOgr(p).release());
  return multi;
}

}  // namespace parcelscope::test
