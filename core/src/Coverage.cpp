#include "parcelscope/core/Coverage.h"

#include <algorithm>
#include <cstddef>
#include <utility>

namespace parcelscope {

namespace {

struct Edge {
  Point a, b;
};

bool same(const Point& p, const Point& q) { return p.x == q.x && p.y == q.y; }
bool before(const Point& p, const Point& q) { return p.x < q.x || (p.x == q.x && p.y < q.y); }

void addRing(const Ring& ring, std::vector<Edge>& edges) {
  for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
    const Point& a = ring[i];
    const Point& b = ring[i + 1 == n ? 0 : i + 1];
    if (!same(a, b)) edges.push_back({a, b});
  }
}

// Every edge split at the vertices of the set lying on it within `snap`; the
// pieces run through the vertices themselves, so a neighbour's edges ending
// there find their reverse.
std::vector<Edge> splitAtVertices(const std::vector<Edge>& edges, double snap) {
  std::vector<Point> vertices;
  vertices.reserve(edges.size());
  for (const Edge& e : edges) vertices.push_back(e.a);
  std::sort(vertices.begin(), vertices.end(), before);
  vertices.erase(std::unique(vertices.begin(), vertices.end(), same), vertices.end());

  std::vector<Edge> out;
  out.reserve(edges.size() + edges.size() / 4);
  std::vector<std::pair<double, Point>> inner;
  for (const Edge& e : edges) {
    const double minX = std::min(e.a.x, e.b.x) - snap, maxX = std::max(e.a.x, e.b.x) + snap;
    const double minY = std::min(e.a.y, e.b.y) - snap, maxY = std::max(e.a.y, e.b.y) + snap;
    const double dx = e.b.x - e.a.x, dy = e.b.y - e.a.y;
    const double length2 = dx * dx + dy * dy;
    inner.clear();
    auto it = std::lower_bound(vertices.begin(), vertices.end(), minX,
                               [](const Point& p, double x) { return p.x < x; });
    for (; it != vertices.end() && it->x <= maxX; ++it) {
      const Point& v = *it;
      if (v.y < minY || v.y > maxY || same(v, e.a) || same(v, e.b)) continue;
      const double t = ((v.x - e.a.x) * dx + (v.y - e.a.y) * dy) / length2;
      if (t <= 0 || t >= 1) continue;
      if (norm(e.a.x + t * dx - v.x, e.a.y + t * dy - v.y) <= snap) inner.emplace_back(t, v);
    }
    std::sort(inner.begin(), inner.end(), [](const auto& p, const auto& q) { return p.first < q.first; });
    Point from = e.a;
    for (const auto& [t, v] : inner) {
      if (!same(v, from)) out.push_back({from, v});
      from = v;
    }
    out.push_back({from, e.b});
  }
  return out;
}

// Drops every edge that appears once each way; nothing when an edge appears
// twice in one direction or more than twice.
std::optional<std::vector<Edge>> cancelShared(const std::vector<Edge>& edges) {
  struct Key {
    Point lo, hi;
    bool forward;
  };
  std::vector<Key> keys;
  keys.reserve(edges.size());
  for (const Edge& e : edges) {
    keys.push_back(before(e.a, e.b) ? Key{e.a, e.b, true} : Key{e.b, e.a, false});
  }
  auto segmentBefore = [](const Key& p, const Key& q) {
    if (!same(p.lo, q.lo)) return before(p.lo, q.lo);
    return before(p.hi, q.hi);
  };
  std::sort(keys.begin(), keys.end(), segmentBefore);
  std::vector<Edge> left;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i + 1;
    while (j < keys.size() && same(keys[j].lo, keys[i].lo) && same(keys[j].hi, keys[i].hi)) ++j;
    if (j - i == 1) {
      const Key& k = keys[i];
      left.push_back(k.forward ? Edge{k.lo, k.hi} : Edge{k.hi, k.lo});
    } else if (j - i > 2 || keys[i].forward == keys[i + 1].forward) {
      return std::nullopt;
    }
    i = j;
  }
  return left;
}

// Chains edges into closed rings; nothing unless every vertex starts exactly
// one edge and every chain closes on itself.
std::optional<std::vector<Ring>> chainRings(std::vector<Edge> edges) {
  std::sort(edges.begin(), edges.end(), [](const Edge& p, const Edge& q) { return before(p.a, q.a); });
  for (std::size_t i = 1; i < edges.size(); ++i) {
    if (same(edges[i - 1].a, edges[i].a)) return std::nullopt;
  }
  std::vector<char> used(edges.size(), 0);
  std::vector<Ring> rings;
  for (std::size_t first = 0; first < edges.size(); ++first) {
    if (used[first]) continue;
    Ring ring;
    std::size_t current = first;
    while (true) {
      used[current] = 1;
      ring.push_back(edges[current].a);
      const Point& end = edges[current].b;
      const auto next = std::lower_bound(edges.begin(), edges.end(), end,
                                         [](const Edge& e, const Point& p) { return before(e.a, p); });
      if (next == edges.end() || !same(next->a, end)) return std::nullopt;
      current = static_cast<std::size_t>(next - edges.begin());
      if (current == first) break;
      if (used[current]) return std::nullopt;
    }
    rings.push_back(std::move(ring));
  }
  return rings;
}

}  // namespace

std::optional<std::vector<Polygon>> dissolveCoverage(const std::vector<const Polygon*>& polygons,
                                                     const DissolveOptions& options) {
  std::vector<Edge> edges;
  for (const Polygon* p : polygons) {
    addRing(p->outer, edges);
    for (const Ring& h : p->holes) addRing(h, edges);
  }
  if (options.snap > 0) edges = splitAtVertices(edges, options.snap);
  auto left = cancelShared(edges);
  if (!left) return std::nullopt;
  auto rings = chainRings(std::move(*left));
  if (!rings) return std::nullopt;

  std::vector<Polygon> parts;
  std::vector<double> shellAreas;
  std::vector<Ring> holes;
  for (Ring& ring : *rings) {
    const double a = signedArea(ring);
    if (a == 0.0) return std::nullopt;
    if (a > 0) {
      parts.push_back({std::move(ring), {}});
      shellAreas.push_back(a);
    } else {
      holes.push_back(std::move(ring));
    }
  }
  for (Ring& hole : holes) {
    std::size_t best = parts.size();
    if (parts.size() == 1) {
      best = 0;
    } else {
      // The smallest outer ring holding the hole's first vertex. A vertex on a
      // ring may go either way; a wrong choice leaves the hole outside its
      // shell, which the validity check the caller makes rejects.
      for (std::size_t s = 0; s < parts.size(); ++s) {
        if (pointInRing(hole.front(), parts[s].outer) && (best == parts.size() || shellAreas[s] < shellAreas[best])) {
          best = s;
        }
      }
    }
    if (best == parts.size()) return std::nullopt;
    parts[best].holes.push_back(std::move(hole));
  }
  return parts;
}

}  // namespace parcelscope
