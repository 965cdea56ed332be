#pragma once
// The comparison stage shared by compare() and CompareSession.
#include <chrono>
#include <vector>

#include "parcelscope/pipeline/CompareJob.h"

namespace parcelscope::pipeline::detail {

inline double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Fills r.observedLots (when empty), r.blocks, r.city and r.histograms from
/// r.observed and r.generated. Where `keep` (one flag per observed block) is
/// set and r.blocks already holds that block, its comparison is kept as it is.
void compareStage(CompareResult& r, const CompareRequest& request, const std::vector<char>* keep = nullptr);

/// The generation request of a compare request over observed data already read.
pipeline::GenerateRequest generateRequest(const CompareRequest& request, const pipeline::ObservedData* observed);

/// Throws Error(Input) when `observed` has no block to compare.
void requireBlocks(const CompareRequest& request, const pipeline::ObservedData& observed);

/// Throws Error(Usage) when a value of `request` is outside its parameter's
/// range, or its metric is not a parcel quantity.
void checkRequest(const CompareRequest& request);

}  // namespace parcelscope::pipeline::detail
