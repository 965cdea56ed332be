#pragma once
// Reading rendered PNGs back and comparing them with baseline images, for the
// render tests (they run under xvfb-run; see tests/CMakeLists.txt).
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>

#include <cstdint>
#include <filesystem>
#include <set>
#include <string>

namespace parcelscope::test {

struct Image {
  int width = 0, height = 0, components = 0;
  vtkSmartPointer<vtkImageData> data;
  /// RGB of pixel (x, y), y counted from the top as in the file.
  std::uint32_t rgb(int x, int y) const {
    const auto* p = static_cast<const unsigned char*>(data->GetScalarPointer(x, height - 1 - y, 0));
    return std::uint32_t(p[0]) << 16 | std::uint32_t(p[1]) << 8 | p[2];
  }
};

inline Image readPng(const std::string& path) {
  Image image;
  vtkNew<vtkPNGReader> reader;
  if (!std::filesystem::exists(path) || !reader->CanReadFile(path.c_str())) return image;
  reader->SetFileName(path.c_str());
  reader->Update();
  image.data = reader->GetOutput();
  int dims[3];
  image.data->GetDimensions(dims);
  image.width = dims[0];
  image.height = dims[1];
  image.components = image.data->GetNumberOfScalarComponents();
  return image;
}

/// Share of pixels that are not (near) white, and the number of distinct colours.
struct Ink {
  double share = 0;
  std::size_t colours = 0;
};

inline Ink ink(const Image& image) {
  Ink r;
  std::set<std::uint32_t> colours;
  long inked = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint32_t c = image.rgb(x, y);
      colours.insert(c);
      const int red = c >> 16, green = (c >> 8) & 0xff, blue = c & 0xff;
      inked += red < 240 || green < 240 || blue < 240;
    }
  }
  r.share = static_cast<double>(inked) / (static_cast<double>(image.width) * image.height);
  r.colours = colours.size();
  return r;
}

/// Share of pixels whose colour differs by more than `levels` (of 255) in some
/// channel: small for antialiasing and font hinting noise, large for a moved,
/// missing or recoloured element. 1 when the sizes differ.
inline double differingShare(const Image& a, const Image& b, int levels = 30) {
  if (!a.data || !b.data || a.width != b.width || a.height != b.height) return 1.0;
  long differing = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const std::uint32_t p = a.rgb(x, y), q = b.rgb(x, y);
      for (int shift : {0, 8, 16}) {
        const int d = static_cast<int>((p >> shift) & 0xff) - static_cast<int>((q >> shift) & 0xff);
        if (d > levels || d < -levels) {
          ++differing;
          break;
        }
      }
    }
  }
  return static_cast<double>(differing) / (static_cast<double>(a.width) * a.height);
}

}  // namespace parcelscope::test
