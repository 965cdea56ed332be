#include "BoxPairs.h"

#include <CGAL/box_intersection_d.h>

#include <algorithm>

namespace parcelscope::analysis::detail {

std::vector<std::pair<int, int>> intersectingPairs(const std::vector<Box>& boxes) {
  using CgalBox = CGAL::Box_intersection_d::Box_with_info_d<double, 2, int>;
  std::vector<CgalBox> cboxes;
  cboxes.reserve(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    double lo[2] = {boxes[i].minX, boxes[i].minY};
    double hi[2] = {boxes[i].maxX, boxes[i].maxY};
    cboxes.emplace_back(lo, hi, static_cast<int>(i));
  }
  std::vector<std::pair<int, int>> pairs;
  CGAL::box_self_intersection_d(cboxes.begin(), cboxes.end(), [&](const CgalBox& a, const CgalBox& b) {
    const int i = a.info(), j = b.info();
    pairs.emplace_back(std::min(i, j), std::max(i, j));
  });
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace parcelscope::analysis::detail
