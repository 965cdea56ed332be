#include "BoxPairs.h"

#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cmath>

#include "parcelscope/core/Parallel.h"

namespace parcelscope::analysis::detail {

std::vector<std::pair<int, int>> intersectingPairs(const std::vector<Box>& boxes) {
  std::vector<std::pair<int, int>> pairs;
  const int n = static_cast<int>(boxes.size());
  if (n <= 128) {
    // One block's parcels: testing every pair costs less than CGAL's sorting
    // and tree. The same pairs, in the same (sorted) order.
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        if (boxes[static_cast<std::size_t>(i)].intersects(boxes[static_cast<std::size_t>(j)])) pairs.emplace_back(i, j);
      }
    }
    return pairs;
  }
  // Large inputs (a city's parcels): the plane is cut into vertical slabs of
  // equal box counts, one per core, each searched by CGAL on its own. A box
  // joins every slab its x-range reaches; a pair is kept only in the slab
  // holding the larger of the two boxes' minX, where both boxes are (their
  // x-ranges overlap there), so each pair is found once.
  using CgalBox = CGAL::Box_intersection_d::Box_with_info_d<double, 2, int>;
  const std::size_t slabs = n < 20000 ? 1 : std::min<std::size_t>(workerCount(), 8);
  std::vector<double> cuts;  // slab s holds minX in (cuts[s - 1], cuts[s]]
  if (slabs > 1) {
    std::vector<double> minX(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) minX[i] = boxes[i].minX;
    std::sort(minX.begin(), minX.end());
    for (std::size_t s = 1; s < slabs; ++s) cuts.push_back(minX[s * minX.size() / slabs]);
  }
  cuts.push_back(HUGE_VAL);
  auto slabOf = [&](double x) {
    return static_cast<std::size_t>(std::lower_bound(cuts.begin(), cuts.end(), x) - cuts.begin());
  };
  std::vector<std::vector<std::pair<int, int>>> found(slabs);
  parallelFor(slabs, [&](std::size_t s) {
    const double from = s == 0 ? -HUGE_VAL : cuts[s - 1], to = cuts[s];
    std::vector<CgalBox> cboxes;
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const Box& b = boxes[i];
      if (b.minX > to || b.maxX <= from) continue;
      double lo[2] = {b.minX, b.minY};
      double hi[2] = {b.maxX, b.maxY};
      cboxes.emplace_back(lo, hi, static_cast<int>(i));
    }
    auto& out = found[s];
    CGAL::box_self_intersection_d(cboxes.begin(), cboxes.end(), [&](const CgalBox& a, const CgalBox& b) {
      const int i = a.info(), j = b.info();
      if (slabs > 1 && slabOf(std::max(a.min_coord(0), b.min_coord(0))) != s) return;
      out.emplace_back(std::min(i, j), std::max(i, j));
    });
    std::sort(out.begin(), out.end());  // each slab's pairs sorted on its own thread, then merged
  });
  for (auto& f : found) {
    const std::size_t before = pairs.size();
    pairs.insert(pairs.end(), f.begin(), f.end());
    std::inplace_merge(pairs.begin(), pairs.begin() + static_cast<std::ptrdiff_t>(before), pairs.end());
    f = {};
  }
  return pairs;
}

}  // namespace parcelscope::analysis::detail
