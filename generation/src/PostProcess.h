#pragma once
// What every style does to a block's result once its own algorithm is done:
// check that the parcels tile the block as valid polygons, and fall back to
// the OBB style, with the reason, when a style cannot subdivide a block. A
// new style calls these instead of writing its own.
#include <cstdint>
#include <stdexcept>
#include <string>

#include "parcelscope/core/Geometry.h"
#include "parcelscope/generation/ObbSubdivision.h"

namespace parcelscope::generation::detail {

/// Thrown by a style that cannot subdivide a block; the message is the reason
/// recorded with the fallback (Subdivision::fallbackReason).
struct StyleFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Throws StyleFailure unless every parcel is a valid polygon (GEOS) and the
/// parcels' areas sum to the block's within 1e-9 of it.
void checkTiling(const Polygon& block, const Subdivision& out);

/// Parcels narrower than this (twice the area over the perimeter) are slivers:
/// numerical crumbs of a cut passing next to a vertex (a triangle of 1e-13 m²
/// has no use as a parcel, and collapses once mapped back to degrees).
constexpr double kMinParcelWidth = 1e-3;  // m

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

}  // namespace parcelscope::generation::detail
