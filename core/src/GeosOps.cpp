#include "parcelscope/core/GeosOps.h"

#include <geos_c.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "parcelscope/core/Coverage.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::geos {

namespace {
// A vertex within this distance (m) of a neighbour's edge is taken to lie on
// it when dissolving a block: far below any surveyed precision, far above
// the rounding of projected coordinates near the origin.
constexpr double kCoverageSnap = 1e-6;

void quiet(const char*, void*) {}

// One GEOS context per thread, silent (failures are reported by the caller).
GEOSContextHandle_t context() {
  struct Context {
    GEOSContextHandle_t handle = GEOS_init_r();
    Context() {
      GEOSContext_setNoticeMessageHandler_r(handle, quiet, nullptr);
      GEOSContext_setErrorMessageHandler_r(handle, quiet, nullptr);
    }
    ~Context() { GEOS_finish_r(handle); }
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
  };
  thread_local Context c;
  return c.handle;
}

// Owns a GEOS geometry of the calling thread's context.
struct Destroy {
  void operator()(GEOSGeometry* g) const { GEOSGeom_destroy_r(context(), g); }
};
using Geom = std::unique_ptr<GEOSGeometry, Destroy>;

GEOSGeometry* ringToGeos(GEOSContextHandle_t ctx, const Ring& ring) {
  std::vector<double> xy;
  xy.reserve(2 * ring.size() + 2);
  for (const Point& p : ring) {
    xy.push_back(p.x);
    xy.push_back(p.y);
  }
  // Closed; a ring of fewer than 4 points is padded with its first point (as
  // GDAL does before handing it to GEOS), so that GEOS builds it and then
  // finds it invalid.
  while (!ring.empty() && (xy.size() < 8 || xy.size() == 2 * ring.size())) {
    xy.push_back(ring.front().x);
    xy.push_back(ring.front().y);
  }
  GEOSCoordSequence* seq = GEOSCoordSeq_copyFromBuffer_r(ctx, xy.data(), static_cast<unsigned>(xy.size() / 2), 0, 0);
  return seq ? GEOSGeom_createLinearRing_r(ctx, seq) : nullptr;  // takes the sequence, even on failure
}

// The polygon with closed rings; null when GEOS refuses a ring.
Geom toGeos(const Polygon& polygon) {
  GEOSContextHandle_t ctx = context();
  GEOSGeometry* shell = ringToGeos(ctx, polygon.outer);
  if (!shell) return nullptr;
  std::vector<GEOSGeometry*> holes;
  for (const Ring& h : polygon.holes) {
    GEOSGeometry* hole = ringToGeos(ctx, h);
    if (!hole) {
      GEOSGeom_destroy_r(ctx, shell);
      for (GEOSGeometry* built : holes) GEOSGeom_destroy_r(ctx, built);
      return nullptr;
    }
    holes.push_back(hole);
  }
  return Geom(GEOSGeom_createPolygon_r(ctx, shell, holes.data(), static_cast<unsigned>(holes.size())));
}

Geom toGeos(const std::vector<const Polygon*>& parts) {
  GEOSContextHandle_t ctx = context();
  std::vector<GEOSGeometry*> built;
  for (const Polygon* p : parts) {
    Geom g = toGeos(*p);
    if (!g) {
      for (GEOSGeometry* b : built) GEOSGeom_destroy_r(ctx, b);
      return nullptr;
    }
    built.push_back(g.release());
  }
  return Geom(GEOSGeom_createCollection_r(ctx, GEOS_MULTIPOLYGON, built.data(), static_cast<unsigned>(built.size())));
}

Ring ringFromGeos(GEOSContextHandle_t ctx, const GEOSGeometry* ring) {
  const GEOSCoordSequence* seq = GEOSGeom_getCoordSeq_r(ctx, ring);
  unsigned n = 0;
  if (!seq || !GEOSCoordSeq_getSize_r(ctx, seq, &n) || n == 0) return {};
  std::vector<double> xy(2 * std::size_t(n));
  GEOSCoordSeq_copyToBuffer_r(ctx, seq, xy.data(), 0, 0);
  Ring out(n);
  for (unsigned i = 0; i < n; ++i) out[i] = {xy[2 * i], xy[2 * i + 1]};
  return out;
}

// Appends every polygon of `g` (polygons, multipolygons, collections), normalised.
void collectPolygons(const GEOSGeometry* g, std::vector<Polygon>& out) {
  GEOSContextHandle_t ctx = context();
  if (GEOSisEmpty_r(ctx, g) == 1) return;
  switch (GEOSGeomTypeId_r(ctx, g)) {
    case GEOS_POLYGON: {
      Polygon p;
      p.outer = ringFromGeos(ctx, GEOSGetExteriorRing_r(ctx, g));
      const int holes = GEOSGetNumInteriorRings_r(ctx, g);
      for (int i = 0; i < holes; ++i) p.holes.push_back(ringFromGeos(ctx, GEOSGetInteriorRingN_r(ctx, g, i)));
      if (normalise(p)) out.push_back(std::move(p));
      return;
    }
    case GEOS_MULTIPOLYGON:
    case GEOS_GEOMETRYCOLLECTION: {
      const int n = GEOSGetNumGeometries_r(ctx, g);
      for (int i = 0; i < n; ++i) collectPolygons(GEOSGetGeometryN_r(ctx, g, i), out);
      return;
    }
    default:
      return;
  }
}

bool valid(const GEOSGeometry* g) { return g && GEOSisValid_r(context(), g) == 1; }

// Whether a polygon of `g` has a hole closer than `grid` to its outer ring:
// valid, but a sliver of the shell between them, or a hole meant to be a
// notch (a cut along the shell, off by roundings). The shell is prepared (an
// index of its segments), so that a block of thousands of holes stays cheap.
bool holeNearShell(const GEOSGeometry* g, double grid) {
  GEOSContextHandle_t ctx = context();
  struct DestroyPrepared {
    GEOSContextHandle_t ctx;
    void operator()(const GEOSPreparedGeometry* p) const { GEOSPreparedGeom_destroy_r(ctx, p); }
  };
  for (int i = 0, n = GEOSGetNumGeometries_r(ctx, g); i < n; ++i) {
    const GEOSGeometry* p = GEOSGetGeometryN_r(ctx, g, i);
    if (GEOSGeomTypeId_r(ctx, p) != GEOS_POLYGON) continue;
    const int holes = GEOSGetNumInteriorRings_r(ctx, p);
    if (holes <= 0) continue;
    std::unique_ptr<const GEOSPreparedGeometry, DestroyPrepared> shell(
        GEOSPrepare_r(ctx, GEOSGetExteriorRing_r(ctx, p)), DestroyPrepared{ctx});
    if (!shell) continue;
    for (int h = 0; h < holes; ++h) {
      if (GEOSPreparedDistanceWithin_r(ctx, shell.get(), GEOSGetInteriorRingN_r(ctx, p, h), grid) == 1) return true;
    }
  }
  return false;
}

// GEOS buffer with mitred joins.
Geom mitreBuffer(const GEOSGeometry* g, double distance) {
  constexpr double kMitreLimit = 5.0;  // spikes sharper than ~23 degrees are bevelled
  return Geom(GEOSBufferWithStyle_r(context(), g, distance, 8, GEOSBUF_CAP_FLAT, GEOSBUF_JOIN_MITRE, kMitreLimit));
}

// Union of parcels that form a clean coverage (shared edges identical): GEOS's
// coverage union only drops the edges that occur twice, far faster than a
// general overlay. Its result is trusted only when it is valid and keeps the
// total area (overlaps, gaps with T-junctions or mismatched edges fail one of
// the two); otherwise null, and the caller uses the general union.
Geom coverageUnion(const GEOSGeometry* multi, double totalArea) {
  GEOSContextHandle_t ctx = context();
  Geom u(GEOSCoverageUnion_r(ctx, multi));
  double a = 0;
  if (u && GEOSisValid_r(ctx, u.get()) == 1 && GEOSArea_r(ctx, u.get(), &a) == 1 &&
      std::fabs(a - totalArea) <= 1e-9 * totalArea) {
    return u;
  }
  return nullptr;
}

}  // namespace

std::vector<Polygon> unionAndClose(const std::vector<const Polygon*>& polygons, double closeDistance) {
  if (polygons.empty()) return {};
  GEOSContextHandle_t ctx = context();
  // Parcels that share their edges vertex for vertex (most blocks), also after
  // splitting edges at a neighbour's vertex lying on them: cancel the shared
  // edges, and keep the rings left when GEOS finds them valid. Otherwise GEOS
  // unions them: its coverage union, then a general union.
  Geom result;
  for (const double snap : {0.0, kCoverageSnap}) {
    auto dissolved = dissolveCoverage(polygons, {snap});
    if (!dissolved || dissolved->empty()) continue;
    const bool single = dissolved->size() == 1;
    // One ring that is clearly simple (a conservative test) is a valid outline
    // with nothing to close: GEOS need not be asked.
    if (single && dissolved->front().holes.empty() && isClearlySimple(dissolved->front().outer)) {
      return std::move(*dissolved);
    }
    std::vector<const Polygon*> parts;
    for (const Polygon& p : *dissolved) parts.push_back(&p);
    Geom outline = single ? toGeos(dissolved->front()) : toGeos(parts);
    if (!valid(outline.get())) continue;
    if (single && dissolved->front().holes.empty()) return std::move(*dissolved);  // nothing to close
    result = std::move(outline);
    break;
  }
  if (!result) {
    double totalArea = 0;
    for (const Polygon* p : polygons) totalArea += area(*p);
    Geom multi = toGeos(polygons);
    if (multi) {
      result = coverageUnion(multi.get(), totalArea);
      if (!result) result.reset(GEOSUnionCascaded_r(ctx, multi.get()));
      if (!result) result.reset(GEOSBuffer_r(ctx, multi.get(), 0.0, 30));
    }
  }
  const bool simple = result && GEOSGeomTypeId_r(ctx, result.get()) == GEOS_POLYGON &&
                      GEOSGetNumInteriorRings_r(ctx, result.get()) == 0;
  if (result && closeDistance > 0 && !simple) {
    // Gaps or holes: close them where narrower than the tolerance. Buffering
    // out unions the parts; buffering back in restores the outline. Mitred
    // joins give corners back exactly (round joins would cut them).
    if (Geom grown = mitreBuffer(result.get(), 0.5 * closeDistance))
      result = mitreBuffer(grown.get(), -0.5 * closeDistance);
  }
  if (!result) throw geometryError("union of " + std::to_string(polygons.size()) + " parcels failed");
  // Parts smaller than half a tolerance square are artefacts of the closing.
  const double minArea = closeDistance > 0 ? 0.5 * closeDistance * closeDistance : 1e-6;
  std::vector<Polygon> all, parts;
  collectPolygons(result.get(), all);
  double largest = 0;
  for (const Polygon& p : all) largest = std::max(largest, area(p));
  for (auto& p : all) {
    const double a = area(p);
    if (a >= minArea || a == largest) parts.push_back(std::move(p));  // never drop the whole block
  }
  return parts;
}

namespace {
// GEOS make-valid, structure method, collapsed parts dropped (as OGR's
// MakeValid with METHOD=STRUCTURE); null when GEOS fails.
Geom madeValid(const GEOSGeometry* g) {
  GEOSContextHandle_t ctx = context();
  GEOSMakeValidParams* params = GEOSMakeValidParams_create_r(ctx);
  if (!params) return nullptr;
  Geom fixed;
  if (GEOSMakeValidParams_setMethod_r(ctx, params, GEOS_MAKE_VALID_STRUCTURE) &&
      GEOSMakeValidParams_setKeepCollapsed_r(ctx, params, 0)) {
    fixed.reset(GEOSMakeValidWithParams_r(ctx, g, params));
  }
  GEOSMakeValidParams_destroy_r(ctx, params);
  return fixed;
}
}  // namespace

bool isValid(const Polygon& polygon) { return valid(toGeos(polygon).get()); }

std::vector<Polygon> validParts(const Polygon& polygon) {
  Geom geometry = toGeos(polygon);
  if (valid(geometry.get())) return {polygon};
  std::vector<Polygon> out;
  if (!geometry) return out;
  Geom fixed = madeValid(geometry.get());
  if (fixed) collectPolygons(fixed.get(), out);
  return out;
}

std::optional<std::vector<Polygon>> validWithManyHoles(const Polygon& polygon) {
  if (polygon.holes.size() < kManyHoles) return std::nullopt;
  GEOSContextHandle_t ctx = context();
  // One ring as a polygon of its own, made valid as GEOS fixes a ring (a
  // closing vertex given is dropped: toGeos closes the ring).
  const auto fixedRing = [&](const Ring& ring) {
    Polygon alone{ring, {}};
    if (alone.outer.size() > 1 && alone.outer.front().x == alone.outer.back().x &&
        alone.outer.front().y == alone.outer.back().y) {
      alone.outer.pop_back();
    }
    const Geom g = toGeos(alone);
    return g ? madeValid(g.get()) : Geom();
  };
  const Geom shell = fixedRing(polygon.outer);
  if (!shell || GEOSisEmpty_r(ctx, shell.get()) != 0) return std::nullopt;
  const std::unique_ptr<const GEOSPreparedGeometry, void (*)(const GEOSPreparedGeometry*)> prepared(
      GEOSPrepare_r(ctx, shell.get()), [](const GEOSPreparedGeometry* p) { GEOSPreparedGeom_destroy_r(context(), p); });
  if (!prepared) return std::nullopt;
  std::vector<Geom> holes;
  for (const Ring& ring : polygon.holes) {
    Geom hole = fixedRing(ring);
    if (!hole) return std::nullopt;
    if (GEOSisEmpty_r(ctx, hole.get()) != 0) continue;  // a collapsed hole: GEOS unites it, empty, with the result
    // A hole outside its shell: GEOS makes it a shell of its own.
    if (GEOSPreparedIntersects_r(ctx, prepared.get(), hole.get()) != 1) return std::nullopt;
    const int type = GEOSGeomTypeId_r(ctx, hole.get());
    if (type == GEOS_POLYGON) {
      holes.push_back(std::move(hole));
    } else if (type == GEOS_MULTIPOLYGON) {
      for (int k = 0; k < GEOSGetNumGeometries_r(ctx, hole.get()); ++k) {
        Geom part(GEOSGeom_clone_r(ctx, GEOSGetGeometryN_r(ctx, hole.get(), k)));
        if (!part) return std::nullopt;
        holes.push_back(std::move(part));
      }
    } else {
      return std::nullopt;
    }
  }
  // The multipolygon takes the holes (also when it cannot be made).
  std::vector<GEOSGeometry*> parts;
  parts.reserve(holes.size());
  for (Geom& h : holes) parts.push_back(h.release());
  const Geom multi(
      GEOSGeom_createCollection_r(ctx, GEOS_MULTIPOLYGON, parts.data(), static_cast<unsigned>(parts.size())));
  if (!valid(multi.get())) return std::nullopt;
  const Geom result(GEOSDifference_r(ctx, shell.get(), multi.get()));
  if (!valid(result.get())) return std::nullopt;
  std::vector<Polygon> out;
  collectPolygons(result.get(), out);
  return out;
}

std::optional<Polygon> unionIfOne(const Polygon& a, const Polygon& b) {
  Geom ga = toGeos(a), gb = toGeos(b);
  if (!ga || !gb) return std::nullopt;
  Geom u(GEOSUnion_r(context(), ga.get(), gb.get()));
  if (!valid(u.get())) return std::nullopt;
  std::vector<Polygon> parts;
  collectPolygons(u.get(), parts);
  if (parts.size() != 1) return std::nullopt;
  return std::move(parts.front());
}

std::vector<Polygon> validMultiPolygon(std::vector<Polygon> parts, bool& repaired, double minShare) {
  repaired = false;
  // One ring proven simple with a margin is a valid polygon: GEOS is not asked.
  if (parts.size() == 1 && parts.front().holes.empty() && isClearlySimple(parts.front().outer)) return parts;
  std::vector<const Polygon*> pointers;
  for (const Polygon& p : parts) pointers.push_back(&p);
  Geom geometry = parts.size() == 1 ? toGeos(parts.front()) : toGeos(pointers);
  if (valid(geometry.get())) return parts;
  repaired = true;
  std::vector<Polygon> out;
  if (!geometry) return out;
  Geom fixed = madeValid(geometry.get());
  if (fixed) collectPolygons(fixed.get(), out);
  double total = 0;
  for (const Polygon& p : out) total += area(p);
  std::vector<Polygon> kept;
  for (Polygon& p : out) {
    if (area(p) >= minShare * total) kept.push_back(std::move(p));
  }
  return kept;
}

double intersectionArea(const Polygon& a, const Polygon& b) {
  // Snap-rounded overlay on a 1e-6 m grid: floating overlay (GEOS 3.11) can
  // return a whole polygon as the intersection of two polygons whose shared
  // edge differs in the last bits; snap rounding is fully robust.
  constexpr double kGrid = 1e-6;
  GEOSContextHandle_t ctx = context();
  double result = -1;
  Geom ga = toGeos(a), gb = toGeos(b);
  if (ga && gb) {
    if (Geom i{GEOSIntersectionPrec_r(ctx, ga.get(), gb.get(), kGrid)}) {
      if (GEOSArea_r(ctx, i.get(), &result) != 1) result = -1;
    }
  }
  if (result < 0) throw geometryError("intersection failed");
  return result;
}

namespace {

GEOSGeometry* lineToGeos(GEOSContextHandle_t ctx, const Polyline& line) {
  std::vector<double> xy;
  xy.reserve(2 * line.size());
  for (const Point& p : line) {
    xy.push_back(p.x);
    xy.push_back(p.y);
  }
  GEOSCoordSequence* seq = GEOSCoordSeq_copyFromBuffer_r(ctx, xy.data(), static_cast<unsigned>(line.size()), 0, 0);
  return seq ? GEOSGeom_createLineString_r(ctx, seq) : nullptr;
}

Geom linesToGeos(const std::vector<const Polyline*>& lines) {
  GEOSContextHandle_t ctx = context();
  std::vector<GEOSGeometry*> built;
  for (const Polyline* l : lines) {
    GEOSGeometry* g = l->size() >= 2 ? lineToGeos(ctx, *l) : nullptr;
    if (!g) {
      for (GEOSGeometry* b : built) GEOSGeom_destroy_r(ctx, b);
      return nullptr;
    }
    built.push_back(g);
  }
  return Geom(
      GEOSGeom_createCollection_r(ctx, GEOS_MULTILINESTRING, built.data(), static_cast<unsigned>(built.size())));
}

// Appends every line string of `g` (lines, multilines, collections).
void collectLines(const GEOSGeometry* g, std::vector<Polyline>& out) {
  GEOSContextHandle_t ctx = context();
  if (GEOSisEmpty_r(ctx, g) == 1) return;
  switch (GEOSGeomTypeId_r(ctx, g)) {
    case GEOS_LINESTRING:
    case GEOS_LINEARRING:
      out.push_back(ringFromGeos(ctx, g));
      return;
    case GEOS_MULTILINESTRING:
    case GEOS_GEOMETRYCOLLECTION: {
      const int n = GEOSGetNumGeometries_r(ctx, g);
      for (int i = 0; i < n; ++i) collectLines(GEOSGetGeometryN_r(ctx, g, i), out);
      return;
    }
    default:
      return;
  }
}

}  // namespace

std::vector<Polyline> nodeLines(const std::vector<Polyline>& lines, double grid) {
  std::vector<const Polyline*> pointers;
  for (const Polyline& l : lines) {
    if (l.size() >= 2) pointers.push_back(&l);
  }
  if (pointers.empty()) return {};
  Geom multi = linesToGeos(pointers);
  Geom noded(multi ? GEOSUnaryUnionPrec_r(context(), multi.get(), grid) : nullptr);
  if (!noded) throw geometryError("noding " + std::to_string(pointers.size()) + " lines failed");
  std::vector<Polyline> out;
  collectLines(noded.get(), out);
  return out;
}

LineFaces polygonizeLines(const std::vector<Polyline>& noded) {
  GEOSContextHandle_t ctx = context();
  std::vector<const Polyline*> pointers;
  for (const Polyline& l : noded) {
    if (l.size() >= 2) pointers.push_back(&l);
  }
  LineFaces out;
  if (pointers.empty()) return out;
  Geom multi = linesToGeos(pointers);
  GEOSGeometry *cuts = nullptr, *dangles = nullptr, *invalid = nullptr;
  Geom faces(multi ? GEOSPolygonize_full_r(ctx, multi.get(), &cuts, &dangles, &invalid) : nullptr);
  Geom ownedCuts(cuts), ownedDangles(dangles), ownedInvalid(invalid);
  if (!faces) throw geometryError("faces of " + std::to_string(pointers.size()) + " lines failed");
  collectPolygons(faces.get(), out.faces);
  if (cuts) collectLines(cuts, out.cutEdges);
  if (dangles) collectLines(dangles, out.dangles);
  return out;
}

std::vector<Polygon> bufferedUnion(const std::vector<const Polyline*>& lines, const std::vector<double>& halfWidths,
                                   int quadrantSegments) {
  GEOSContextHandle_t ctx = context();
  std::vector<GEOSGeometry*> buffers;
  auto destroyAll = [&] {
    for (GEOSGeometry* b : buffers) GEOSGeom_destroy_r(ctx, b);
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i]->size() < 2 || !(halfWidths[i] > 0)) continue;
    Geom line(lineToGeos(ctx, *lines[i]));
    GEOSGeometry* b = line ? GEOSBuffer_r(ctx, line.get(), halfWidths[i], quadrantSegments) : nullptr;
    if (!b) {
      destroyAll();
      throw geometryError("buffer of a line failed");
    }
    buffers.push_back(b);
  }
  if (buffers.empty()) return {};
  std::vector<Polygon> out;
  if (buffers.size() == 1) {  // one buffer needs no union
    Geom one(buffers.front());
    collectPolygons(one.get(), out);
    return out;
  }
  Geom all(
      GEOSGeom_createCollection_r(ctx, GEOS_GEOMETRYCOLLECTION, buffers.data(), static_cast<unsigned>(buffers.size())));
  Geom u(all ? GEOSUnaryUnion_r(ctx, all.get()) : nullptr);
  if (!u) throw geometryError("union of " + std::to_string(buffers.size()) + " street buffers failed");
  collectPolygons(u.get(), out);
  return out;
}

std::vector<Polygon> difference(const Polygon& a, const std::vector<const Polygon*>& cut, double grid) {
  GEOSContextHandle_t ctx = context();
  Geom ga = toGeos(a);
  if (!ga) throw geometryError("difference: the polygon cannot be built");
  std::vector<Polygon> out;
  if (cut.empty()) {
    out.push_back(a);
    return out;
  }
  // Floating overlay first (GEOS's own fallbacks make it robust in nearly
  // every case), one cutter at a time (cheaper than their union first); snap
  // rounding on the grid when that fails, gives an invalid result, or leaves
  // a hole within the grid of its outer ring (a cutter along the shell but
  // for roundings; see holeNearShell) (it costs more: GEOS 3.11 seeds a
  // random device per call).
  Geom d(GEOSGeom_clone_r(ctx, ga.get()));
  for (const Polygon* c : cut) {
    if (!d) break;
    Geom gcut = toGeos(*c);
    d.reset(gcut ? GEOSDifference_r(ctx, d.get(), gcut.get()) : nullptr);
  }
  Geom cutUnion;
  const bool floatingValid = valid(d.get());
  if (!floatingValid || holeNearShell(d.get(), grid)) {
    Geom gc = toGeos(cut);
    cutUnion.reset(gc ? GEOSUnaryUnionPrec_r(ctx, gc.get(), grid) : nullptr);
    Geom snapped(cutUnion ? GEOSDifferencePrec_r(ctx, ga.get(), cutUnion.get(), grid) : nullptr);
    // A valid floating result is kept when snapping fails.
    if (snapped || !floatingValid) d = std::move(snapped);
  }
  if (!d) throw geometryError("difference of a polygon and " + std::to_string(cut.size()) + " polygons failed");
  collectPolygons(d.get(), out);
  return out;
}

std::vector<int> linesNear(const Polygon& polygon, const std::vector<const Polyline*>& lines,
                           const std::vector<double>& distances) {
  GEOSContextHandle_t ctx = context();
  Geom g = toGeos(polygon);
  if (!g) throw geometryError("linesNear: the polygon cannot be built");
  struct DestroyPrepared {
    GEOSContextHandle_t ctx;
    void operator()(const GEOSPreparedGeometry* p) const { GEOSPreparedGeom_destroy_r(ctx, p); }
  };
  std::unique_ptr<const GEOSPreparedGeometry, DestroyPrepared> prepared(GEOSPrepare_r(ctx, g.get()),
                                                                        DestroyPrepared{ctx});
  if (!prepared) throw geometryError("linesNear: the polygon cannot be prepared");
  std::vector<int> near;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    Geom line(lines[i]->size() >= 2 ? lineToGeos(ctx, *lines[i]) : nullptr);
    if (!line) continue;
    const char within = GEOSPreparedDistanceWithin_r(ctx, prepared.get(), line.get(), distances[i]);
    if (within == 2) throw geometryError("linesNear: GEOS failed");
    if (within == 1) near.push_back(static_cast<int>(i));
  }
  return near;
}

std::vector<Polyline> linesOutside(const std::vector<Polyline>& lines, const std::vector<Polygon>& areas) {
  GEOSContextHandle_t ctx = context();
  std::vector<const Polyline*> pointers;
  for (const Polyline& l : lines) {
    if (l.size() >= 2) pointers.push_back(&l);
  }
  if (pointers.empty()) return {};
  if (areas.empty()) return lines;
  Geom g = linesToGeos(pointers);
  std::vector<const Polygon*> parts;
  for (const Polygon& a : areas) parts.push_back(&a);
  Geom multi = toGeos(parts);
  Geom area(multi ? GEOSCoverageUnion_r(ctx, multi.get()) : nullptr);
  if (!valid(area.get())) area.reset(multi ? GEOSUnaryUnion_r(ctx, multi.get()) : nullptr);
  Geom outside(g && area ? GEOSDifference_r(ctx, g.get(), area.get()) : nullptr);
  if (!outside) throw geometryError("lines outside " + std::to_string(areas.size()) + " areas failed");
  Geom merged(GEOSLineMerge_r(ctx, outside.get()));
  std::vector<Polyline> out;
  collectLines(merged ? merged.get() : outside.get(), out);
  return out;
}

double unionArea(const std::vector<const Polygon*>& polygons, double grid) {
  if (polygons.empty()) return 0;
  Geom g = toGeos(polygons);
  Geom u(g ? GEOSUnaryUnionPrec_r(context(), g.get(), grid) : nullptr);
  double a = 0;
  if (!u || GEOSArea_r(context(), u.get(), &a) != 1) throw geometryError("union area failed");
  return a;
}

}  // namespace parcelscope::geos
