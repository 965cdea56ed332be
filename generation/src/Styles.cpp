#include "parcelscope/generation/Styles.h"

#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::generation {

const std::vector<std::pair<std::string, std::string>>& generationStyles() {
  static const std::vector<std::pair<std::string, std::string>> styles = {
      {"obb", "OBB recursive subdivision (Vanegas et al. 2012, 4.3)"},
      {"skeleton", "straight-skeleton strips along the streets (4.2); --offset M leaves patios"},
      {"offset", "skeleton with a finite offset (30 m unless --offset) and patios subdivided by OBB"},
      {"auto", "per block: skeleton where >= 90 % of observed parcels have street access, else obb"},
  };
  return styles;
}

std::vector<ParameterDescription> generationParameterDescriptions() {
  std::vector<ParameterDescription> params = obbParameterDescriptions();
  appendParameters(params, skeletonParameterDescriptions());
  appendParameters(params, analysis::analysisParameters());
  return params;
}

namespace {
constexpr double kDefaultOffsetStyleDepth = 30.0;  // m, style offset without --offset
}  // namespace

Subdivision subdivideBlock(const Polygon& block, const std::string& style, const SkeletonParameters& parameters,
                           std::uint64_t seed, const StreetWidths& streetWidths, const SkeletonReuse& reuse) {
  if (style == "obb") return subdivideObb(block, parameters.bounds, seed);
  SkeletonParameters p = parameters;
  if (style == "offset") {
    if (p.offset <= 0) p.offset = kDefaultOffsetStyleDepth;
    p.subdividePatios = true;
  } else if (style != "skeleton") {
    throw usageError("no subdivision style '" + style + "'");
  }
  return subdivideSkeleton(block, p, seed, streetWidths, reuse);
}

}  // namespace parcelscope::generation
