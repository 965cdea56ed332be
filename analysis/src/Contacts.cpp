#include "Contacts.h"

#include "parcelscope/core/Parallel.h"

#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace parcelscope::analysis::detail {

namespace {

struct EdgeInfo {
  int polygon;
  const Point* p;
  const Point* q;
};

using EdgeBox = CGAL::Box_intersection_d::Box_with_info_d<double, 2, std::size_t>;

void addRingEdges(const Ring& r, int index, double grow, std::vector<EdgeInfo>& edges,
                  std::vector<EdgeBox>& boxes) {
  for (std::size_t i = 0, n = r.size(); i < n; ++i) {
    const Point& p = r[i];
    const Point& q = r[(i + 1) % n];
    double lo[2] = {std::min(p.x, q.x) - grow, std::min(p.y, q.y) - grow};
    double hi[2] = {std::max(p.x, q.x) + grow, std::max(p.y, q.y) + grow};
    boxes.emplace_back(lo, hi, edges.size());
    edges.push_back({index, &p, &q});
  }
}

void addEdges(const Polygon& polygon, int index, double grow, std::vector<EdgeInfo>& edges,
              std::vector<EdgeBox>& boxes) {
  addRingEdges(polygon.outer, index, grow, edges, boxes);
  for (const auto& h : polygon.holes) addRingEdges(h, index, grow, edges, boxes);
}

// (edge of the measured polygon, other polygon, interval) records, grouped to
// take the union of intervals per edge and polygon pair.
struct Cover {
  std::size_t edge;
  int other;
  double lo, hi;
  bool operator<(const Cover& o) const { return std::tie(edge, other, lo) < std::tie(o.edge, o.other, o.lo); }
};

template <typename Sink>
void sumCovers(std::vector<Cover>& covers, const std::vector<EdgeInfo>& edges, Sink&& sink) {
  std::sort(covers.begin(), covers.end());
  std::vector<std::pair<double, double>> intervals;
  for (std::size_t i = 0; i < covers.size();) {
    std::size_t j = i;
    intervals.clear();
    while (j < covers.size() && covers[j].edge == covers[i].edge && covers[j].other == covers[i].other) {
      intervals.emplace_back(covers[j].lo, covers[j].hi);
      ++j;
    }
    sink(edges[covers[i].edge].polygon, covers[i].other, unionLength(intervals));
    i = j;
  }
}
}  // namespace

bool coveredInterval(const Point& p, const Point& q, const Point& r, const Point& s, double tolerance,
                     double& lo, double& hi) {
  static const double sinMax = std::sin(10.0 * kPi / 180.0);
  const double len = norm(q.x - p.x, q.y - p.y);
  const double l2 = norm(s.x - r.x, s.y - r.y);
  if (len == 0 || l2 == 0) return false;
  const double ux = (q.x - p.x) / len, uy = (q.y - p.y) / len;
  const double vx = (s.x - r.x) / l2, vy = (s.y - r.y) / l2;
  if (std::fabs(ux * vy - uy * vx) > sinMax) return false;  // not parallel
  // Offsets of r and s from the line of [p, q] and their positions along it.
  const double dr = (r.x - p.x) * -uy + (r.y - p.y) * ux;
  const double ds = (s.x - p.x) * -uy + (s.y - p.y) * ux;
  // Both ends beyond the tolerance on the same side: no part is close. (Ends on
  // opposite sides cross the band, and the clipping below keeps the middle.)
  if ((dr > tolerance && ds > tolerance) || (dr < -tolerance && ds < -tolerance)) return false;
  const double tr = (r.x - p.x) * ux + (r.y - p.y) * uy;
  const double ts = (s.x - p.x) * ux + (s.y - p.y) * uy;
  double a = std::min(tr, ts), b = std::max(tr, ts);
  // Keep only the part of [r, s] within the tolerance of the line (offset is linear in t).
  if (std::fabs(ds - dr) > 1e-12 && ts != tr) {
    const double slope = (ds - dr) / (ts - tr);
    double c = tr + (-tolerance - dr) / slope, d = tr + (tolerance - dr) / slope;
    if (c > d) std::swap(c, d);
    a = std::max(a, c);
    b = std::min(b, d);
  }
  lo = std::max(0.0, a);
  hi = std::min(len, b);
  return hi > lo;
}

double unionLength(std::vector<std::pair<double, double>>& intervals) {
  if (intervals.empty()) return 0.0;
  std::sort(intervals.begin(), intervals.end());
  double total = 0, lo = intervals[0].first, hi = intervals[0].second;
  for (std::size_t i = 1; i < intervals.size(); ++i) {
    if (intervals[i].first > hi) {
      total += hi - lo;
      lo = intervals[i].first;
      hi = intervals[i].second;
    } else {
      hi = std::max(hi, intervals[i].second);
    }
  }
  return total + (hi - lo);
}

std::vector<Contact> contacts(const std::vector<const Polygon*>& polygons, double tolerance,
                              double sharedTolerance) {
  if (sharedTolerance < 0 || sharedTolerance > tolerance) sharedTolerance = tolerance;
  std::vector<EdgeInfo> edges;
  std::vector<EdgeBox> boxes;
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    addEdges(*polygons[i], static_cast<int>(i), 0.5 * tolerance, edges, boxes);
  }
  // Two halves split at the median x, searched in parallel. A box crossing the
  // split goes to both halves; a pair is kept only in the half that holds the
  // larger of the two boxes' minimum x, so no pair is found twice.
  std::vector<double> xs;
  // Small inputs (one block, one parcel pair) stay on the calling thread.
  const bool parallel = boxes.size() >= 20000;
  double split = std::numeric_limits<double>::infinity();
  if (parallel) {
    xs.reserve(boxes.size());
    for (const EdgeBox& b : boxes) xs.push_back(0.5 * (b.min_coord(0) + b.max_coord(0)));
    std::nth_element(xs.begin(), xs.begin() + static_cast<long>(xs.size() / 2), xs.end());
    split = xs[xs.size() / 2];
  }
  struct Half {
    std::vector<EdgeBox> boxes;
    std::vector<Cover> covers;
    std::vector<std::pair<int, int>> closePairs;
  };
  Half halves[2];
  for (const EdgeBox& b : boxes) {
    if (b.min_coord(0) < split) halves[0].boxes.push_back(b);
    if (b.max_coord(0) >= split) halves[1].boxes.push_back(b);
  }
  auto search = [&](std::size_t h) {
    Half& half = halves[h];
    CGAL::box_self_intersection_d(half.boxes.begin(), half.boxes.end(), [&](const EdgeBox& x, const EdgeBox& y) {
      const bool upper = std::max(x.min_coord(0), y.min_coord(0)) >= split;
      if (upper != (h == 1)) return;
      const EdgeInfo& e = edges[x.info()];
      const EdgeInfo& f = edges[y.info()];
      if (e.polygon == f.polygon) return;
      if (segmentDistance(*e.p, *e.q, *f.p, *f.q) > tolerance) return;
      half.closePairs.emplace_back(std::min(e.polygon, f.polygon), std::max(e.polygon, f.polygon));
      double lo = 0, hi = 0;
      if (coveredInterval(*e.p, *e.q, *f.p, *f.q, sharedTolerance, lo, hi)) {
        half.covers.push_back({x.info(), f.polygon, lo, hi});
      }
      if (coveredInterval(*f.p, *f.q, *e.p, *e.q, sharedTolerance, lo, hi)) {
        half.covers.push_back({y.info(), e.polygon, lo, hi});
      }
    });
  };
  if (parallel) {
    parallelFor(2, search);
  } else {
    search(0);
  }
  std::vector<Cover> covers = std::move(halves[0].covers);
  covers.insert(covers.end(), halves[1].covers.begin(), halves[1].covers.end());
  std::vector<std::pair<int, int>> closePairs = std::move(halves[0].closePairs);
  closePairs.insert(closePairs.end(), halves[1].closePairs.begin(), halves[1].closePairs.end());
  std::sort(closePairs.begin(), closePairs.end());
  closePairs.erase(std::unique(closePairs.begin(), closePairs.end()), closePairs.end());
  std::vector<Contact> out(closePairs.size());
  std::vector<double> sharedBack(closePairs.size(), 0.0);
  for (std::size_t k = 0; k < closePairs.size(); ++k) {
    out[k].a = closePairs[k].first;
    out[k].b = closePairs[k].second;
    out[k].close = true;
  }
  auto find = [&](int a, int b) {
    const auto it = std::lower_bound(closePairs.begin(), closePairs.end(), std::make_pair(a, b));
    return static_cast<std::size_t>(it - closePairs.begin());
  };
  sumCovers(covers, edges, [&](int measured, int other, double length) {
    if (measured < other) {
      out[find(measured, other)].shared += length;
    } else {
      sharedBack[find(other, measured)] += length;
    }
  });
  // Both sides measure the same shared stretch; take the smaller (digitising
  // differences can make one side's edges overlap the other's twice).
  for (std::size_t k = 0; k < out.size(); ++k) out[k].shared = std::min(out[k].shared, sharedBack[k]);
  return out;
}

std::vector<double> lengthAlong(const std::vector<const Polygon*>& polygons, const std::vector<Ring>& rings,
                                double tolerance) {
  std::vector<EdgeInfo> edges, ringEdges;
  std::vector<EdgeBox> boxes, ringBoxes;
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    addEdges(*polygons[i], static_cast<int>(i), 0.5 * tolerance, edges, boxes);
  }
  for (const Ring& r : rings) addRingEdges(r, -1, 0.5 * tolerance, ringEdges, ringBoxes);
  std::vector<Cover> covers;
  CGAL::box_intersection_d(boxes.begin(), boxes.end(), ringBoxes.begin(), ringBoxes.end(),
                           [&](const EdgeBox& x, const EdgeBox& y) {
                             const EdgeInfo& e = edges[x.info()];
                             const EdgeInfo& f = ringEdges[y.info()];
                             double lo = 0, hi = 0;
                             if (coveredInterval(*e.p, *e.q, *f.p, *f.q, tolerance, lo, hi)) {
                               covers.push_back({x.info(), -1, lo, hi});
                             }
                           });
  std::vector<double> out(polygons.size(), 0.0);
  sumCovers(covers, edges, [&](int measured, int, double length) { out[measured] += length; });
  return out;
}

}  // namespace parcelscope::analysis::detail
