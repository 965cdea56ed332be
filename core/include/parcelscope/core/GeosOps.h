#pragma once
// Robust polygon operations through the GEOS C API, on ParcelScope's plain
// types. A target of its own (parcelscope_geos) so that the algorithms
// (analysis/, generation/) reach GEOS without linking GDAL.
#include <cstddef>
#include <optional>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::geos {

/// Union of `polygons`, then a morphological closing by `closeDistance` metres
/// (buffer out by half of it, back in by half of it) so that parts separated by
/// gaps narrower than `closeDistance` join and slivers narrower than it vanish.
/// Holes wider than `closeDistance` are kept. Returns normalised polygons.
/// Polygons forming a clean coverage (see `dissolveCoverage`) are dissolved
/// without an overlay when GEOS finds the outline valid; others go through
/// GEOS's coverage union, then its general union.
/// Throws Error(Geometry) if GEOS fails even after a buffer(0) repair.
std::vector<Polygon> unionAndClose(const std::vector<const Polygon*>& polygons, double closeDistance);

/// True when the polygon is valid in the OGC simple-features sense (GEOS IsValid).
/// A ring GEOS cannot even build (fewer than 4 points once closed) is invalid.
bool isValid(const Polygon& polygon);

/// The polygon as valid polygons (GEOS make-valid, structure method: rings
/// that pinch or fold split into their parts; zero-width corridors vanish).
/// A valid polygon comes back as it is. Parts are normalised.
std::vector<Polygon> validParts(const Polygon& polygon);

/// GEOS make-valid (structure method) of an invalid polygon with many holes
/// (a street network stored as a parcel: the blocks are its holes), without
/// GEOS's cascaded union of the holes. GEOS fixes the shell and each hole,
/// then takes the shell minus the union of the holes; where the fixed holes
/// all meet the fixed shell and form a valid multipolygon, that union adds
/// nothing, and the shell minus the holes as they are gives the same polygons
/// (their rings may start elsewhere and come in another order). Nothing where
/// that does not hold, where the polygon has fewer than `kManyHoles` holes,
/// or where the result is not valid (GEOS's difference may take its older
/// overlay where make-valid's robust one fails): make it valid with GEOS then.
/// Rings may be given closed or open. Parts are normalised.
constexpr std::size_t kManyHoles = 16;
std::optional<std::vector<Polygon>> validWithManyHoles(const Polygon& polygon);

/// The union of two polygons (GEOS overlay) when it is one valid polygon;
/// nothing when it is not (they touch at a point or not at all) or GEOS fails.
std::optional<Polygon> unionIfOne(const Polygon& a, const Polygon& b);

/// `parts` as one valid multipolygon, for a file: unchanged (and `repaired`
/// false) when it is valid (one part of one ring that isClearlySimple proves
/// simple, else as GEOS finds it); otherwise GEOS make-valid
/// (structure method, collapsed parts dropped), whose polygons come back with
/// `repaired` true. Parts of the repaired result below `minShare` of its area
/// (the crumbs of a crossing a few nanometres wide) are dropped, unless that
/// would leave nothing. May return nothing when every part collapses.
std::vector<Polygon> validMultiPolygon(std::vector<Polygon> parts, bool& repaired, double minShare = 1e-9);

/// Area in m² of the intersection of two polygons (GEOS, snap-rounded to a
/// 1e-6 m grid, so the result is within about perimeter x 1e-6 m² of exact).
/// Throws Error(Geometry) if GEOS fails.
double intersectionArea(const Polygon& a, const Polygon& b);

// Lines (street centre lines): noding, faces, buffers.

/// An open polyline, local metres.
using Polyline = std::vector<Point>;

/// The lines noded on a `grid`-metre grid (GEOS snap-rounding union): wherever
/// two lines cross or touch (within the grid) both are cut at one shared
/// vertex, and pieces that overlap are merged into one. Each piece runs between
/// two nodes; lines meeting end to end stay separate pieces. Throws
/// Error(Geometry) if GEOS fails.
std::vector<Polyline> nodeLines(const std::vector<Polyline>& lines, double grid);

/// The faces of noded lines (GEOS polygonizer): every area the lines enclose,
/// holes included (an enclosed face is a hole of the face around it and a face
/// of its own). `dangles` are the pieces with a free end (dead ends), `cutEdges`
/// pieces with a face on neither side or the same face on both.
struct LineFaces {
  std::vector<Polygon> faces;
  std::vector<Polyline> dangles, cutEdges;
};
LineFaces polygonizeLines(const std::vector<Polyline>& noded);

/// Each line buffered by its own half width in metres (round caps and joins,
/// `quadrantSegments` segments per quarter circle), then all unioned.
std::vector<Polygon> bufferedUnion(const std::vector<const Polyline*>& lines, const std::vector<double>& halfWidths,
                                   int quadrantSegments = 4);

/// `a` minus the union of `cut` (floating overlay; where that fails, is
/// invalid or leaves a hole within `grid` of its outer ring, snap rounding on a
/// `grid`-metre grid); normalised valid parts. Throws Error(Geometry) if GEOS fails.
std::vector<Polygon> difference(const Polygon& a, const std::vector<const Polygon*>& cut, double grid);

/// Indices of the `lines` that come within `distances[i]` of `polygon`
/// (inside it or near it; GEOS prepared geometry), in increasing order.
std::vector<int> linesNear(const Polygon& polygon, const std::vector<const Polyline*>& lines,
                           const std::vector<double>& distances);

/// The parts of `lines` outside the union of `areas` (GEOS difference; the
/// areas a clean coverage, such as faces, or not).
std::vector<Polyline> linesOutside(const std::vector<Polyline>& lines, const std::vector<Polygon>& areas);

/// Area of the union of `polygons` (snap-rounded on a `grid`-metre grid).
double unionArea(const std::vector<const Polygon*>& polygons, double grid);

}  // namespace parcelscope::geos
