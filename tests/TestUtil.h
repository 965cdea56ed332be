#pragma once
// Helpers shared by the tests: polygons from compact literals, temporary
// folders, and the location of the shared datasets.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <random>
#include <string>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::test {

inline Polygon rect(double x0, double y0, double x1, double y1) {
  return Polygon{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, {}};
}

inline Polygon poly(std::initializer_list<Point> outer, std::initializer_list<Ring> holes = {}) {
  return Polygon{Ring(outer), std::vector<Ring>(holes)};
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
