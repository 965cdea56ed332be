#include "parcelscope/core/Parallel.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <thread>
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

TEST(Parallel, NestedLoopsRunOnTheirWorkersThreadInOrder) {
  constexpr std::size_t kOuter = 64, kInner = 50;
  std::vector<std::vector<std::size_t>> order(kOuter);
  std::vector<char> sameThread(kOuter, 1);
  parallelFor(kOuter, [&](std::size_t i) {
    const auto outer = std::this_thread::get_id();
    parallelFor(kInner, [&](std::size_t j) {
      order[i].push_back(j);  // unsynchronised: safe only on one thread
      if (std::this_thread::get_id() != outer) sameThread[i] = 0;
    });
  });
  for (std::size_t i = 0; i < kOuter; ++i) {
    EXPECT_TRUE(sameThread[i]) << i;
    ASSERT_EQ(order[i].size(), kInner);
    for (std::size_t j = 0; j < kInner; ++j) EXPECT_EQ(order[i][j], j);
  }
  // After the outer loop, loops run in parallel again.
  std::vector<int> hits(1000, 0);
  parallelFor(hits.size(), [&](std::size_t i) { hits[i] += 1; });
  for (int h : hits) ASSERT_EQ(h, 1);
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
