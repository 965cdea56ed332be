#include "OgrConvert.h"

#include <cpl_error.h>
#include <gdal_priv.h>

#include <mutex>

namespace parcelscope::io::detail {

namespace {
std::unique_ptr<OGRLinearRing> ringToOgr(const Ring& ring) {
  auto r = std::make_unique<OGRLinearRing>();
  r->setNumPoints(static_cast<int>(ring.size() + 1), FALSE);
  for (std::size_t i = 0; i < ring.size(); ++i) {
    r->setPoint(static_cast<int>(i), ring[i].x, ring[i].y);
  }
  if (!ring.empty()) r->setPoint(static_cast<int>(ring.size()), ring[0].x, ring[0].y);
  return r;
}

Ring ringFromOgr(const OGRLinearRing& r) {
  Ring ring;
  const int n = r.getNumPoints();
  ring.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) ring.push_back({r.getX(i), r.getY(i)});
  return ring;
}
}  // namespace

std::unique_ptr<OGRPolygon> toOgr(const Polygon& polygon) {
  auto p = std::make_unique<OGRPolygon>();
  p->addRingDirectly(ringToOgr(polygon.outer).release());
  for (const auto& h : polygon.holes) p->addRingDirectly(ringToOgr(h).release());
  return p;
}

std::unique_ptr<OGRMultiPolygon> toOgr(const std::vector<Polygon>& parts) {
  auto m = std::make_unique<OGRMultiPolygon>();
  for (const auto& p : parts) m->addGeometryDirectly(toOgr(p).release());
  return m;
}

Polygon fromOgr(const OGRPolygon& polygon) {
  Polygon p;
  if (const OGRLinearRing* ext = polygon.getExteriorRing()) p.outer = ringFromOgr(*ext);
  for (int i = 0; i < polygon.getNumInteriorRings(); ++i) {
    p.holes.push_back(ringFromOgr(*polygon.getInteriorRing(i)));
  }
  return p;
}

bool collectPolygons(const OGRGeometry& geometry, std::vector<std::unique_ptr<OGRPolygon>>& out) {
  if (geometry.IsEmpty()) return true;
  switch (wkbFlatten(geometry.getGeometryType())) {
    case wkbPolygon: {
      std::unique_ptr<OGRPolygon> p(geometry.toPolygon()->clone());
      p->flattenTo2D();
      out.push_back(std::move(p));
      return true;
    }
    case wkbMultiPolygon:
    case wkbGeometryCollection:
    case wkbMultiSurface: {
      bool onlyPolygons = true;
      for (const OGRGeometry* g : *geometry.toGeometryCollection()) {
        onlyPolygons = collectPolygons(*g, out) && onlyPolygons;
      }
      return onlyPolygons;
    }
    case wkbCurvePolygon: {
      std::unique_ptr<OGRGeometry> linear(geometry.getLinearGeometry());
      return linear ? collectPolygons(*linear, out) : false;
    }
    default:
      return false;
  }
}

OGRFieldType ogrFieldType(Column::Type type) {
  return type == Column::Type::Integer ? OFTInteger64 : type == Column::Type::Real ? OFTReal : OFTString;
}

namespace {
// Errors raised on this thread while quiet are kept (so CPLGetLastErrorMsg works)
// but not printed.
void CPL_STDCALL keepQuiet(CPLErr, CPLErrorNum, const char*) {}
}  // namespace

QuietErrors::QuietErrors() { CPLPushErrorHandler(keepQuiet); }
QuietErrors::~QuietErrors() { CPLPopErrorHandler(); }

void ensureGdalRegistered() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

}  // namespace parcelscope::io::detail
