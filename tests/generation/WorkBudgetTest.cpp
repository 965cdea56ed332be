// The work budget of each block (issue 29, item 2): no block makes a style run
// without bound. The three blocks that did (a 100,000-vertex noisy circle, a
// polygon of 90 by 40 degrees in its local frame, a 15-vertex self-intersecting
// polygon 170 km across after the reader's repair) come back from every style
// within the budget, tiling the block, with the fallback or failure naming it,
// and the process's peak memory grows by less than 1 GB.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "TestUtil.h"
#include "TilingCheck.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/generation/Styles.h"

#if defined(__SANITIZE_ADDRESS__)
#define PARCELSCOPE_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PARCELSCOPE_TEST_SANITIZED 1
#endif
#endif

namespace parcelscope::generation {
namespace {

constexpr double kGiB = 1024.0 * 1024.0 * 1024.0;

long peakRssKiB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

// Caps the process's address space (3 GiB above what it holds now), so that a
// block allocating without bound ends in std::bad_alloc, which the style
// rethrows and the test reports, instead of taking the machine's memory.
// Not under AddressSanitizer, whose shadow memory is reserved address space.
class AddressSpaceCap : public ::testing::Environment {
public:
  void SetUp() override {
#ifndef PARCELSCOPE_TEST_SANITIZED
    rlimit current{};
    if (getrlimit(RLIMIT_AS, &current) != 0) return;
    long pages = 0;
    if (FILE* f = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
      std::fclose(f);
    }
    const rlim_t cap = static_cast<rlim_t>(pages) * 4096 + static_cast<rlim_t>(3 * kGiB);
    if (current.rlim_cur == RLIM_INFINITY || current.rlim_cur > cap) {
      rlimit next = current;
      next.rlim_cur = cap;
      setrlimit(RLIMIT_AS, &next);
    }
#endif
  }
};
const auto* const kCap = ::testing::AddGlobalTestEnvironment(new AddressSpaceCap);

// `n` vertices on a circle of radius 300 m, each moved radially by up to
// `noise` m (a star-shaped ring in angular order: simple).
Polygon noisyCircle(int n = 100000, double noise = 1.0) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> moved(-noise, noise);
  Polygon p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n, r = 300 + moved(rng);
    p.outer.push_back({r * std::cos(a), r * std::sin(a)});
  }
  return p;
}

// A polygon of 90 by 40 degrees of longitude and latitude in its local
// transverse Mercator frame: about 10,000 km by 4,400 km, narrower to the pole.
Polygon continent() {
  return test::poly({{-5.0e6, -2.2e6}, {5.0e6, -2.2e6}, {3.6e6, 2.2e6}, {0.0, 2.35e6}, {-3.6e6, 2.2e6}});
}

// A 15-vertex ring about 170 km across whose edges cross (a star polygon
// {15/7}, radii varying), as the reader repairs it: GEOS make-valid, structure
// method (io's ParcelReader), into valid parts.
std::vector<Polygon> repairedStar() {
  Polygon p;
  const int n = 15;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * ((7 * i) % n) / n, r = 85000.0 * (0.75 + 0.25 * ((i * 4) % 5) / 4.0);
    p.outer.push_back({r * std::cos(a), r * std::sin(a)});
  }
  return geos::validParts(p);
}

struct Outcome {
  Subdivision result;
  double seconds = 0;
  double peakGrowthGiB = 0;
};

Outcome run(const Polygon& block, const std::string& styleName) {
  const Style& chosen = style(styleName);
  const Style& concrete = chosen.resolve({std::nan("")});  // auto: a block layer without observed parcels
  const ParameterValues values = defaultValues(generationParameterDescriptions());
  const StreetWidths widths;
  const long before = peakRssKiB();
  const auto start = std::chrono::steady_clock::now();
  Outcome o;
  o.result = concrete.run({block, values, 7, widths});
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.peakGrowthGiB = static_cast<double>(peakRssKiB() - before) * 1024.0 / kGiB;
  return o;
}

// A generous sanity bound, for a loaded machine running tests in parallel:
// the must-hold is 10 s for a block on its own in a release build (measured
// times in docs/algorithms/skeleton.md, under 4 s); debug and sanitizer
// builds run several times slower.
#if defined(NDEBUG) && !defined(PARCELSCOPE_TEST_SANITIZED)
constexpr double kSanitySeconds = 30;
#else
constexpr double kSanitySeconds = 120;
#endif

bool namesBudget(const std::string& reason) { return reason.find("work budget") != std::string::npos; }

void expectWithinBudget(const Polygon& block, const Outcome& o, const std::string& what) {
  std::printf("%s: %.2f s, peak memory +%.0f MiB\n", what.c_str(), o.seconds, o.peakGrowthGiB * 1024);
  EXPECT_LT(o.peakGrowthGiB, 1.0) << what;
  EXPECT_LT(o.seconds, kSanitySeconds) << what;
  EXPECT_TILES(block, o.result.parcels, what);
  // What was given up is said: a fallback or a failure names the budget.
  if (o.result.fallback) {
    EXPECT_TRUE(namesBudget(o.result.fallbackReason)) << what << ": " << o.result.fallbackReason;
  }
  if (o.result.failed) {
    EXPECT_TRUE(namesBudget(o.result.failure)) << what << ": " << o.result.failure;
    ASSERT_EQ(o.result.parcels.size(), 1u) << what;
  }
}

class SkeletonStyles : public ::testing::TestWithParam<const char*> {};
INSTANTIATE_TEST_SUITE_P(WorkBudget, SkeletonStyles, ::testing::Values("skeleton", "offset", "auto"));

// The skeleton is built on the outline simplified until it fits the budget:
// the block is subdivided by its own style, its parcels along the block's own
// vertices.
TEST_P(SkeletonStyles, NoisyCircleOf100000VerticesIsSimplifiedIntoTheBudget) {
  const Polygon block = noisyCircle();
  const Outcome o = run(block, GetParam());
  expectWithinBudget(block, o, GetParam());
  EXPECT_FALSE(o.result.fallback) << o.result.fallbackReason;
  EXPECT_FALSE(o.result.failed) << o.result.failure;
  EXPECT_GT(o.result.parcels.size(), 50u);
}

// A gear of 1,500 teeth 10 m deep keeps every vertex at the coarsest chord
// tolerance (half of W_min), more than the budget: the block goes to obb, and
// says why.
TEST_P(SkeletonStyles, OutlineBeyondTheSimplificationFallsBackToObb) {
  Polygon block;
  for (int i = 0; i < 3000; ++i) {
    const double a = 2 * M_PI * i / 3000, r = i % 2 ? 990.0 : 1000.0;
    block.outer.push_back({r * std::cos(a), r * std::sin(a)});
  }
  const Outcome o = run(block, GetParam());
  expectWithinBudget(block, o, GetParam());
  EXPECT_TRUE(o.result.fallback);
  EXPECT_NE(o.result.fallbackReason.find("skeleton contour vertices"), std::string::npos) << o.result.fallbackReason;
  EXPECT_FALSE(o.result.failed) << o.result.failure;
}

// 2,400 vertices moved by up to 60 m keep about 1,900 at every tolerance: the
// skeleton's events (about a fifth of the square of the vertices on such a
// ring) pass their budget and the construction stops.
TEST_P(SkeletonStyles, SkeletonEventsBeyondTheBudgetFallBackToObb) {
  const Polygon block = noisyCircle(2400, 60.0);
  const Outcome o = run(block, GetParam());
  expectWithinBudget(block, o, GetParam());
  EXPECT_TRUE(o.result.fallback);
  EXPECT_NE(o.result.fallbackReason.find("events"), std::string::npos) << o.result.fallbackReason;
}

// obb splits the same circle; its street-access test no longer pairs every
// edge of a piece with every edge of the outline (26 s before, under 1 s now).
TEST(WorkBudget, NoisyCircleOf100000VerticesObbSubdivides) {
  const Polygon block = noisyCircle(100000, 0.05);
  const Outcome o = run(block, "obb");
  expectWithinBudget(block, o, "obb");
  EXPECT_FALSE(o.result.failed) << o.result.failure;
  EXPECT_GT(o.result.parcels.size(), 100u);
}

TEST(WorkBudget, PolygonOf90By40DegreesIsKeptWholeByEveryStyle) {
  const Polygon block = continent();
  for (const char* s : {"obb", "skeleton", "offset", "parish", "sexton", "template", "auto"}) {
    const Outcome o = run(block, s);
    expectWithinBudget(block, o, s);
    EXPECT_TRUE(o.result.failed) << s;
    EXPECT_EQ(o.result.fallback, std::string(s) != "obb" && std::string(s) != "parish" && std::string(s) != "sexton" &&
                                     std::string(s) != "template")
        << s;
  }
  // The small squares of the same layer are subdivided as always.
  const Polygon square = test::rect(1000, 1000, 1080, 1080);
  for (const char* s : {"obb", "skeleton", "offset", "parish", "sexton", "template", "auto"}) {
    const Outcome o = run(square, s);
    EXPECT_FALSE(o.result.failed || o.result.fallback) << s << ": " << o.result.failure << o.result.fallbackReason;
    EXPECT_GT(o.result.parcels.size(), 4u) << s;
    EXPECT_TILES(square, o.result.parcels, s);
  }
}

TEST(WorkBudget, RepairedSelfIntersectingPolygonOf170KmStaysWithinTheBudgetInEveryStyle) {
  const std::vector<Polygon> parts = repairedStar();
  ASSERT_FALSE(parts.empty());
  int kept = 0;
  for (const char* s : {"obb", "skeleton", "offset", "parish", "sexton", "template", "auto"}) {
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const std::string what = std::string(s) + " part " + std::to_string(i);
      const Outcome o = run(parts[i], s);
      expectWithinBudget(parts[i], o, what);
      kept += o.result.failed;
    }
  }
  // Thousands of km² are beyond every style's budget: each keeps it whole.
  EXPECT_EQ(kept, static_cast<int>(7 * parts.size()));
}

TEST(WorkBudget, BudgetedOutcomesAreReproducible) {
  const Polygon block = noisyCircle(2400, 60.0);
  const Outcome a = run(block, "skeleton"), b = run(block, "skeleton");
  ASSERT_TRUE(a.result.fallback);
  ASSERT_EQ(a.result.parcels.size(), b.result.parcels.size());
  for (std::size_t i = 0; i < a.result.parcels.size(); ++i) {
    EXPECT_TRUE(test::sameBits(a.result.parcels[i], b.result.parcels[i])) << i;
  }
  EXPECT_EQ(a.result.fallbackReason, b.result.fallbackReason);
}

}  // namespace
}  // namespace parcelscope::generation
