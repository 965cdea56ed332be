#include "parcelscope/core/Parallel.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "parcelscope/core/Error.h"
#include "parcelscope/core/Progress.h"

namespace parcelscope {
namespace {

TEST(Parallel, VisitsEveryIndexOnce) {
  std::vector<int> hits(10000, 0);
  parallelFor(hits.size(), [&](std::size_t i) { hits[i] += 1; });
  for (int h : hits) ASSERT_EQ(h, 1);
}

TEST(Parallel, RethrowsTheBodysException) {
  EXPECT_THROW(parallelFor(100, [](std::size_t i) {
                 if (i == 42) throw std::runtime_error("boom");
               }),
               std::runtime_error);
}

TEST(Progress, CancellingThrowsCancelled) {
  ProgressFn stop = [](double, const std::string&) { return false; };
  try {
    reportProgress(stop, 0.5, "blocks");
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::Cancelled);
  }
}

TEST(Progress, ScaledProgressMapsOntoParentRange) {
  double seen = -1;
  ProgressFn parent = [&](double f, const std::string&) {
    seen = f;
    return true;
  };
  scaledProgress(parent, 0.4, 0.8)(0.5, "x");
  EXPECT_DOUBLE_EQ(seen, 0.6);
}

}  // namespace
}  // namespace parcelscope
