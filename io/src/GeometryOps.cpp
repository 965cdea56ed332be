#include "parcelscope/io/GeometryOps.h"

#include <geos_c.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "OgrConvert.h"
#include "parcelscope/core/Coverage.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::io {

namespace {
// A vertex within this distance (m) of a neighbour's edge is taken to lie on
// it when dissolving a block: far below any surveyed precision, far above
// the rounding of projected coordinates near the origin.
constexpr double kCoverageSnap = 1e-6;

std::vector<Polygon> polygonsOf(const OGRGeometry& g) {
  std::vector<std::unique_ptr<OGRPolygon>> parts;
  detail::collectPolygons(g, parts);
  std::vector<Polygon> out;
  for (const auto& p : parts) {
    Polygon polygon = detail::fromOgr(*p);
    if (normalise(polygon)) out.push_back(std::move(polygon));
  }
  return out;
}
// GEOS buffer with mitred joins (OGR's Buffer only offers round joins).
std::unique_ptr<OGRGeometry> mitreBuffer(const OGRGeometry& g, double distance) {
  GEOSContextHandle_t ctx = OGRGeometry::createGEOSContext();
  std::unique_ptr<OGRGeometry> out;
  if (GEOSGeom in = g.exportToGEOS(ctx)) {
    constexpr double kMitreLimit = 5.0;  // spikes sharper than ~23 degrees are bevelled
    if (GEOSGeom b = GEOSBufferWithStyle_r(ctx, in, distance, 8, GEOSBUF_CAP_FLAT, GEOSBUF_JOIN_MITRE, kMitreLimit)) {
      out.reset(OGRGeometryFactory::createFromGEOS(ctx, b));
      GEOSGeom_destroy_r(ctx, b);
    }
    GEOSGeom_destroy_r(ctx, in);
  }
  OGRGeometry::freeGEOSContext(ctx);
  return out;
}

// Union of parcels that form a clean coverage (shared edges identical): GEOS's
// coverage union only drops the edges that occur twice, far faster than a
// general overlay. Its result is trusted only when it is valid and keeps the
// total area (overlaps, gaps with T-junctions or mismatched edges fail one of
// the two); otherwise nullptr, and the caller uses the general union.
std::unique_ptr<OGRGeometry> coverageUnion(const OGRMultiPolygon& multi, double totalArea) {
  GEOSContextHandle_t ctx = OGRGeometry::createGEOSContext();
  std::unique_ptr<OGRGeometry> out;
  if (GEOSGeom in = multi.exportToGEOS(ctx)) {
    if (GEOSGeom u = GEOSCoverageUnion_r(ctx, in)) {
      double a = 0;
      if (GEOSisValid_r(ctx, u) == 1 && GEOSArea_r(ctx, u, &a) == 1 &&
          std::fabs(a - totalArea) <= 1e-9 * totalArea) {
        out.reset(OGRGeometryFactory::createFromGEOS(ctx, u));
      }
      GEOSGeom_destroy_r(ctx, u);
    }
    GEOSGeom_destroy_r(ctx, in);
  }
  OGRGeometry::freeGEOSContext(ctx);
  return out;
}

}  // namespace

std::vector<Polygon> unionAndClose(const std::vector<const Polygon*>& polygons, double closeDistance) {
  detail::QuietErrors quiet;
  if (polygons.empty()) return {};
  // Parcels that share their edges vertex for vertex (most blocks), also after
  // splitting edges at a neighbour's vertex lying on them: cancel the shared
  // edges, and keep the rings left when GEOS finds them valid. Otherwise GEOS
  // unions them: its coverage union, then a general union.
  std::unique_ptr<OGRGeometry> result;
  for (const double snap : {0.0, kCoverageSnap}) {
    auto dissolved = dissolveCoverage(polygons, {snap});
    if (!dissolved || dissolved->empty()) continue;
    const bool single = dissolved->size() == 1;
    std::unique_ptr<OGRGeometry> outline = single ? std::unique_ptr<OGRGeometry>(detail::toOgr(dissolved->front()))
                                                  : std::unique_ptr<OGRGeometry>(detail::toOgr(*dissolved));
    if (!outline->IsValid()) continue;
    if (single && dissolved->front().holes.empty()) return std::move(*dissolved);  // nothing to close
    result = std::move(outline);
    break;
  }
  if (!result) {
    OGRMultiPolygon multi;
    double totalArea = 0;
    for (const Polygon* p : polygons) {
      multi.addGeometryDirectly(detail::toOgr(*p).release());
      totalArea += area(*p);
    }
    result = coverageUnion(multi, totalArea);
    if (!result) result.reset(multi.UnionCascaded());
    if (!result) result.reset(multi.Buffer(0.0));
  }
  const bool simple = result && wkbFlatten(result->getGeometryType()) == wkbPolygon &&
                      result->toPolygon()->getNumInteriorRings() == 0;
  if (result && closeDistance > 0 && !simple) {
    // Gaps or holes: close them where narrower than the tolerance. Buffering
    // out unions the parts; buffering back in restores the outline. Mitred
    // joins give corners back exactly (round joins would cut them).
    std::unique_ptr<OGRGeometry> grown(mitreBuffer(*result, 0.5 * closeDistance));
    if (grown) result = mitreBuffer(*grown, -0.5 * closeDistance);
  }
  if (!result) throw geometryError("union of " + std::to_string(polygons.size()) + " parcels failed");
  // Parts smaller than half a tolerance square are artefacts of the closing.
  const double minArea = closeDistance > 0 ? 0.5 * closeDistance * closeDistance : 1e-6;
  std::vector<Polygon> all = polygonsOf(*result), parts;
  double largest = 0;
  for (const Polygon& p : all) largest = std::max(largest, area(p));
  for (auto& p : all) {
    const double a = area(p);
    if (a >= minArea || a == largest) parts.push_back(std::move(p));  // never drop the whole block
  }
  return parts;
}

bool isValid(const Polygon& polygon) {
  detail::QuietErrors quiet;
  return detail::toOgr(polygon)->IsValid();
}

std::vector<Polygon> validParts(const Polygon& polygon) {
  detail::QuietErrors quiet;
  const auto geometry = detail::toOgr(polygon);
  if (geometry->IsValid()) return {polygon};
  const char* const options[] = {"METHOD=STRUCTURE", nullptr};
  std::unique_ptr<OGRGeometry> fixed(geometry->MakeValid(options));
  std::vector<Polygon> out;
  if (!fixed) return out;
  std::vector<std::unique_ptr<OGRPolygon>> parts;
  detail::collectPolygons(*fixed, parts);
  for (const auto& part : parts) {
    Polygon p = detail::fromOgr(*part);
    if (normalise(p)) out.push_back(std::move(p));
  }
  return out;
}

double intersectionArea(const Polygon& a, const Polygon& b) {
  // Snap-rounded overlay on a 1e-6 m grid: floating overlay (GEOS 3.11) can
  // return a whole polygon as the intersection of two polygons whose shared
  // edge differs in the last bits; snap rounding is fully robust.
  constexpr double kGrid = 1e-6;
  detail::QuietErrors quiet;
  GEOSContextHandle_t ctx = OGRGeometry::createGEOSContext();
  double result = -1;
  GEOSGeom ga = detail::toOgr(a)->exportToGEOS(ctx);
  GEOSGeom gb = detail::toOgr(b)->exportToGEOS(ctx);
  if (ga && gb) {
    if (GEOSGeom i = GEOSIntersectionPrec_r(ctx, ga, gb, kGrid)) {
      if (GEOSArea_r(ctx, i, &result) != 1) result = -1;
      GEOSGeom_destroy_r(ctx, i);
    }
  }
  if (ga) GEOSGeom_destroy_r(ctx, ga);
  if (gb) GEOSGeom_destroy_r(ctx, gb);
  OGRGeometry::freeGEOSContext(ctx);
  if (result < 0) throw geometryError("intersection failed");
  return result;
}

}  // namespace parcelscope::io
