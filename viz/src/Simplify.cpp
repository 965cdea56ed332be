#include "Simplify.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

namespace parcelscope::viz::detail {

namespace {

// Points ordered by x, then y: the order that makes every choice below
// independent of the direction a ring runs.
bool before(const Point& a, const Point& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

std::uint64_t bits(double v) {
  if (v == 0) v = 0;  // -0 and 0 are one point
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

std::uint64_t mix(std::uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ull;
  return h ^ (h >> 33);
}

// Every vertex of every ring once, with a hash of the two neighbours it was
// first seen between (in the order of `before`), and whether another sighting
// had other neighbours (a junction).
class Sightings {
public:
  void reset(std::size_t vertices) {
    std::size_t size = 16;
    while (size < 2 * vertices) size *= 2;
    slots_.assign(size, Slot{});
    mask_ = size - 1;
    at_.clear();
    at_.reserve(vertices);
  }

  // Records ring[i] (between its neighbours); sightings are numbered in order.
  void see(const Point& v, const Point& p, const Point& n) {
    const bool order = before(p, n);
    const Point& a = order ? p : n;
    const Point& b = order ? n : p;
    const std::uint64_t pair = mix(bits(a.x) ^ mix(bits(a.y) ^ mix(bits(b.x) ^ mix(bits(b.y)))));
    std::size_t i = mix(bits(v.x) * 0x9e3779b97f4a7c15ull ^ bits(v.y)) & mask_;
    while (slots_[i].used && !(slots_[i].x == v.x && slots_[i].y == v.y)) i = (i + 1) & mask_;
    Slot& s = slots_[i];
    if (!s.used) {
      s = {v.x, v.y, pair, true, false};
    } else if (s.pair != pair) {
      s.junction = true;
    }
    at_.push_back(static_cast<std::uint32_t>(i));
  }

  // Whether the k-th sighting's vertex is a junction.
  bool junction(std::size_t k) const { return slots_[at_[k]].junction; }

private:
  struct Slot {
    double x = 0, y = 0;
    std::uint64_t pair = 0;
    bool used = false;
    bool junction = false;
  };
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> at_;
  std::size_t mask_ = 0;
};

// Squared distance from p to the segment between a and b, with the ends taken
// in the order of `before`: the same number whichever way the ring runs.
double distance2(const Point& p, Point a, Point b) {
  if (before(b, a)) std::swap(a, b);
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double length2 = dx * dx + dy * dy;
  double t = length2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / length2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  const double ex = a.x + t * dx - p.x, ey = a.y + t * dy - p.y;
  return ex * ex + ey * ey;
}

// Douglas-Peucker on the run of `count` vertices of `ring` starting at
// `first` (both ends kept by the caller): marks in `keep` the vertices that
// stay. The farthest vertex is chosen by distance, then by `before`, so the
// run gives the same vertices read from either end.
void simplifyRun(const Ring& ring, std::size_t first, std::size_t count, double tolerance2, std::vector<char>& keep,
                 std::vector<std::pair<std::size_t, std::size_t>>& stack) {
  const std::size_t n = ring.size();
  // first + k stays below 2n (a run ends at most one turn after it starts):
  // no division needed to wrap it.
  const auto at = [&](std::size_t k) { return first + k < n ? first + k : first + k - n; };
  stack.clear();
  stack.emplace_back(0, count - 1);
  while (!stack.empty()) {
    const auto [lo, hi] = stack.back();
    stack.pop_back();
    if (hi - lo < 2) continue;
    const Point& a = ring[at(lo)];
    const Point& b = ring[at(hi)];
    std::size_t best = 0;
    double farthest = -1;
    for (std::size_t k = lo + 1; k < hi; ++k) {
      const Point& p = ring[at(k)];
      const double d = distance2(p, a, b);
      if (d > farthest || (d == farthest && before(p, ring[at(best)]))) {
        farthest = d;
        best = k;
      }
    }
    if (farthest <= tolerance2) continue;
    keep[at(best)] = 1;
    stack.emplace_back(lo, best);
    stack.emplace_back(best, hi);
  }
}

// `ring` simplified into `out`; its vertices are sightings first, first + 1, ...
void simplifyRing(const Ring& ring, std::size_t first, double tolerance2, const Sightings& seen, Ring& out,
                  std::vector<char>& keep, std::vector<std::size_t>& anchors,
                  std::vector<std::pair<std::size_t, std::size_t>>& stack) {
  const std::size_t n = ring.size();
  // (Triangles too: a triangle keeping a vertex its neighbours drop would
  // overlap or leave a gap; one thinner than the tolerance goes.)
  out.clear();
  if (n < 3) return;
  keep.assign(n, 0);
  anchors.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (seen.junction(first + i)) anchors.push_back(i);
  }
  if (anchors.empty()) {
    // A ring shared whole or not at all: its smallest vertex and the vertex
    // farthest from it, the same for every ring with these vertices.
    std::size_t low = 0;
    for (std::size_t i = 1; i < n; ++i) {
      if (before(ring[i], ring[low])) low = i;
    }
    std::size_t far = low == 0 ? 1 : 0;
    double farthest = -1;
    for (std::size_t i = 0; i < n; ++i) {
      if (i == low) continue;
      const double dx = ring[i].x - ring[low].x, dy = ring[i].y - ring[low].y;
      const double d = dx * dx + dy * dy;
      if (d > farthest || (d == farthest && before(ring[i], ring[far]))) {
        farthest = d;
        far = i;
      }
    }
    anchors = {std::min(low, far), std::max(low, far)};
  }
  for (std::size_t a : anchors) keep[a] = 1;
  for (std::size_t j = 0; j < anchors.size(); ++j) {
    const std::size_t from = anchors[j];
    const std::size_t to = j + 1 < anchors.size() ? anchors[j + 1] : anchors[0] + n;
    simplifyRun(ring, from, to - from + 1, tolerance2, keep, stack);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (keep[i]) out.push_back(ring[i]);
  }
  if (out.size() < 3) out.clear();
}

}  // namespace

void simplifyShared(const std::vector<const Polygon*>& shapes, double tolerance, std::vector<Polygon>& out) {
  out.resize(shapes.size());
  if (!(tolerance > 0)) {
    for (std::size_t k = 0; k < shapes.size(); ++k) out[k] = *shapes[k];
    return;
  }
  std::size_t vertices = 0;
  for (const Polygon* shape : shapes) {
    vertices += shape->outer.size();
    for (const Ring& hole : shape->holes) vertices += hole.size();
  }
  // Scratch kept by each thread: a view builds its parts side by side, again
  // after every change.
  thread_local Sightings seen;
  thread_local std::vector<char> keep;
  thread_local std::vector<std::size_t> anchors;
  thread_local std::vector<std::pair<std::size_t, std::size_t>> stack;
  seen.reset(vertices);
  const auto look = [&](const Ring& ring) {
    const std::size_t n = ring.size();
    for (std::size_t i = 0; i < n; ++i) seen.see(ring[i], ring[i == 0 ? n - 1 : i - 1], ring[i + 1 == n ? 0 : i + 1]);
  };
  for (const Polygon* shape : shapes) {
    look(shape->outer);
    for (const Ring& hole : shape->holes) look(hole);
  }
  const double tolerance2 = tolerance * tolerance;
  std::size_t first = 0;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    const Polygon& shape = *shapes[k];
    Polygon& p = out[k];
    simplifyRing(shape.outer, first, tolerance2, seen, p.outer, keep, anchors, stack);
    first += shape.outer.size();
    std::size_t holes = 0;
    for (const Ring& hole : shape.holes) {
      if (p.holes.size() <= holes) p.holes.emplace_back();
      simplifyRing(hole, first, tolerance2, seen, p.holes[holes], keep, anchors, stack);
      first += hole.size();
      if (!p.holes[holes].empty()) ++holes;
    }
    p.holes.resize(p.outer.empty() ? 0 : holes);
  }
}

}  // namespace parcelscope::viz::detail
