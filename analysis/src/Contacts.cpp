#include "Contacts.h"

#include "parcelscope/analysis/Metrics.h"

#include "BoxPairs.h"

#include "parcelscope/core/BoxIndex.h"
#include "parcelscope/core/Parallel.h"

#include <boost/iterator/function_output_iterator.hpp>

#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <tuple>

namespace parcelscope::analysis::detail {

namespace {

using EdgeBox = CGAL::Box_intersection_d::Box_with_info_d<double, 2, std::size_t>;

// (edge of the measured polygon, interval) records, grouped to take the union
// of intervals per edge.
struct Cover {
  std::size_t edge;
  double lo, hi;
  bool operator<(const Cover& o) const { return std::tie(edge, lo) < std::tie(o.edge, o.lo); }
};

}  // namespace

namespace {

// coveredInterval, given both edges' lengths (not 0) and unit directions.
inline bool coveredAlong(const Point& p, double len, double ux, double uy, const Point& r, const Point& s, double vx,
                         double vy, double tolerance, double& lo, double& hi) {
  static const double sinMax = std::sin(10.0 * kPi / 180.0);
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

}  // namespace

bool coveredInterval(const Point& p, const Point& q, const Point& r, const Point& s, double tolerance, double& lo,
                     double& hi) {
  const double len = norm(q.x - p.x, q.y - p.y);
  const double l2 = norm(s.x - r.x, s.y - r.y);
  if (len == 0 || l2 == 0) return false;
  return coveredAlong(p, len, (q.x - p.x) / len, (q.y - p.y) / len, r, s, (s.x - r.x) / l2, (s.y - r.y) / l2, tolerance,
                      lo, hi);
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

namespace {

struct NearEdge {
  const Point* p;
  const Point* q;
  double lo[2], hi[2];
  double len, ux, uy;  // length and unit direction, computed once per edge
};

// Edges sorted by the left side of their boxes: those whose boxes meet a
// query box are found among the edges starting at most the widest box's
// width to its left, not by testing every edge. Many edges (a street network
// stored as a parcel, thousands of edges kilometres across, some of them
// long) go to an R-tree instead: an x-slab as wide as the longest edge would
// hold a large share of them for every query.
class EdgeIndex {
public:
  // Below this many edges, testing every one costs less.
  static constexpr std::size_t kScanUpTo = 24;
  // From this many edges, the R-tree.
  static constexpr std::size_t kTreeFrom = 512;

  void build(const std::vector<NearEdge>& edges) {
    order_.clear();
    left_.clear();
    tree_.clear();
    widest_ = 0;
    if (edges.size() <= kScanUpTo) return;
    if (edges.size() >= kTreeFrom) {
      std::vector<std::pair<IndexBox, std::size_t>> boxes;
      boxes.reserve(edges.size());
      for (std::size_t j = 0; j < edges.size(); ++j) {
        boxes.emplace_back(
            IndexBox(IndexPoint(edges[j].lo[0], edges[j].lo[1]), IndexPoint(edges[j].hi[0], edges[j].hi[1])), j);
      }
      tree_ = BoxTree<std::size_t>(boxes.begin(), boxes.end());  // packed (bulk loading)
      return;
    }
    // Sorted as (left side, edge) pairs; `meeting` sorts what it finds, so
    // the order of ties does not matter.
    thread_local std::vector<std::pair<double, std::size_t>> sorted;
    sorted.resize(edges.size());
    for (std::size_t j = 0; j < edges.size(); ++j) sorted[j] = {edges[j].lo[0], j};
    std::sort(sorted.begin(), sorted.end(),
              [](const std::pair<double, std::size_t>& a, const std::pair<double, std::size_t>& b) {
                return a.first < b.first;
              });
    order_.resize(edges.size());
    left_.resize(edges.size());
    for (std::size_t k = 0; k < sorted.size(); ++k) {
      const std::size_t j = sorted[k].second;
      order_[k] = j;
      left_[k] = sorted[k].first;
      widest_ = std::max(widest_, edges[j].hi[0] - edges[j].lo[0]);
    }
  }

  // The indices of `edges` (those given to build) whose boxes meet `box`
  // (closed boxes), in increasing order.
  void meeting(const std::vector<NearEdge>& edges, const Box& box, std::vector<std::size_t>& out) const {
    out.clear();
    auto meets = [&](const NearEdge& e) {
      return e.lo[0] <= box.maxX && box.minX <= e.hi[0] && e.lo[1] <= box.maxY && box.minY <= e.hi[1];
    };
    if (!tree_.empty()) {
      // Boost.Geometry's box intersection is closed, as `meets`.
      tree_.query(boost::geometry::index::intersects(indexBox(box)),
                  boost::iterators::make_function_output_iterator(
                      [&](const std::pair<IndexBox, std::size_t>& v) { out.push_back(v.second); }));
      std::sort(out.begin(), out.end());
      return;
    }
    if (order_.empty()) {
      for (std::size_t j = 0; j < edges.size(); ++j) {
        if (meets(edges[j])) out.push_back(j);
      }
      return;
    }
    const auto from = std::lower_bound(left_.begin(), left_.end(), box.minX - widest_);
    const auto to = std::upper_bound(from, left_.end(), box.maxX);
    for (auto k = from; k != to; ++k) {
      const std::size_t j = order_[static_cast<std::size_t>(k - left_.begin())];
      if (meets(edges[j])) out.push_back(j);
    }
    std::sort(out.begin(), out.end());
  }

private:
  std::vector<std::size_t> order_;
  std::vector<double> left_;  // edges' lo[0], in order_
  double widest_ = 0;
  BoxTree<std::size_t> tree_;
};

// coveredInterval(*e.p, *e.q, *f.p, *f.q, ...) with the lengths and directions
// computed when the edges were gathered: the same values, without the square roots.
bool coveredInterval(const NearEdge& e, const NearEdge& f, double tolerance, double& lo, double& hi) {
  if (e.len == 0 || f.len == 0) return false;
  return coveredAlong(*e.p, e.len, e.ux, e.uy, *f.p, *f.q, f.ux, f.uy, tolerance, lo, hi);
}

}  // namespace

Box contactBox(const Polygon& polygon, double tolerance) {
  Box b = bounds(polygon.outer);
  for (const Ring& h : polygon.holes) {
    const Box hb = bounds(h);
    b = {std::min(b.minX, hb.minX), std::min(b.minY, hb.minY), std::max(b.maxX, hb.maxX), std::max(b.maxY, hb.maxY)};
  }
  return b.expanded(0.5 * tolerance);
}

namespace {

// Appends the edges of `r`, in order, whose boxes grown by `grow` meet `box`
// (closed boxes).
void appendEdgesNear(const Ring& r, double grow, const Box& box, std::vector<NearEdge>& out) {
  if (out.capacity() < out.size() + r.size()) out.reserve(std::max(out.size() + r.size(), 2 * out.capacity()));
  for (std::size_t i = 0, n = r.size(); i < n; ++i) {
    const Point& p = r[i];
    const Point& q = r[(i + 1) % n];
    NearEdge e{&p,
               &q,
               {std::min(p.x, q.x) - grow, std::min(p.y, q.y) - grow},
               {std::max(p.x, q.x) + grow, std::max(p.y, q.y) + grow},
               0,
               0,
               0};
    if (e.lo[0] <= box.maxX && box.minX <= e.hi[0] && e.lo[1] <= box.maxY && box.minY <= e.hi[1]) {
      e.len = norm(q.x - p.x, q.y - p.y);
      if (e.len != 0) {
        e.ux = (q.x - p.x) / e.len;
        e.uy = (q.y - p.y) / e.len;
      }
      out.push_back(e);
    }
  }
}

// The edges of `polygon`, in ring order (outer ring, then holes), whose boxes
// grown by `grow` meet `box` (closed boxes).
void edgesNear(const Polygon& polygon, double grow, const Box& box, std::vector<NearEdge>& out) {
  out.clear();
  appendEdgesNear(polygon.outer, grow, box, out);
  for (const Ring& h : polygon.holes) appendEdgesNear(h, grow, box, out);
}

struct PairMeasure {
  bool close = false;
  double sharedA = 0, sharedB = 0;  // boundary of a along b, of b along a
  bool enough = false;              // stopped early: both shared lengths reach `enough`
};

// One pair of polygons, edge pair by edge pair: edges whose boxes (grown by
// half the close tolerance) meet and that come within the close tolerance;
// covered intervals within the shared tolerance, united per edge and summed in
// ring order. `boxA` and `boxB` are the polygons' bounds grown the same way:
// only edges meeting the other polygon's box can pair. Without `closeness`
// only the shared lengths are measured (`close` stays false): an edge pair
// with a covered interval is within the tolerance anyway.
PairMeasure measureEdges(const std::vector<NearEdge>& ea, const std::vector<NearEdge>& eb, double closeTolerance,
                         double sharedTolerance, bool closeness, double enough = HUGE_VAL) {
  thread_local std::vector<std::pair<double, double>> intervals;
  thread_local std::vector<Cover> coversB;
  coversB.clear();
  PairMeasure m;
  for (const NearEdge& e : ea) {
    intervals.clear();
    for (std::size_t j = 0; j < eb.size(); ++j) {
      const NearEdge& f = eb[j];
      if (!(e.lo[0] <= f.hi[0] && f.lo[0] <= e.hi[0] && e.lo[1] <= f.hi[1] && f.lo[1] <= e.hi[1])) continue;
      if (closeness) {
        if (segmentDistance(*e.p, *e.q, *f.p, *f.q) > closeTolerance) continue;
        m.close = true;
      }
      double lo = 0, hi = 0, loB = 0, hiB = 0;
      const bool alongA = coveredInterval(e, f, sharedTolerance, lo, hi);
      if (alongA) intervals.emplace_back(lo, hi);
      const bool alongB = coveredInterval(f, e, sharedTolerance, loB, hiB);
      if (alongB) coversB.push_back({j, loB, hiB});
      // One edge pair covering `enough` both ways: each shared length (a sum
      // of unions holding these intervals) is at least that much.
      if (alongA && alongB && hi - lo >= enough && hiB - loB >= enough) {
        m.enough = true;
        return m;
      }
    }
    if (!intervals.empty()) m.sharedA += unionLength(intervals);
  }
  std::sort(coversB.begin(), coversB.end());
  for (std::size_t i = 0; i < coversB.size();) {
    std::size_t j = i;
    intervals.clear();
    for (; j < coversB.size() && coversB[j].edge == coversB[i].edge; ++j) {
      intervals.emplace_back(coversB[j].lo, coversB[j].hi);
    }
    m.sharedB += unionLength(intervals);
    i = j;
  }
  return m;
}

// Every edge of a polygon with many vertices (a street network stored as a
// parcel has tens of thousands), gathered and indexed once: each of its pairs
// then finds the edges near the other polygon without testing them all.
struct IndexedEdges {
  static constexpr std::size_t kFromVertices = 256;
  std::vector<NearEdge> all;  // ring order, as edgesNear gives them
  EdgeIndex index;
  IndexedEdges(const Polygon& polygon, double grow) {
    const Box everything{-HUGE_VAL, -HUGE_VAL, HUGE_VAL, HUGE_VAL};
    edgesNear(polygon, grow, everything, all);
    index.build(all);
  }
  // edgesNear(polygon, grow, box, out): the same edges, in the same order.
  void near(const Box& box, std::vector<NearEdge>& out) const {
    thread_local std::vector<std::size_t> found;
    index.meeting(all, box, found);
    out.clear();
    for (std::size_t j : found) out.push_back(all[j]);
  }
};

PairMeasure measurePair(const Polygon& a, const Polygon& b, const Box& boxA, const Box& boxB, double closeTolerance,
                        double sharedTolerance, bool closeness = true, double enough = HUGE_VAL,
                        const IndexedEdges* indexedA = nullptr, const IndexedEdges* indexedB = nullptr) {
  thread_local std::vector<NearEdge> ea, eb;
  const double grow = 0.5 * closeTolerance;
  if (indexedA) {
    indexedA->near(boxB, ea);
  } else {
    edgesNear(a, grow, boxB, ea);
  }
  if (indexedB) {
    indexedB->near(boxA, eb);
  } else {
    edgesNear(b, grow, boxA, eb);
  }
  return measureEdges(ea, eb, closeTolerance, sharedTolerance, closeness, enough);
}

}  // namespace

std::vector<Contact> contacts(const std::vector<const Polygon*>& polygons, double tolerance, double sharedTolerance,
                              double enough) {
  std::vector<Box> boxes(polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) boxes[i] = contactBox(*polygons[i], tolerance);
  return contacts(polygons, intersectingPairs(boxes), tolerance, sharedTolerance, enough);
}

std::vector<Contact> contacts(const std::vector<const Polygon*>& polygons,
                              const std::vector<std::pair<int, int>>& candidates, double tolerance,
                              double sharedTolerance, double enough) {
  if (sharedTolerance < 0 || sharedTolerance > tolerance) sharedTolerance = tolerance;
  std::vector<Box> boxes(polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) boxes[i] = contactBox(*polygons[i], tolerance);
  std::vector<std::unique_ptr<IndexedEdges>> indexed(polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    std::size_t vertices = polygons[i]->outer.size();
    for (const Ring& h : polygons[i]->holes) vertices += h.size();
    if (vertices >= IndexedEdges::kFromVertices)
      indexed[i] = std::make_unique<IndexedEdges>(*polygons[i], 0.5 * tolerance);
  }
  std::vector<PairMeasure> measured(candidates.size());
  auto measureRange = [&](std::size_t from, std::size_t to) {
    for (std::size_t k = from; k < to; ++k) {
      const auto [i, j] = candidates[k];
      measured[k] = measurePair(*polygons[i], *polygons[j], boxes[i], boxes[j], tolerance, sharedTolerance, true,
                                enough, indexed[i].get(), indexed[j].get());
    }
  };
  // Small inputs (one block, one parcel pair) stay on the calling thread.
  constexpr std::size_t kChunk = 2048;
  if (candidates.size() < 4 * kChunk) {
    measureRange(0, candidates.size());
  } else {
    parallelFor((candidates.size() + kChunk - 1) / kChunk,
                [&](std::size_t c) { measureRange(c * kChunk, std::min(candidates.size(), (c + 1) * kChunk)); });
  }
  std::vector<Contact> out;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    if (!measured[k].close) continue;
    Contact c;
    c.a = candidates[k].first;
    c.b = candidates[k].second;
    c.close = true;
    // Both sides measure the same shared stretch; take the smaller (digitising
    // differences can make one side's edges overlap the other's twice).
    c.shared = measured[k].enough ? enough : std::min(measured[k].sharedA, measured[k].sharedB);
    out.push_back(c);
  }
  return out;
}

double sharedLength(const Polygon& a, const Polygon& b, double tolerance) {
  const PairMeasure m =
      measurePair(a, b, contactBox(a, tolerance), contactBox(b, tolerance), tolerance, tolerance, false);
  return std::min(m.sharedA, m.sharedB);
}

std::vector<double> lengthAlong(const std::vector<const Polygon*>& polygons, const std::vector<Ring>& rings,
                                double tolerance) {
  // Polygon by polygon: the ring edges near its contact box, then each of its
  // edges against those. Pairs of a polygon edge and a ring edge are tested
  // when their boxes grown by half the tolerance meet, as an edge-by-edge
  // search would pair them; each edge's covered intervals are united and the
  // edges summed in ring order.
  constexpr std::size_t kEveryPairUpTo = 16384;
  constexpr std::ptrdiff_t kScanCutoff = 1000;
  const double grow = 0.5 * tolerance;
  const Box everything{-HUGE_VAL, -HUGE_VAL, HUGE_VAL, HUGE_VAL};
  std::vector<NearEdge> ringEdges;
  for (const Ring& r : rings) appendEdgesNear(r, grow, everything, ringEdges);
  std::vector<Box> boxes(polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) boxes[i] = contactBox(*polygons[i], tolerance);
  // (polygon, ring edge) pairs whose boxes meet, by polygon.
  std::vector<std::pair<std::size_t, std::size_t>> near;
  if (polygons.size() * ringEdges.size() <= kEveryPairUpTo) {
    EdgeIndex index;
    index.build(ringEdges);
    std::vector<std::size_t> found;
    for (std::size_t i = 0; i < polygons.size(); ++i) {
      index.meeting(ringEdges, boxes[i], found);
      for (std::size_t j : found) near.emplace_back(i, j);
    }
  } else {
    std::vector<EdgeBox> polygonBoxes, edgeBoxes;
    polygonBoxes.reserve(polygons.size());
    edgeBoxes.reserve(ringEdges.size());
    for (std::size_t i = 0; i < polygons.size(); ++i) {
      double lo[2] = {boxes[i].minX, boxes[i].minY}, hi[2] = {boxes[i].maxX, boxes[i].maxY};
      polygonBoxes.emplace_back(lo, hi, i);
    }
    for (std::size_t j = 0; j < ringEdges.size(); ++j) {
      double lo[2] = {ringEdges[j].lo[0], ringEdges[j].lo[1]}, hi[2] = {ringEdges[j].hi[0], ringEdges[j].hi[1]};
      edgeBoxes.emplace_back(lo, hi, j);
    }
    // Below kScanCutoff boxes a side, CGAL scans them sorted along x (its
    // segment tree costs more than it saves there).
    CGAL::box_intersection_d(
        polygonBoxes.begin(), polygonBoxes.end(), edgeBoxes.begin(), edgeBoxes.end(),
        [&](const EdgeBox& a, const EdgeBox& b) { near.emplace_back(a.info(), b.info()); }, kScanCutoff);
    std::sort(near.begin(), near.end());
  }
  std::vector<double> out(polygons.size(), 0.0);
  std::vector<NearEdge> edges, candidates;
  std::vector<std::pair<double, double>> intervals;
  EdgeIndex candidateIndex;
  std::vector<std::size_t> found;
  for (std::size_t k = 0; k < near.size();) {
    const std::size_t i = near[k].first;
    candidates.clear();
    Box reach{HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (; k < near.size() && near[k].first == i; ++k) {
      const NearEdge& f = ringEdges[near[k].second];
      candidates.push_back(f);
      reach = {std::min(reach.minX, f.lo[0]), std::min(reach.minY, f.lo[1]), std::max(reach.maxX, f.hi[0]),
               std::max(reach.maxY, f.hi[1])};
    }
    edgesNear(*polygons[i], grow, reach, edges);
    // Many edges on both sides (a large parcel along a long ring): the
    // candidates meeting each edge's box come from an index, in the same order.
    const bool indexed = edges.size() > EdgeIndex::kScanUpTo && candidates.size() > EdgeIndex::kScanUpTo;
    if (indexed) candidateIndex.build(candidates);
    double total = 0;
    for (const NearEdge& e : edges) {
      intervals.clear();
      auto measure = [&](const NearEdge& f) {
        if (!(e.lo[0] <= f.hi[0] && f.lo[0] <= e.hi[0] && e.lo[1] <= f.hi[1] && f.lo[1] <= e.hi[1])) return;
        double lo = 0, hi = 0;
        if (coveredInterval(e, f, tolerance, lo, hi)) intervals.emplace_back(lo, hi);
      };
      if (indexed) {
        candidateIndex.meeting(candidates, {e.lo[0], e.lo[1], e.hi[0], e.hi[1]}, found);
        for (std::size_t j : found) measure(candidates[j]);
      } else {
        for (const NearEdge& f : candidates) measure(f);
      }
      if (!intervals.empty()) total += unionLength(intervals);
    }
    out[i] = total;
  }
  return out;
}

}  // namespace parcelscope::analysis::detail

namespace parcelscope::analysis {

struct PreparedBoundary::Impl {
  std::vector<detail::NearEdge> edges;  // every edge of the reference, boxes grown by half the tolerance, ring order
  detail::EdgeIndex index;              // of edges
  Box box;                              // the reference's contact box
  Box bounds;                           // the reference's bounds
  double tolerance = 0;
};

PreparedBoundary::PreparedBoundary(const Polygon& reference, double tolerance) : impl_(std::make_unique<Impl>()) {
  impl_->tolerance = tolerance;
  impl_->box = detail::contactBox(reference, tolerance);
  impl_->bounds = parcelscope::bounds(reference);
  const Box everything{-HUGE_VAL, -HUGE_VAL, HUGE_VAL, HUGE_VAL};
  detail::edgesNear(reference, 0.5 * tolerance, everything, impl_->edges);
  impl_->index.build(impl_->edges);
}

PreparedBoundary::~PreparedBoundary() = default;

double PreparedBoundary::sharedLength(const Polygon& piece) const { return measure(piece, HUGE_VAL); }

bool PreparedBoundary::sharesAtLeast(const Polygon& piece, double length) const {
  return measure(piece, length) >= length;
}

double PreparedBoundary::measure(const Polygon& piece, double enough) const {
  thread_local std::vector<detail::NearEdge> ea, eb;
  thread_local std::vector<std::size_t> found;
  const Impl& r = *impl_;
  if (!parcelscope::bounds(piece).expanded(r.tolerance).intersects(r.bounds)) return 0.0;  // as sharedBoundaryLength
  const double grow = 0.5 * r.tolerance;
  detail::edgesNear(piece, grow, r.box, ea);
  const Box box = detail::contactBox(piece, r.tolerance);
  r.index.meeting(r.edges, box, found);
  eb.clear();
  for (std::size_t j : found) eb.push_back(r.edges[j]);
  const detail::PairMeasure m = detail::measureEdges(ea, eb, r.tolerance, r.tolerance, false, enough);
  return m.enough ? enough : std::min(m.sharedA, m.sharedB);
}

}  // namespace parcelscope::analysis
