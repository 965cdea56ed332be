#include "parcelscope/core/Geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>  // part of every x86-64 processor
#endif

namespace parcelscope {

double signedArea(const Ring& ring) {
  const std::size_t n = ring.size();
  if (n < 3) return 0.0;
  // Shifted to the first vertex to keep the products small.
  const Point o = ring[0];
  double twice = 0.0;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double ax = ring[i].x - o.x, ay = ring[i].y - o.y;
    const double bx = ring[i + 1].x - o.x, by = ring[i + 1].y - o.y;
    twice += ax * by - bx * ay;
  }
  return 0.5 * twice;
}

double area(const Polygon& polygon) {
  double a = std::fabs(signedArea(polygon.outer));
  for (const auto& h : polygon.holes) a -= std::fabs(signedArea(h));
  return a;
}

double ringLength(const Ring& ring) {
  double l = 0.0;
  for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
    const Point& a = ring[i];
    const Point& b = ring[(i + 1) % n];
    l += norm(b.x - a.x, b.y - a.y);
  }
  return l;
}

double perimeter(const Polygon& polygon) {
  double l = ringLength(polygon.outer);
  for (const auto& h : polygon.holes) l += ringLength(h);
  return l;
}

Box bounds(const Ring& ring) {
  Box b{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
        std::numeric_limits<double>::lowest()};
  for (const auto& p : ring) {
    b.minX = std::min(b.minX, p.x);
    b.minY = std::min(b.minY, p.y);
    b.maxX = std::max(b.maxX, p.x);
    b.maxY = std::max(b.maxY, p.y);
  }
  return b;
}

Box bounds(const Polygon& polygon) { return bounds(polygon.outer); }

Point centroid(const Polygon& polygon) {
  double cx = 0, cy = 0, a = 0;
  auto accumulate = [&](const Ring& r) {
    const Point o = polygon.outer.empty() ? Point{} : polygon.outer[0];
    for (std::size_t i = 0, n = r.size(); i < n; ++i) {
      const double x0 = r[i].x - o.x, y0 = r[i].y - o.y;
      const double x1 = r[(i + 1) % n].x - o.x, y1 = r[(i + 1) % n].y - o.y;
      const double c = x0 * y1 - x1 * y0;
      a += c;
      cx += (x0 + x1) * c;
      cy += (y0 + y1) * c;
    }
  };
  accumulate(polygon.outer);
  for (const auto& h : polygon.holes) accumulate(h);
  if (std::fabs(a) < 1e-300) return polygon.outer.empty() ? Point{} : polygon.outer[0];
  const Point o = polygon.outer[0];
  return {o.x + cx / (3.0 * a), o.y + cy / (3.0 * a)};
}

namespace {
// Drops repeated consecutive vertices (and closing repeats of the first), in place.
void dedupe(Ring& r) {
  r.erase(std::unique(r.begin(), r.end(), [](const Point& a, const Point& b) { return a.x == b.x && a.y == b.y; }),
          r.end());
  while (r.size() > 1 && r.front().x == r.back().x && r.front().y == r.back().y) r.pop_back();
}
}  // namespace

bool sameVertices(const Polygon& a, const Polygon& b) {
  auto same = [](const Ring& x, const Ring& y) {
    return std::equal(x.begin(), x.end(), y.begin(), y.end(),
                      [](const Point& p, const Point& q) { return p.x == q.x && p.y == q.y; });
  };
  return same(a.outer, b.outer) && std::equal(a.holes.begin(), a.holes.end(), b.holes.begin(), b.holes.end(), same);
}

bool normalise(Polygon& polygon) {
  dedupe(polygon.outer);
  if (polygon.outer.size() < 3 || signedArea(polygon.outer) == 0.0) return false;
  if (signedArea(polygon.outer) < 0) std::reverse(polygon.outer.begin(), polygon.outer.end());
  std::vector<Ring> holes;
  for (auto& h : polygon.holes) {
    dedupe(h);
    if (h.size() < 3 || signedArea(h) == 0.0) continue;
    if (signedArea(h) > 0) std::reverse(h.begin(), h.end());
    holes.push_back(std::move(h));
  }
  polygon.holes.swap(holes);
  return true;
}

bool pointInRing(const Point& p, const Ring& ring) {
  bool inside = false;
  for (std::size_t i = 0, n = ring.size(), j = n - 1; i < n; j = i++) {
    const Point& a = ring[i];
    const Point& b = ring[j];
    if ((a.y > p.y) != (b.y > p.y)) {
      const double x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (p.x < x) inside = !inside;
    }
  }
  return inside;
}

bool pointInPolygon(const Point& p, const Polygon& polygon) {
  if (!pointInRing(p, polygon.outer)) return false;
  for (const auto& h : polygon.holes) {
    if (pointInRing(p, h)) return false;
  }
  return true;
}

Point interiorPoint(const Polygon& polygon) {
  if (polygon.outer.empty()) return {};
  const Point c = centroid(polygon);
  if (pointInPolygon(c, polygon)) return c;
  // Scan line through the middle of the bounding box: take the midpoint of the
  // widest interval inside the polygon.
  const Box b = bounds(polygon);
  double bestLen = -1;
  Point best = polygon.outer[0];
  for (double t : {0.5, 0.25, 0.75, 0.125, 0.375, 0.625, 0.875}) {
    const double y = b.minY + t * b.height();
    std::vector<double> xs;
    auto collect = [&](const Ring& r) {
      for (std::size_t i = 0, n = r.size(), j = n - 1; i < n; j = i++) {
        const Point& p = r[i];
        const Point& q = r[j];
        if ((p.y > y) != (q.y > y)) xs.push_back(p.x + (y - p.y) * (q.x - p.x) / (q.y - p.y));
      }
    };
    collect(polygon.outer);
    for (const auto& h : polygon.holes) collect(h);
    std::sort(xs.begin(), xs.end());
    for (std::size_t i = 0; i + 1 < xs.size(); i += 2) {
      if (xs[i + 1] - xs[i] > bestLen) {
        bestLen = xs[i + 1] - xs[i];
        best = {0.5 * (xs[i] + xs[i + 1]), y};
      }
    }
    if (bestLen > 0) break;
  }
  return best;
}

namespace {
// The square of pointSegmentDistance: the same sum, before its square root.
double pointSegmentDistance2(const Point& p, const Point& a, const Point& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = p.x - (a.x + t * dx), ey = p.y - (a.y + t * dy);
  return ex * ex + ey * ey;
}
}  // namespace

double pointSegmentDistance(const Point& p, const Point& a, const Point& b) {
  return __builtin_sqrt(pointSegmentDistance2(p, a, b));
}

namespace {
double cross(const Point& o, const Point& a, const Point& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

bool segmentsCross(const Point& a, const Point& b, const Point& c, const Point& d) {
  const double d1 = cross(c, d, a), d2 = cross(c, d, b);
  const double d3 = cross(a, b, c), d4 = cross(a, b, d);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

}  // namespace

double segmentDistance(const Point& a, const Point& b, const Point& c, const Point& d) {
  if (segmentsCross(a, b, c, d)) return 0.0;
  // One square root, of the least: the square root is correctly rounded and
  // never decreasing, so this is the least of the four distances exactly.
  return __builtin_sqrt(std::min(std::min(pointSegmentDistance2(a, c, d), pointSegmentDistance2(b, c, d)),
                                 std::min(pointSegmentDistance2(c, a, b), pointSegmentDistance2(d, a, b))));
}

bool isClearlySimple(const Ring& r) {
  if (r.size() < 3) return false;
  return isClearlySimple(r, bounds(r), signedArea(r));
}

bool isClearlySimple(const Ring& r, const Box& b, double ringArea) {
  const std::size_t n = r.size();
  if (n < 3) return false;
  const double eps = 1e-9 * std::max(b.width(), b.height());
  if (!(eps > 0) || std::fabs(ringArea) <= eps * eps) return false;
  for (std::size_t i = 0; i < n; ++i) {
    const Point& p = r[i];
    const Point& q = r[(i + 1) % n];
    const Point& s = r[(i + 2) % n];
    if (norm(q.x - p.x, q.y - p.y) <= eps) return false;
    // Fold-back: the next edge returns along this one.
    const double cr = (q.x - p.x) * (s.y - q.y) - (q.y - p.y) * (s.x - q.x);
    const double dot = (q.x - p.x) * (s.x - q.x) + (q.y - p.y) * (s.y - q.y);
    if (dot < 0 && std::fabs(cr) <= eps * norm(q.x - p.x, q.y - p.y)) return false;
  }
  // Edge boxes grown by eps: edges whose boxes do not meet are farther apart
  // than eps, and need no distance computed.
  const auto edgeBox = [&](std::size_t i) {
    const Point& p = r[i];
    const Point& q = r[(i + 1) % n];
    return Box{std::min(p.x, q.x), std::min(p.y, q.y), std::max(p.x, q.x), std::max(p.y, q.y)}.expanded(eps);
  };
  // Two edges not adjacent along the ring closer than eps.
  const auto tooClose = [&](std::size_t i, std::size_t j) {
    if (i > j) std::swap(i, j);
    if (j == i + 1 || (i == 0 && j == n - 1)) return false;
    return segmentDistance(r[i], r[(i + 1) % n], r[j], r[(j + 1) % n]) <= eps;
  };
  if (n <= 64) {
    // Every pair.
    Box boxes[64];
    for (std::size_t i = 0; i < n; ++i) boxes[i] = edgeBox(i);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 2; j < n; ++j) {
        if (boxes[i].intersects(boxes[j]) && tooClose(i, j)) return false;
      }
    }
    return true;
  }
  // A sweep in x: each edge meets only the edges whose boxes are still open
  // when its own box opens.
  // Scratch kept by each thread; the edges are sorted by their boxes' left
  // sides as (left, edge) pairs, not through the boxes (the answer does not
  // depend on the order of ties).
  thread_local std::vector<Box> boxes;
  thread_local std::vector<std::pair<double, std::size_t>> order;
  thread_local std::vector<std::size_t> open;
  boxes.resize(n);
  order.resize(n);
  open.clear();
  for (std::size_t i = 0; i < n; ++i) {
    boxes[i] = edgeBox(i);
    order[i] = {boxes[i].minX, i};
  }
  std::sort(order.begin(), order.end(),
            [](const std::pair<double, std::size_t>& x, const std::pair<double, std::size_t>& y) {
              return x.first < y.first;
            });
  for (const auto& entry : order) {
    const std::size_t i = entry.second;
    std::size_t kept = 0;
    for (const std::size_t j : open) {
      if (boxes[j].maxX < boxes[i].minX) continue;  // closed before this one opens
      open[kept++] = j;
      if (boxes[i].intersects(boxes[j]) && tooClose(i, j)) return false;
    }
    open.resize(kept);
    open.push_back(i);
  }
  return true;
}

void convexHullInto(const std::vector<Point>& points, Ring& hull) {
  thread_local std::vector<Point> pts;  // sorted copy, kept across calls on this thread
  pts.assign(points.begin(), points.end());
  std::sort(pts.begin(), pts.end(),
            [](const Point& a, const Point& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  pts.erase(
      std::unique(pts.begin(), pts.end(), [](const Point& a, const Point& b) { return a.x == b.x && a.y == b.y; }),
      pts.end());
  if (pts.size() < 3) {
    hull.assign(pts.begin(), pts.end());
    return;
  }
  hull.resize(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {  // lower hull
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {  // upper hull
    while (k >= t && cross(hull[k - 2], hull[k - 1], pts[i - 1]) <= 0) --k;
    hull[k++] = pts[i - 1];
  }
  hull.resize(k - 1);
}

void convexHullOfSimpleRing(const Ring& ring, Ring& hull) {
  const std::size_t n = ring.size();
  if (n < 4 || cross(ring[0], ring[1], ring[2]) == 0) {
    convexHullInto(ring, hull);
    return;
  }
  // The hull so far as a deque in an array, both ends holding the last point
  // added: bottom..top runs counter-clockwise. Each end grows by at most n.
  thread_local std::vector<Point> d;
  d.resize(2 * n + 2);
  std::size_t bottom = n, top = n + 3;
  d[bottom] = d[top] = ring[2];
  const bool left = cross(ring[0], ring[1], ring[2]) > 0;
  d[bottom + 1] = left ? ring[0] : ring[1];
  d[bottom + 2] = left ? ring[1] : ring[0];
  for (std::size_t i = 3; i < n; ++i) {
    const Point& v = ring[i];
    if (cross(d[bottom], d[bottom + 1], v) > 0 && cross(d[top - 1], d[top], v) > 0) continue;  // inside
    while (bottom + 1 < top && cross(d[bottom], d[bottom + 1], v) <= 0) ++bottom;
    d[--bottom] = v;
    while (bottom + 1 < top && cross(d[top - 1], d[top], v) <= 0) --top;
    d[++top] = v;
  }
  // As convexHullInto gives it: from the lowest point in x-then-y order (a
  // corner of the hull), counter-clockwise, without collinear points (the
  // deque may keep one where the ring closes).
  std::size_t first = bottom;
  for (std::size_t k = bottom + 1; k < top; ++k) {
    if (d[k].x < d[first].x || (d[k].x == d[first].x && d[k].y < d[first].y)) first = k;
  }
  const std::size_t m = top - bottom;
  hull.clear();
  for (std::size_t k = 0; k < m; ++k) {
    const Point& v = d[bottom + (first - bottom + k) % m];
    while (hull.size() >= 2 && cross(hull[hull.size() - 2], hull.back(), v) <= 0) hull.pop_back();
    hull.push_back(v);
  }
  while (hull.size() >= 3 && cross(hull[hull.size() - 2], hull.back(), hull.front()) <= 0) hull.pop_back();
}

Ring convexHull(const std::vector<Point>& points) {
  Ring hull;
  hull.reserve(2 * points.size());
  convexHullInto(points, hull);
  return hull;
}

namespace {

// The vertex of a large hull farthest along a direction, found from the
// hull's edge angles: a convex polygon's vertex is extreme for the directions
// between its two edges' outward normals. Used from kFastFrom vertices (below
// that, testing every vertex costs less).
class HullExtremes {
public:
  static constexpr std::size_t kFastFrom = 256;

  // The edges' directions of the hull (relative coordinates dxs, dys), turned
  // into one increasing sequence of angles; false unless the hull turns left
  // at every vertex (counter-clockwise, strictly convex).
  bool build(const std::vector<double>& dxs, const std::vector<double>& dys) {
    const std::size_t m = dxs.size();
    angles_.resize(m);
    double previous = 0;
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t k = (j + 1) % m;
      const double a = std::atan2(dys[k] - dys[j], dxs[k] - dxs[j]);
      if (j == 0) {
        angles_[0] = previous = a;
        continue;
      }
      double turn = a - std::remainder(previous, 2 * M_PI);
      while (turn <= 0) turn += 2 * M_PI;
      while (turn > 2 * M_PI) turn -= 2 * M_PI;
      if (!(turn < M_PI)) return false;
      angles_[j] = previous = previous + turn;
    }
    return angles_[m - 1] - angles_[0] < 2 * M_PI;
  }

  // The index of the vertex farthest along (x, y): the first whose outgoing
  // edge turns past the direction's left normal.
  std::size_t farthest(double x, double y) const {
    double psi = std::atan2(y, x) + 0.5 * M_PI;
    while (psi < angles_[0]) psi += 2 * M_PI;
    while (psi >= angles_[0] + 2 * M_PI) psi -= 2 * M_PI;
    const auto it = std::lower_bound(angles_.begin(), angles_.end(), psi);
    return it == angles_.end() ? 0 : static_cast<std::size_t>(it - angles_.begin());
  }

private:
  std::vector<double> angles_;
};

}  // namespace

OrientedBox smallestBoxAlongEdges(const Ring& hull, const Ring& edges) {
  OrientedBox best;
  if (hull.empty()) return best;
  best.center = hull[0];
  const Point o = hull[0];  // projections relative to a hull point keep precision
  // The hull relative to o, once (the same differences for every edge).
  thread_local std::vector<double> dxs, dys;
  const std::size_t m = hull.size();
  dxs.resize(m);
  dys.resize(m);
  for (std::size_t j = 0; j < m; ++j) {
    dxs[j] = hull[j].x - o.x;
    dys[j] = hull[j].y - o.y;
  }
  double bestArea = std::numeric_limits<double>::max();
  // A large hull: each extreme taken among the vertex its angle gives and two
  // neighbours each side (the same projections, so the same extremes, as
  // testing every vertex), in time logarithmic in the hull's size.
  thread_local HullExtremes extremes;
  const bool fast = m >= HullExtremes::kFastFrom && extremes.build(dxs, dys);
  for (std::size_t i = 0, n = edges.size(); i < n; ++i) {
    const Point& a = edges[i];
    const Point& b = edges[(i + 1) % n];
    const double l = norm(b.x - a.x, b.y - a.y);
    if (l == 0) continue;
    const Point e{(b.x - a.x) / l, (b.y - a.y) / l};
    // The extents of the projections along e and its normal, two points at a
    // time. Each projection is computed as one point at a time would, and the
    // extremes of a set do not depend on the order they are taken in.
    double minE1 = std::numeric_limits<double>::max(), maxE1 = std::numeric_limits<double>::lowest();
    double minN1 = minE1, maxN1 = maxE1;
    std::size_t j = 0;
    if (fast) {
      const auto around = [&](std::size_t centre, auto&& take) {
        for (std::size_t k = centre + m - 2; k <= centre + m + 2; ++k) take(k % m);
      };
      around(extremes.farthest(e.x, e.y), [&](std::size_t k) { maxE1 = std::max(maxE1, dxs[k] * e.x + dys[k] * e.y); });
      around(extremes.farthest(-e.x, -e.y),
             [&](std::size_t k) { minE1 = std::min(minE1, dxs[k] * e.x + dys[k] * e.y); });
      around(extremes.farthest(-e.y, e.x),
             [&](std::size_t k) { maxN1 = std::max(maxN1, -dxs[k] * e.y + dys[k] * e.x); });
      around(extremes.farthest(e.y, -e.x),
             [&](std::size_t k) { minN1 = std::min(minN1, -dxs[k] * e.y + dys[k] * e.x); });
    } else {
#if defined(__SSE2__)
      const __m128d ex = _mm_set1_pd(e.x), ey = _mm_set1_pd(e.y), sign = _mm_set1_pd(-0.0);
      __m128d minE = _mm_set1_pd(minE1), maxE = _mm_set1_pd(maxE1), minN = minE, maxN = maxE;
      for (; j + 2 <= m; j += 2) {
        const __m128d dx = _mm_loadu_pd(&dxs[j]), dy = _mm_loadu_pd(&dys[j]);
        const __m128d pe = _mm_add_pd(_mm_mul_pd(dx, ex), _mm_mul_pd(dy, ey));
        const __m128d pn = _mm_add_pd(_mm_mul_pd(_mm_xor_pd(dx, sign), ey), _mm_mul_pd(dy, ex));
        minE = _mm_min_pd(pe, minE);
        maxE = _mm_max_pd(pe, maxE);
        minN = _mm_min_pd(pn, minN);
        maxN = _mm_max_pd(pn, maxN);
      }
      double lo[2], hi[2], loN[2], hiN[2];
      _mm_storeu_pd(lo, minE);
      _mm_storeu_pd(hi, maxE);
      _mm_storeu_pd(loN, minN);
      _mm_storeu_pd(hiN, maxN);
      minE1 = std::min(lo[0], lo[1]);
      maxE1 = std::max(hi[0], hi[1]);
      minN1 = std::min(loN[0], loN[1]);
      maxN1 = std::max(hiN[0], hiN[1]);
#endif
      for (; j < m; ++j) {
        const double pe = dxs[j] * e.x + dys[j] * e.y;
        const double pn = -dxs[j] * e.y + dys[j] * e.x;
        minE1 = std::min(minE1, pe);
        maxE1 = std::max(maxE1, pe);
        minN1 = std::min(minN1, pn);
        maxN1 = std::max(maxN1, pn);
      }
    }
    const double w = maxE1 - minE1, h = maxN1 - minN1;
    if (w * h < bestArea * (1 - 1e-9)) {
      bestArea = w * h;
      const double ce = 0.5 * (minE1 + maxE1), cn = 0.5 * (minN1 + maxN1);
      best.center = {o.x + ce * e.x - cn * e.y, o.y + ce * e.y + cn * e.x};
      if (w >= h) {
        best.u = e;
        best.length = w;
        best.width = h;
      } else {
        best.u = {-e.y, e.x};
        best.length = h;
        best.width = w;
      }
    }
  }
  return best;
}

OrientedBox minimumAreaBox(const Ring& ring) {
  thread_local Ring hull;  // kept across calls on this thread
  convexHullInto(ring, hull);
  return minimumAreaBoxOfHull(hull);
}

OrientedBox minimumAreaBoxOfHull(const Ring& hull) {
  if (hull.size() >= 3) return smallestBoxAlongEdges(hull, hull);
  OrientedBox best;  // degenerate: a segment or a point
  if (hull.size() == 2) {
    const double dx = hull[1].x - hull[0].x, dy = hull[1].y - hull[0].y;
    const double l = norm(dx, dy);
    best.center = {0.5 * (hull[0].x + hull[1].x), 0.5 * (hull[0].y + hull[1].y)};
    if (l > 0) best.u = {dx / l, dy / l};
    best.length = l;
  } else if (hull.size() == 1) {
    best.center = hull[0];
  }
  return best;
}

}  // namespace parcelscope
