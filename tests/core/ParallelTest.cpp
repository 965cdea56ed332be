#include "parcelscope/core/Parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <memory>
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
  EXPECT_THROW(parallelFor(100,
                           [](std::size_t i) {
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

// A loop whose items all finish before its first poll still reports its start
// and its end (a progress bar showed no "subdividing" on a quick sample).
TEST(Parallel, TicksAtTheStartAndAtTheEndEvenWhenItemsAreInstant) {
  for (std::size_t n : {std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{5000}}) {
    std::vector<std::size_t> ticks;
    parallelFor(
        n, [](std::size_t) {}, [&](std::size_t done) { ticks.push_back(done); });
    ASSERT_GE(ticks.size(), 2u) << n;
    EXPECT_EQ(ticks.front(), 0u) << n;
    EXPECT_EQ(ticks.back(), n) << n;
    for (std::size_t k = 1; k < ticks.size(); ++k) EXPECT_LE(ticks[k - 1], ticks[k]) << n;
  }
  // No items, no ticks: callers report done / n.
  int emptyTicks = 0;
  parallelFor(
      0, [](std::size_t) {}, [&](std::size_t) { ++emptyTicks; });
  EXPECT_EQ(emptyTicks, 0);
}

// A tick that throws (a cancelled progress) stops the loop before every item runs.
TEST(Parallel, ATickThatThrowsStopsTheLoop) {
  std::atomic<std::size_t> ran{0};
  int calls = 0;
  EXPECT_THROW(parallelFor(
                   100000,
                   [&](std::size_t) {
                     ran.fetch_add(1);
                     std::this_thread::sleep_for(std::chrono::microseconds(50));
                   },
                   [&](std::size_t) {
                     if (++calls == 2) throw std::runtime_error("cancelled");
                   }),
               std::runtime_error);
  EXPECT_LT(ran.load(), 100000u);
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

// A reference handed over is dropped on another thread; waiting returns once
// it has been. When the queue is full (the background thread held up), the
// next one is dropped on the calling thread instead of piling up.
TEST(ReleaseInBackground, DropsOnAnotherThreadAndFallsBackWhenTheQueueIsFull) {
  const std::thread::id caller = std::this_thread::get_id();
  std::promise<std::thread::id> firstDroppedOn;
  std::promise<void> letFirstFinish;
  std::shared_future<void> go = letFirstFinish.get_future().share();
  std::promise<void> firstStarted;
  releaseInBackground(std::shared_ptr<const void>(new int(1), [&, go](const int* p) {
    delete p;
    firstDroppedOn.set_value(std::this_thread::get_id());
    firstStarted.set_value();
    go.wait();
  }));
  firstStarted.get_future().wait();  // the background thread is held up in the first drop
  std::atomic<int> droppedHere{0}, droppedElsewhere{0};
  auto counted = [&] {
    return std::shared_ptr<const void>(new int(2), [&, caller](const int* p) {
      delete p;
      (std::this_thread::get_id() == caller ? droppedHere : droppedElsewhere)++;
    });
  };
  for (int i = 0; i < 20; ++i) releaseInBackground(counted());
  // The queue holds up to kMaxWaitingReleases; the others were dropped at once, here.
  EXPECT_EQ(droppedHere.load(), 20 - static_cast<int>(kMaxWaitingReleases));
  EXPECT_EQ(droppedElsewhere.load(), 0);
  letFirstFinish.set_value();
  waitForBackgroundReleases();
  EXPECT_EQ(droppedElsewhere.load(), static_cast<int>(kMaxWaitingReleases));
  EXPECT_NE(firstDroppedOn.get_future().get(), caller);
  // A reference still held elsewhere only loses one owner.
  auto kept = std::make_shared<int>(3);
  releaseInBackground(kept);
  waitForBackgroundReleases();
  EXPECT_EQ(kept.use_count(), 1);
}

}  // namespace
}  // namespace parcelscope
