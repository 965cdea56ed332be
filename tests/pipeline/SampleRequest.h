#pragma once
// The bundled sample's compare request as the pipeline tests use it: its
// right-of-way features filtered out, default parameters, no figures.
#include <string>

#include "parcelscope/pipeline/CompareJob.h"

namespace parcelscope::test {

inline pipeline::CompareRequest sampleCompareRequest(const std::string& style) {
  pipeline::CompareRequest r;
  r.input.path = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
  r.input.where = "use <> 'ROW'";
  r.style = style;
  r.parameters = defaultValues(pipeline::compareParameters());
  r.parameters["figures"] = 0;
  return r;
}

}  // namespace parcelscope::test
