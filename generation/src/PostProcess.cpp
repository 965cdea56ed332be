#include "PostProcess.h"

#include <cmath>
#include <optional>

#include "parcelscope/analysis/Metrics.h"

#include "parcelscope/core/GeosOps.h"

namespace parcelscope::generation::detail {

void checkTiling(const Polygon& block, const Subdivision& out, const std::vector<char>& knownValid) {
  double sum = 0;
  for (std::size_t i = 0; i < out.parcels.size(); ++i) {
    const Polygon& parcel = out.parcels[i];
    // A ring clearly simple (floating-point test with a margin) is valid;
    // anything else is judged by GEOS.
    const bool valid = (i < knownValid.size() && knownValid[i]) ||
                       (parcel.holes.empty() && isClearlySimple(parcel.outer)) || geos::isValid(parcel);
    if (!valid) throw StyleFailure("a parcel is not a valid polygon once rounded");
    sum += area(parcel);
  }
  const double a = area(block);
  if (std::fabs(sum - a) > 1e-9 * a) throw StyleFailure("the parcels do not sum to the block's area");
}

namespace {
bool isSliver(const Polygon& p) {
  const double perim = perimeter(p);
  return perim > 0 && 2 * area(p) / perim < kMinParcelWidth;
}

}  // namespace

long mergeIntoNeighbour(std::vector<Polygon>& parcels, std::size_t i,
                        const std::function<bool(const Polygon&)>& eligible,
                        const std::function<bool(const Polygon&)>& acceptUnion) {
  const Polygon& piece = parcels[i];
  // The neighbour sharing the most boundary: the union's perimeter is the
  // two perimeters less twice the shared length.
  const Box box = bounds(piece).expanded(kMinParcelWidth);
  const double piecePerimeter = perimeter(piece);
  std::size_t best = parcels.size();
  double bestShared = 0;
  std::optional<Polygon> bestUnion;
  for (std::size_t j = 0; j < parcels.size(); ++j) {
    if (j == i || !box.intersects(bounds(parcels[j])) || (eligible && !eligible(parcels[j]))) continue;
    std::optional<Polygon> u = geos::unionIfOne(parcels[j], piece);
    if (!u || (acceptUnion && !acceptUnion(*u))) continue;
    const double shared = 0.5 * (perimeter(parcels[j]) + piecePerimeter - perimeter(*u));
    if (shared > bestShared) {
      best = j;
      bestShared = shared;
      bestUnion = std::move(u);
    }
  }
  if (!bestUnion) return -1;
  parcels[best] = std::move(*bestUnion);
  parcels.erase(parcels.begin() + static_cast<long>(i));
  return static_cast<long>(best);
}

int mergeSlivers(const Polygon& block, Subdivision& out, double minFrontage) {
  int left = 0;
  const Polygon outline{block.outer, {}};
  for (std::size_t i = 0; i < out.parcels.size();) {
    if (!isSliver(out.parcels[i])) {
      ++i;
      continue;
    }
    const Polygon sliver = out.parcels[i];  // merged away below
    const std::size_t firstUnassigned = out.parcels.size() - static_cast<std::size_t>(out.unassignedParcels);
    const std::size_t firstPatio = firstUnassigned - static_cast<std::size_t>(out.patioParcels);
    if (mergeIntoNeighbour(out.parcels, i) < 0) {
      ++left;
      ++i;
      continue;
    }
    if (i >= firstUnassigned) {
      --out.unassignedParcels;
    } else if (i >= firstPatio) {
      --out.patioParcels;
    } else if (out.withoutAccess > 0 &&
               analysis::sharedBoundaryLength(sliver, outline, kMinParcelWidth) < minFrontage) {
      --out.withoutAccess;
    }
  }
  return left;
}

Subdivision fallBackToObb(const Polygon& block, const ObbParameters& bounds, std::uint64_t seed,
                          const std::string& reason) {
  Subdivision out = subdivideObb(block, bounds, seed);
  out.fallback = true;
  out.fallbackReason = reason;
  return out;
}

}  // namespace parcelscope::generation::detail
