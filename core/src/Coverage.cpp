#include "parcelscope/core/Coverage.h"

#include <algorithm>
#include <cmath>
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
    auto it =
        std::lower_bound(vertices.begin(), vertices.end(), minX, [](const Point& p, double x) { return p.x < x; });
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

// Cuts a ring at every vertex it passes twice into rings that pass it once:
// the loop between the two visits becomes a ring of its own.
void splitAtRepeats(const Ring& ring, const std::vector<char>& pinch, std::vector<Ring>& out) {
  Ring stack;
  std::vector<char> stackPinch;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    if (pinch[i]) {
      for (std::size_t k = stack.size(); k-- > 0;) {
        if (stackPinch[k] && same(stack[k], ring[i])) {
          out.emplace_back(stack.begin() + static_cast<std::ptrdiff_t>(k), stack.end());
          stack.resize(k);
          stackPinch.resize(k);
          break;
        }
      }
    }
    stack.push_back(ring[i]);
    stackPinch.push_back(pinch[i]);
  }
  out.push_back(std::move(stack));
}

// Chains edges into closed rings. Where several edges start at one vertex
// (parts or holes touching at a point), an edge arriving there continues with
// the first edge met turning clockwise from the way it came, and a ring that
// passes such a vertex twice is cut there: rings touch at the vertex, as a
// valid polygon's rings may, instead of running through it. Nothing when two
// edges would continue with the same edge.
std::optional<std::vector<Ring>> chainRings(std::vector<Edge> edges) {
  std::sort(edges.begin(), edges.end(),
            [](const Edge& p, const Edge& q) { return before(p.a, q.a) || (same(p.a, q.a) && before(p.b, q.b)); });
  const std::size_t n = edges.size();
  std::vector<std::size_t> next(n);
  std::vector<char> taken(n, 0), pinch(n, 0);
  for (std::size_t e = 0; e < n; ++e) {
    const Point& v = edges[e].b;
    auto first =
        std::lower_bound(edges.begin(), edges.end(), v, [](const Edge& x, const Point& p) { return before(x.a, p); });
    if (first == edges.end() || !same(first->a, v)) return std::nullopt;
    auto last = first + 1;
    while (last != edges.end() && same(last->a, v)) ++last;
    auto chosen = first;
    if (last - first > 1) {
      const double back = std::atan2(edges[e].a.y - v.y, edges[e].a.x - v.x);
      double best = 10.0;
      for (auto it = first; it != last; ++it) {
        double turn = back - std::atan2(it->b.y - v.y, it->b.x - v.x);  // clockwise from the way back
        while (turn <= 0) turn += 2 * kPi;
        while (turn > 2 * kPi) turn -= 2 * kPi;
        if (turn < best) {
          best = turn;
          chosen = it;
        }
      }
      for (auto it = first; it != last; ++it) pinch[static_cast<std::size_t>(it - edges.begin())] = 1;
    }
    next[e] = static_cast<std::size_t>(chosen - edges.begin());
    if (taken[next[e]]++) return std::nullopt;
  }
  std::vector<char> used(n, 0);
  std::vector<Ring> rings;
  for (std::size_t first = 0; first < n; ++first) {
    if (used[first]) continue;
    Ring ring;
    std::vector<char> ringPinch;
    bool pinched = false;
    for (std::size_t e = first; !used[e]; e = next[e]) {
      used[e] = 1;
      ring.push_back(edges[e].a);
      ringPinch.push_back(pinch[e]);
      pinched = pinched || pinch[e];
    }
    if (pinched) {
      splitAtRepeats(ring, ringPinch, rings);
    } else {
      rings.push_back(std::move(ring));
    }
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

  // Every ring from its lowest vertex, and rings in order of it: the result
  // does not depend on the order of the polygons.
  for (Ring& ring : *rings) {
    std::rotate(ring.begin(), std::min_element(ring.begin(), ring.end(), before), ring.end());
  }
  std::sort(rings->begin(), rings->end(), [](const Ring& p, const Ring& q) { return before(p.front(), q.front()); });
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
      // The smallest outer ring holding the middle of the hole's first edge
      // (a hole's vertex may touch a ring; its edges do not run along one). A
      // wrong choice leaves the hole outside its shell, which the validity
      // check the caller makes rejects.
      const Point probe{0.5 * (hole[0].x + hole[1].x), 0.5 * (hole[0].y + hole[1].y)};
      for (std::size_t s = 0; s < parts.size(); ++s) {
        if (pointInRing(probe, parts[s].outer) && (best == parts.size() || shellAreas[s] < shellAreas[best])) {
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
