#pragma once
// One block run through a registered style with some values changed from
// the style's defaults, as the style tests do.
#include <cstdint>

#include "parcelscope/generation/Styles.h"

namespace parcelscope::test {

inline generation::Subdivision runStyle(const generation::Style& style, const Polygon& block,
                                        const ParameterValues& values, std::uint64_t seed = 1,
                                        const generation::ObservedSample* observed = nullptr) {
  ParameterValues all = generation::styleValues(style, {});
  for (const auto& [name, v] : values) all[name] = v;
  generation::StyleRun run{block, all, seed, {}};
  run.observed = observed;
  return style.subdivide(run);
}

}  // namespace parcelscope::test
