#pragma once
// What every style does to a block's result once its own algorithm is done:
// check that the parcels tile the block as valid polygons, and fall back to
// the OBB style, with the reason, when a style cannot subdivide a block. A
// new style calls these instead of writing its own.
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "BlockFailure.h"
#include "LocalShift.h"
#include "PolygonSplit.h"
#include "parcelscope/core/Geometry.h"
#include "parcelscope/generation/ObbSubdivision.h"

namespace parcelscope::generation::detail {

/// Thrown by a style that cannot subdivide a block; the message is the reason
/// recorded with the fallback (Subdivision::fallbackReason).
struct StyleFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Throws StyleFailure unless every parcel is a valid polygon (GEOS) and the
/// parcels' areas sum to the block's within 1e-9 of it. Parcels whose flag in
/// `knownValid` is set (the style proved them valid as they are) are not
/// tested again; the flags may be fewer than the parcels, or none.
void checkTiling(const Polygon& block, const Subdivision& out, const std::vector<char>& knownValid = {});

/// Parcels narrower than this (twice the area over the perimeter) are slivers:
/// numerical crumbs of a cut passing next to a vertex (a triangle of 1e-13 m²
/// has no use as a parcel, and collapses once mapped back to degrees).
constexpr double kMinParcelWidth = 1e-3;  // m

/// Merges parcels[i] into the neighbour sharing the longest boundary with it
/// (of those `eligible` accepts, all without it) when their union is one valid
/// polygon: the neighbour becomes the union and parcels[i] is erased, the
/// others keeping their order. Returns the neighbour's index before the
/// erase, or -1 when no neighbour takes it. With `acceptUnion`, only unions
/// it accepts are taken (e.g. those that stay valid once moved back from
/// near the origin).
long mergeIntoNeighbour(std::vector<Polygon>& parcels, std::size_t i,
                        const std::function<bool(const Polygon&)>& eligible = {},
                        const std::function<bool(const Polygon&)>& acceptUnion = {});

/// Merges every sliver (see kMinParcelWidth) into the neighbouring parcel it
/// shares the longest boundary with, when their union is one valid polygon.
/// Keeps the order of the other parcels; adjusts unassignedParcels, patioParcels and
/// withoutAccess (a sliver with less than `minFrontage` m on the block's outer
/// contour counted without access). Returns the number of slivers left (no
/// neighbour to merge with).
int mergeSlivers(const Polygon& block, Subdivision& out, double minFrontage);

/// The block subdivided by the OBB style, marked as a fallback for `reason`.
Subdivision fallBackToObb(const Polygon& block, const ObbParameters& bounds, std::uint64_t seed,
                          const std::string& reason);

/// Thrown by a style when a block exceeds its work budget; the message is the
/// failure recorded (the block comes back whole).
struct WorkBudgetExceeded : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// How the lot-splitting styles (parish, sexton) run on a block:
/// `subdivide(local, out)` on the block moved next to the origin
/// (exactShiftOrigin) once it passed the validity check, then the parcels
/// moved back and their tiling checked. A block over its work budget
/// (WorkBudgetExceeded, or `out.failed` set) comes back whole, failed; one the
/// style cannot subdivide (StyleFailure, an invalid block, CGAL's failed
/// preconditions) falls back to obb with the reason.
template <typename Subdivide>
Subdivision runNearOrigin(const Polygon& block, const ObbParameters& bounds, std::uint64_t seed,
                          Subdivide&& subdivide) {
  const Point o = exactShiftOrigin(block);
  Polygon local = translated(block, -o.x, -o.y);
  Subdivision out;
  std::string reason;
  try {
    if (!normalise(local) || !isValidForSplit(local)) throw StyleFailure("the block is not a valid polygon with holes");
    subdivide(static_cast<const Polygon&>(local), out);
    if (!out.failed) {
      if (o.x != 0 || o.y != 0) {
        for (Polygon& parcel : out.parcels) translate(parcel, o.x, o.y);
      }
      checkTiling(block, out);
    }
  } catch (const WorkBudgetExceeded& e) {
    out = Subdivision{};
    out.failed = true;
    out.failure = e.what();
  } catch (const std::exception& e) {
    rethrowUnlessBlockFailure();
    reason = e.what();
  }
  if (out.failed) {
    out.parcels = {block};
    return out;
  }
  if (!reason.empty()) out = fallBackToObb(block, bounds, seed, reason);
  return out;
}

}  // namespace parcelscope::generation::detail
