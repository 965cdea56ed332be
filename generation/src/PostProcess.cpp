#include "PostProcess.h"

#include <cmath>

#include "parcelscope/core/GeosOps.h"

namespace parcelscope::generation::detail {

void checkTiling(const Polygon& block, const Subdivision& out) {
  double sum = 0;
  for (const Polygon& parcel : out.parcels) {
    if (!geos::isValid(parcel)) throw StyleFailure("a parcel is not a valid polygon once rounded");
    sum += area(parcel);
  }
  const double a = area(block);
  if (std::fabs(sum - a) > 1e-9 * a) throw StyleFailure("the parcels do not sum to the block's area");
}

Subdivision fallBackToObb(const Polygon& block, const ObbParameters& bounds, std::uint64_t seed,
                          const std::string& reason) {
  Subdivision out = subdivideObb(block, bounds, seed);
  out.fallback = true;
  out.fallbackReason = reason;
  return out;
}

}  // namespace parcelscope::generation::detail
