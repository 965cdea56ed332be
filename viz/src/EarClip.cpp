#include "EarClip.h"

namespace parcelscope::viz::detail {

namespace {

double cross(const Point& a, const Point& b, const Point& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

bool same(const Point& a, const Point& b) { return a.x == b.x && a.y == b.y; }

}  // namespace

bool earClip(const Ring& ring, std::vector<int>& triangles) {
  const auto n = static_cast<int>(ring.size());
  if (n < 3 || ring.size() > kEarClipMaxVertices) return false;
  double area = 0;
  const auto at = [&](int i) -> const Point& { return ring[static_cast<std::size_t>(i)]; };
  for (int i = 0; i < n; ++i) area += cross(at(0), at(i), at((i + 1) % n));
  if (area == 0) return false;
  // Every turn measured as if the ring went counter-clockwise.
  const double turn = area > 0 ? 1.0 : -1.0;
  // Buffers kept by each thread: a view's geometry clips thousands of rings.
  thread_local std::vector<int> prev, next;
  prev.resize(ring.size());
  next.resize(ring.size());
  for (int i = 0; i < n; ++i) {
    prev[static_cast<std::size_t>(i)] = (i + n - 1) % n;
    next[static_cast<std::size_t>(i)] = (i + 1) % n;
  }
  const std::size_t start = triangles.size();
  // b is an ear when it turns strictly left and no other remaining vertex lies
  // in or on the triangle (a, b, c); vertices at the triangle's corners (a
  // ring touching itself) are passed over.
  const auto isEar = [&](int a, int b, int c) {
    const Point &pa = at(a), &pb = at(b), &pc = at(c);
    if (turn * cross(pa, pb, pc) <= 0) return false;
    for (int v = next[static_cast<std::size_t>(c)]; v != a; v = next[static_cast<std::size_t>(v)]) {
      const Point& p = at(v);
      if (same(p, pa) || same(p, pb) || same(p, pc)) continue;
      if (turn * cross(pa, pb, p) >= 0 && turn * cross(pb, pc, p) >= 0 && turn * cross(pc, pa, p) >= 0) return false;
    }
    return true;
  };
  int remaining = n, b = 0, misses = 0;
  while (remaining > 3) {
    const int a = prev[static_cast<std::size_t>(b)], c = next[static_cast<std::size_t>(b)];
    if (isEar(a, b, c)) {
      triangles.insert(triangles.end(), {a, b, c});
      next[static_cast<std::size_t>(a)] = c;
      prev[static_cast<std::size_t>(c)] = a;
      --remaining;
      misses = 0;
      b = c;
    } else if (++misses > remaining) {
      triangles.resize(start);
      return false;
    } else {
      b = c;
    }
  }
  triangles.insert(triangles.end(), {prev[static_cast<std::size_t>(b)], b, next[static_cast<std::size_t>(b)]});
  return true;
}

}  // namespace parcelscope::viz::detail
