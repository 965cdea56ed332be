#pragma once
// Helpers shared by the tests: polygons from compact literals, temporary
// folders, and the location of the shared datasets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::test {

/// A random generator for a randomized test, its seed printed (with `what`)
/// so that a failure can be replayed.
inline std::mt19937_64 seededRandom(std::uint64_t seed, const char* what) {
  std::printf("%s seed %llu\n", what, static_cast<unsigned long long>(seed));
  return std::mt19937_64(seed);
}

inline Polygon rect(double x0, double y0, double x1, double y1) {
  return Polygon{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, {}};
}

inline Polygon poly(std::initializer_list<Point> outer, std::initializer_list<Ring> holes = {}) {
  return Polygon{Ring(outer), std::vector<Ring>(holes)};
}

/// The same rings, vertex for vertex, to the last bit.
inline bool sameBits(const Polygon& a, const Polygon& b) { return sameVertices(a, b); }

/// Lots of an nx by ny grid of 10 m cells whose corners are moved at random by
/// up to 0.3 m; neighbouring lots share their corners exactly. Each cell is
/// kept with probability `keep` (the rest leave holes and separate parts).
inline std::vector<Polygon> jitteredGrid(std::mt19937& rng, int nx, int ny, double keep) {
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::bernoulli_distribution kept(keep);
  std::vector<std::vector<Point>> corner(nx + 1, std::vector<Point>(ny + 1));
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j <= ny; ++j) corner[i][j] = {10.0 * i + jitter(rng), 10.0 * j + jitter(rng)};
  std::vector<Polygon> lots;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      if (kept(rng)) lots.push_back({{corner[i][j], corner[i + 1][j], corner[i + 1][j + 1], corner[i][j + 1]}, {}});
  return lots;
}

/// A fresh empty folder under the system temp dir, removed at destruction.
class TempDir {
public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() / ("parcelscope-test-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(file(name), std::ios::binary) << text;
    return file(name);
  }
  const std::filesystem::path& path() const { return path_; }

private:
  std::filesystem::path path_;
};

/// The whole content of a file ("" when it cannot be read).
inline std::string slurpFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline std::string sharedDataset(const std::string& relative) {
  return std::string(PARCELSCOPE_SHARED_DATASETS) + "/" + relative;
}

inline bool haveSharedDatasets() { return std::filesystem::exists(PARCELSCOPE_SHARED_DATASETS); }

#define PARCELSCOPE_REQUIRE_SHARED_DATASETS()                                                         \
  do {                                                                                                \
    if (!::parcelscope::test::haveSharedDatasets())                                                   \
      GTEST_SKIP() << "shared datasets not found at " PARCELSCOPE_SHARED_DATASETS                     \
                      " (clone the project beside shared/ or set -DPARCELSCOPE_SHARED_DATASETS=...)"; \
  } while (0)

}  // namespace parcelscope::test
