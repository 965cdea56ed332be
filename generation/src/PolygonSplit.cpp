#include "PolygonSplit.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <optional>

#include "Exact.h"
#include "parcelscope/core/GeosOps.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace parcelscope::generation::detail {

P2 toExact(const Ring& ring) {
  P2 p;
  for (const Point& v : ring) p.push_back(K::Point_2(v.x, v.y));
  return p;
}

PWH toExact(const Polygon& polygon) {
  P2 outer = toExact(polygon.outer);
  if (outer.orientation() != CGAL::COUNTERCLOCKWISE) outer.reverse_orientation();
  std::vector<P2> holes;
  for (const Ring& h : polygon.holes) {
    P2 hole = toExact(h);
    if (hole.orientation() != CGAL::CLOCKWISE) hole.reverse_orientation();
    holes.push_back(std::move(hole));
  }
  return PWH(outer, holes.begin(), holes.end());
}

namespace {
Ring ringToDouble(const P2& p) {
  Ring r;
  r.reserve(p.size());
  for (auto v = p.vertices_begin(); v != p.vertices_end(); ++v) {
    r.push_back({CGAL::to_double(v->x()), CGAL::to_double(v->y())});
  }
  return r;
}
}  // namespace

bool toDouble(const PWH& exact, Polygon& out) {
  out.outer = ringToDouble(exact.outer_boundary());
  out.holes.clear();
  for (auto h = exact.holes_begin(); h != exact.holes_end(); ++h) out.holes.push_back(ringToDouble(*h));
  return normalise(out);
}

P2 leftHalfPlane(const K::Point_2& through, const K::Vector_2& dir, double reach) {
  const double dx = CGAL::to_double(dir.x()), dy = CGAL::to_double(dir.y());
  const double len = norm(dx, dy);
  const K::Vector_2 u(dx / len * reach, dy / len * reach);
  const K::Vector_2 n(-u.y(), u.x());
  // The edge on the line runs along the exact direction, so both half-planes of
  // one line share it exactly.
  const K::FT s = reach / len;
  const K::Vector_2 along = dir * s;
  P2 q;
  q.push_back(through - along);
  q.push_back(through + along);
  q.push_back(through + along + n);
  q.push_back(through - along + n);
  return q;
}

Region intersect(const PWH& a, const P2& b) {
  Region out;
  Traits traits;
  CGAL::intersection(a, b, std::back_inserter(out), traits);
  return out;
}

Region subtract(const Region& a, const PWH& b) {
  Region out;
  Traits traits;
  const auto bb = b.outer_boundary().bbox();
  for (const PWH& p : a) {
    if (!CGAL::do_overlap(p.outer_boundary().bbox(), bb)) {
      out.push_back(p);
      continue;
    }
    CGAL::difference(p, b, std::back_inserter(out), traits);
  }
  return out;
}

Region clipLeft(const PWH& p, const K::Point_2& through, const K::Vector_2& dir, double reach) {
  const P2& ring = p.outer_boundary();
  const std::size_t n = ring.size();
  if (p.has_holes() || n < 3) return intersect(p, leftHalfPlane(through, dir, reach));
  const K::Point_2 ahead = through + dir;
  std::vector<CGAL::Orientation> side(n);
  std::size_t left = 0, right = 0;
  for (std::size_t i = 0; i < n; ++i) {
    side[i] = CGAL::orientation(through, ahead, ring[i]);
    if (side[i] == CGAL::COLLINEAR) return intersect(p, leftHalfPlane(through, dir, reach));
    (side[i] == CGAL::LEFT_TURN ? left : right) += 1;
  }
  if (right == 0) return {p};
  if (left == 0) return {};
  std::size_t changes = 0;
  for (std::size_t i = 0; i < n; ++i) changes += side[i] != side[(i + 1) % n];
  if (changes != 2) return intersect(p, leftHalfPlane(through, dir, reach));
  P2 out;
  for (std::size_t i = 0; i < n; ++i) {
    const K::Point_2& a = ring[i];
    const K::Point_2& b = ring[(i + 1) % n];
    if (side[i] == CGAL::LEFT_TURN) out.push_back(a);
    if (side[i] != side[(i + 1) % n]) {
      // The crossing, computed from the segment in x-then-y order on both
      // sides of the line so that the two pieces share it exactly; one lazy
      // construction rather than a chain of lazy arithmetic, so that its exact
      // value, when a predicate needs it, comes from one evaluation (about a
      // fifth less time for the skeleton style, whose T-junction tests need
      // the exact values of these points).
      const bool forward = CGAL::compare_xy(a, b) == CGAL::SMALLER;
      const K::Point_2& s = forward ? a : b;
      const K::Point_2& e = forward ? b : a;
      const auto x = CGAL::intersection(K::Segment_2(s, e), K::Line_2(through, dir));
      const K::Point_2* q = x ? boost::get<K::Point_2>(&*x) : nullptr;
      if (!q) return intersect(p, leftHalfPlane(through, dir, reach));
      out.push_back(*q);
    }
  }
  return {PWH(out)};
}

Region clipLeft(const Region& r, const K::Point_2& through, const K::Vector_2& dir, double reach) {
  Region out;
  for (const PWH& p : r) {
    Region part = clipLeft(p, through, dir, reach);
    out.insert(out.end(), part.begin(), part.end());
  }
  return out;
}

namespace {
struct PointLess {
  bool operator()(const K::Point_2& a, const K::Point_2& b) const { return CGAL::compare_xy(a, b) == CGAL::SMALLER; }
};
struct EdgeLess {
  bool operator()(const std::pair<K::Point_2, K::Point_2>& a, const std::pair<K::Point_2, K::Point_2>& b) const {
    const auto c = CGAL::compare_xy(a.first, b.first);
    if (c != CGAL::EQUAL) return c == CGAL::SMALLER;
    return CGAL::compare_xy(a.second, b.second) == CGAL::SMALLER;
  }
};

// Union of interior-disjoint polygons without holes that form one polygon
// without holes: edges split at every vertex lying inside them, coinciding
// opposite edges cancelled, the rest linked into a ring. False when the parts
// do not form exactly one such ring.
bool dissolve(const Region& parts, PWH& out) {
  std::vector<K::Point_2> points;
  std::vector<CGAL::Bbox_2> boxes;
  for (const PWH& p : parts) {
    if (p.has_holes()) return false;
    for (auto v = p.outer_boundary().vertices_begin(); v != p.outer_boundary().vertices_end(); ++v) {
      points.push_back(*v);
      boxes.push_back(v->bbox());
    }
  }
  std::map<std::pair<K::Point_2, K::Point_2>, int, EdgeLess> edges;
  auto addEdge = [&](const K::Point_2& a, const K::Point_2& b) {
    auto opposite = edges.find({b, a});
    if (opposite != edges.end()) {
      edges.erase(opposite);
      return true;
    }
    return edges.emplace(std::make_pair(a, b), 0).second;  // a repeated edge: the parts overlap
  };
  for (const PWH& p : parts) {
    const P2& ring = p.outer_boundary();
    for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
      const K::Point_2& a = ring[i];
      const K::Point_2& b = ring[(i + 1) % n];
      const CGAL::Bbox_2 box = a.bbox() + b.bbox();
      std::vector<K::Point_2> inside;
      for (std::size_t k = 0; k < points.size(); ++k) {
        if (!CGAL::do_overlap(box, boxes[k])) continue;
        if (CGAL::collinear(a, b, points[k]) && CGAL::collinear_are_strictly_ordered_along_line(a, points[k], b)) {
          inside.push_back(points[k]);
        }
      }
      std::sort(inside.begin(), inside.end(), [&](const K::Point_2& x, const K::Point_2& y) {
        return CGAL::compare_distance_to_point(a, x, y) == CGAL::SMALLER;
      });
      inside.erase(std::unique(inside.begin(), inside.end()), inside.end());
      K::Point_2 from = a;
      for (const K::Point_2& x : inside) {
        if (!addEdge(from, x)) return false;
        from = x;
      }
      if (!addEdge(from, b)) return false;
    }
  }
  if (edges.empty()) return false;
  std::map<K::Point_2, K::Point_2, PointLess> next;
  for (const auto& [e, unused] : edges) {
    if (!next.emplace(e.first, e.second).second) return false;  // two ways on: a pinch
  }
  P2 ring;
  K::Point_2 at = next.begin()->first;
  for (std::size_t steps = 0; steps <= next.size(); ++steps) {
    ring.push_back(at);
    auto it = next.find(at);
    if (it == next.end()) return false;
    at = it->second;
    if (at == ring[0]) break;
  }
  if (ring.size() != next.size()) return false;  // more than one ring: holes or separate pieces
  out = PWH(ring);
  return true;
}
}  // namespace

Region join(const Region& parts) {
  Region out;
  if (parts.size() == 1) return parts;
  if (parts.empty()) return out;
  PWH dissolved;
  if (dissolve(parts, dissolved)) return {dissolved};
  Traits traits;
  CGAL::join(parts.begin(), parts.end(), std::back_inserter(out), traits);
  return out;
}

bool isValidExact(const PWH& p) {
  Traits traits;
  return CGAL::is_valid_polygon_with_holes(p, traits);
}

bool isStrictlySimple(const Ring& ring) {
  if (isClearlySimple(ring)) return true;  // proven in floating point, with a margin
  CGAL::Polygon_2<CGAL::Exact_predicates_inexact_constructions_kernel> p;
  for (const Point& v : ring) p.push_back({v.x, v.y});
  return p.size() >= 3 && p.is_simple();
}

namespace {
// Whether no two rings of the polygon share a point (exact predicates on the
// doubles): edges in the order of their boxes' least x, each tested against
// the edges of other rings whose boxes meet its own. Null when that takes
// more than `budget` box tests (many long edges side by side).
std::optional<bool> ringsApart(const Polygon& polygon, std::uint64_t budget) {
  struct Edge {
    double minX, maxX, minY, maxY;
    std::size_t ring;
    Point a, b;
  };
  std::vector<Edge> edges;
  for (std::size_t k = 0; k <= polygon.holes.size(); ++k) {
    const Ring& r = k == 0 ? polygon.outer : polygon.holes[k - 1];
    for (std::size_t i = 0, n = r.size(); i < n; ++i) {
      const Point& a = r[i];
      const Point& b = r[(i + 1) % n];
      edges.push_back({std::min(a.x, b.x), std::max(a.x, b.x), std::min(a.y, b.y), std::max(a.y, b.y), k, a, b});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& e, const Edge& f) { return e.minX < f.minX; });
  using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::uint64_t tests = 0;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const Edge& e = edges[i];
    for (std::size_t j = i + 1; j < edges.size() && edges[j].minX <= e.maxX; ++j) {
      if (++tests > budget) return std::nullopt;
      const Edge& f = edges[j];
      if (f.ring == e.ring || f.minY > e.maxY || f.maxY < e.minY) continue;
      if (CGAL::do_intersect(Epick::Segment_2({e.a.x, e.a.y}, {e.b.x, e.b.y}),
                             Epick::Segment_2({f.a.x, f.a.y}, {f.b.x, f.b.y}))) {
        return false;
      }
    }
  }
  return true;
}
}  // namespace

bool isValidForSplit(const Polygon& polygon) {
  if (polygon.outer.size() < 3) return false;
  // A strictly simple ring is valid (toExact orients it). This test is far
  // cheaper than the Boolean-operations validation, which still judges
  // everything else (touching rings, holes).
  if (polygon.holes.empty() && isStrictlySimple(polygon.outer)) return true;
  // With holes: GEOS's validity (simple rings, holes inside the outer ring,
  // none inside another, no crossing) of rings that share no point is CGAL's
  // too, and far cheaper on many holes (CGAL's validation took half a minute
  // on a block of 1,600 holes). Rings that touch, or too many edges side by
  // side to tell, go to CGAL.
  if (!polygon.holes.empty() && geos::isValid(polygon) && ringsApart(polygon, 50000000).value_or(false)) {
    return true;
  }
  return isValidExact(toExact(polygon));
}

SplitPieces splitByLine(const Polygon& polygon, const Point& pivot, const Point& dir) {
  const Box b = bounds(polygon);
  const double reach = 4.0 * (b.width() + b.height()) + 1.0 + std::fabs(pivot.x - b.minX) + std::fabs(pivot.y - b.minY);
  const K::Point_2 through(pivot.x, pivot.y);
  const K::Vector_2 d(dir.x, dir.y);
  const PWH p = toExact(polygon);
  SplitPieces out;
  for (const auto& [side, target] : {std::pair{d, &out.left}, std::pair{-d, &out.right}}) {
    for (const PWH& part : intersect(p, leftHalfPlane(through, side, reach))) {
      Polygon q;
      if (toDouble(part, q)) target->push_back(std::move(q));
    }
  }
  return out;
}

}  // namespace parcelscope::generation::detail

namespace parcelscope::generation::detail {

namespace {
// Side of q relative to the directed line through `pivot` along `dir`: 1 left,
// -1 right, 0 on it; exact. The floating-point value decides when its sign is
// certain: each of the two products carries one rounded difference, and 1e-15
// of their magnitudes bounds the rounding error of the whole expression with a
// wide margin (3.4e-16 would do). Otherwise the exact kernel decides.
int sideOf(const Point& q, const Point& pivot, const Point& dir) {
  if (q.x == pivot.x && q.y == pivot.y) return 0;
  const double a = dir.x * (q.y - pivot.y), b = dir.y * (q.x - pivot.x);
  const double det = a - b;
  if (std::fabs(det) > 1e-15 * (std::fabs(a) + std::fabs(b))) return det > 0 ? 1 : -1;
  const K::Point_2 through(pivot.x, pivot.y);
  const CGAL::Orientation o = CGAL::orientation(through, through + K::Vector_2(dir.x, dir.y), K::Point_2(q.x, q.y));
  return o == CGAL::LEFT_TURN ? 1 : o == CGAL::RIGHT_TURN ? -1 : 0;
}
}  // namespace

namespace {
// splitByLineFast for a polygon without holes.
bool splitRingFast(const Polygon& polygon, const Point& pivot, const Point& dir, SplitPieces& out) {
  const Ring& r = polygon.outer;
  const std::size_t n = r.size();
  if (n < 3) return false;
  // Scratch kept across calls on this thread (no allocation once grown).
  thread_local std::vector<signed char> side, onLine;
  thread_local std::vector<char> touch;
  side.resize(n);
  for (std::size_t i = 0; i < n; ++i) side[i] = static_cast<signed char>(sideOf(r[i], pivot, dir));
  // A vertex on the line whose neighbours are both on one side (the line
  // touches the ring there, as a split snapped to a contour vertex often does)
  // belongs to that side's piece. On a cut it pinches that side's piece in
  // two there (checked below).
  onLine = side;
  touch.assign(n, 0);
  std::size_t left = 0, right = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const int before = onLine[(i + n - 1) % n], after = onLine[(i + 1) % n];
    if (onLine[i] == 0 && before * after > 0) {
      side[i] = static_cast<signed char>(before);
      touch[i] = 1;
    }
    left += side[i] > 0;
    right += side[i] < 0;
  }
  if (left == 0 || right == 0) {
    // Nothing on one side. (A ring touching the line along an edge is left to
    // the exact split, which knows what to do with it.)
    if (left + right + 1 < n) return false;
    SplitPieces whole;
    (left ? whole.left : whole.right).push_back(polygon);
    out = std::move(whole);
    return true;
  }
  // The ring with its crossings: vertices, and points inserted on edges whose
  // ends lie on opposite sides. Every vertex on the line must be a crossing
  // too (between opposite sides) or a touch; an edge along the line is left to
  // the exact split.
  struct Node {
    Point p;
    int side = 0;  // of the vertex; 0 on the line
    bool touch = false;
    double along = 0;          // on the line (crossings and touches): position along it
    int exit = -1;             // crossings: the other end of its cut; touches on a cut: the next stop along it
    std::vector<int> through;  // the touches from the other side passed on the way to `exit`
  };
  thread_local std::vector<Node> nodes;
  nodes.clear();
  nodes.reserve(n + 8);
  for (std::size_t i = 0; i < n; ++i) {
    const int s = side[i], next = side[(i + 1) % n];
    if (s == 0 && side[(i + n - 1) % n] * next >= 0) return false;
    Node vertex;
    vertex.p = r[i];
    vertex.side = s;
    vertex.touch = touch[i] != 0;
    nodes.push_back(std::move(vertex));
    if (s * next >= 0) continue;
    // The crossing, from the segment taken in x-then-y order, clamped to it.
    const Point& a = r[i];
    const Point& b = r[(i + 1) % n];
    const bool forward = a.x < b.x || (a.x == b.x && a.y < b.y);
    const Point& from = forward ? a : b;
    const Point& to = forward ? b : a;
    const double dx = to.x - from.x, dy = to.y - from.y;
    const double t =
        std::clamp(((pivot.x - from.x) * dir.y - (pivot.y - from.y) * dir.x) / (dx * dir.y - dy * dir.x), 0.0, 1.0);
    Node crossing;
    crossing.p = t == 1.0 ? to : Point{from.x + dx * t, from.y + dy * t};
    crossing.side = 0;
    nodes.push_back(std::move(crossing));
  }
  const std::size_t m = nodes.size();
  auto sideBefore = [&](std::size_t k) { return nodes[(k + m - 1) % m].side; };
  auto sideAfter = [&](std::size_t k) { return nodes[(k + 1) % m].side; };
  // Cuts: the crossings in order along the line, paired first with second,
  // third with fourth, and so on; each pair must join a crossing where the ring
  // leaves the left side to one where it comes back. Points on the line too
  // close along it to be ordered with certainty are left to the exact split.
  SplitPieces result;
  thread_local std::vector<std::size_t> crossings, touches;
  crossings.clear();
  touches.clear();
  for (std::size_t k = 0; k < m; ++k) {
    if (nodes[k].side != 0 && !nodes[k].touch) continue;
    nodes[k].along = (nodes[k].p.x - pivot.x) * dir.x + (nodes[k].p.y - pivot.y) * dir.y;
    (nodes[k].touch ? touches : crossings).push_back(k);
  }
  if (crossings.size() % 2 != 0) return false;
  const auto byAlong = [&](std::size_t x, std::size_t y) { return nodes[x].along < nodes[y].along; };
  std::sort(crossings.begin(), crossings.end(), byAlong);
  std::sort(touches.begin(), touches.end(), byAlong);
  const Box b = bounds(r);
  const double separation = 1e-9 * (b.width() + b.height());
  for (std::size_t c = 0; c + 1 < crossings.size(); ++c) {
    if (!(nodes[crossings[c + 1]].along - nodes[crossings[c]].along > separation)) return false;
  }
  for (std::size_t c = 0; c < crossings.size(); c += 2) {
    const std::size_t x = crossings[c], y = crossings[c + 1];
    if (sideBefore(x) == sideBefore(y)) return false;
    // The stops along the cut: its ends and the touches on it, which pinch
    // their side's piece (one piece ends there, the next begins). A touch
    // too near an end or another stop to order is left to the exact split.
    thread_local std::vector<std::size_t> stops;
    stops.assign(1, x);
    for (const std::size_t t : touches) {
      const double at = nodes[t].along;
      if (!(at > nodes[x].along - separation && at < nodes[y].along + separation)) continue;
      if (!(at - nodes[stops.back()].along > separation && nodes[y].along - at > separation)) return false;
      stops.push_back(t);
      result.pinched = true;
    }
    stops.push_back(y);
    // Each side's pieces run along the cut in one direction: away from the
    // crossing where the ring leaves that side. From there, and from each of
    // its touches (reached along the ring), to the next of its own stops.
    for (const int s : {1, -1}) {
      const bool forward = sideBefore(x) == s;
      const auto at = [&](std::size_t i) { return stops[forward ? i : stops.size() - 1 - i]; };
      for (std::size_t i = 0; i + 1 < stops.size(); ++i) {
        const std::size_t from = at(i);
        if (i > 0 && nodes[from].side != s) continue;
        Node& start = nodes[from];
        start.through.clear();
        std::size_t j = i + 1;
        for (; j + 1 < stops.size() && nodes[at(j)].side != s; ++j) start.through.push_back(static_cast<int>(at(j)));
        start.exit = static_cast<int>(at(j));
      }
    }
  }
  // Each piece: along the ring on its side; where the ring leaves that side
  // (at a crossing, or at a touch on a cut), along the cut to its next stop,
  // and on along the ring from there.
  thread_local std::vector<char> visited;
  thread_local std::vector<int> inPiece;  // touches: the last piece that passed them
  visited.assign(m, 0);
  inPiece.assign(m, -1);
  int pieces = 0;
  // Each walk collects its ring in a buffer kept across pieces and calls, then
  // copies it out once at its size.
  thread_local Ring walked;
  for (const int s : {1, -1}) {
    for (std::size_t start = 0; start < m; ++start) {
      if (nodes[start].side != s || visited[start] || nodes[start].touch) continue;
      walked.clear();
      const int id = pieces++;
      // A piece that passes one of its touches twice is pinched onto itself
      // (the exact split makes a hole of it, or a ring touching itself).
      const auto pass = [&](std::size_t k) {
        walked.push_back(nodes[k].p);
        visited[k] = 1;
        if (!nodes[k].touch) return true;
        if (inPiece[k] == id) return false;
        inPiece[k] = id;
        return true;
      };
      std::size_t k = start;
      for (std::size_t steps = 0;; ++steps) {
        if (steps > 2 * m) return false;  // not a closed walk: leave it to the exact split
        if (!pass(k)) return false;
        const bool leaves = nodes[k].side == 0 ? sideAfter(k) == -s : nodes[k].touch && nodes[k].exit >= 0;
        if (leaves) {
          for (const int t : nodes[k].through) walked.push_back(nodes[static_cast<std::size_t>(t)].p);
          k = static_cast<std::size_t>(nodes[k].exit);
          if (!pass(k)) return false;
        }
        k = (k + 1) % m;
        if (k == start) break;
      }
      // Start at the lowest vertex in x-then-y order.
      Polygon piece;
      const auto lowest = std::min_element(walked.begin(), walked.end(), [](const Point& p, const Point& q) {
        return p.x < q.x || (p.x == q.x && p.y < q.y);
      });
      piece.outer.reserve(walked.size());
      piece.outer.insert(piece.outer.end(), lowest, walked.end());
      piece.outer.insert(piece.outer.end(), walked.begin(), lowest);
      if (normalise(piece)) (s > 0 ? result.left : result.right).push_back(std::move(piece));
    }
  }
  out = std::move(result);
  return true;
}

// Holes the line misses (every vertex certainly on one side, the same for the
// whole hole; a hole's edges then stay on that side too): the line cuts the
// outer ring alone, and each hole goes into the piece of its side that holds
// it. That piece is the side's only one, or the one whose outer ring holds a
// vertex of the hole clear of every piece's boundary.
bool splitHoledFast(const Polygon& polygon, const Point& pivot, const Point& dir, SplitPieces& out) {
  std::vector<int> sides;
  sides.reserve(polygon.holes.size());
  for (const Ring& h : polygon.holes) {
    int s = 0;
    for (const Point& q : h) {
      const int t = sideOf(q, pivot, dir);
      if (t == 0 || (s != 0 && t != s)) return false;
      s = t;
    }
    if (s == 0) return false;
    sides.push_back(s);
  }
  SplitPieces pieces;
  if (!splitRingFast(Polygon{polygon.outer, {}}, pivot, dir, pieces)) return false;
  const Box b = bounds(polygon.outer);
  const double clearance = 1e-9 * (b.width() + b.height());
  const auto nearBoundary = [&](const Point& q, const Ring& ring) {
    for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
      if (pointSegmentDistance(q, ring[i], ring[(i + 1) % n]) <= clearance) return true;
    }
    return false;
  };
  for (std::size_t k = 0; k < polygon.holes.size(); ++k) {
    std::vector<Polygon>& side = sides[k] > 0 ? pieces.left : pieces.right;
    std::size_t holder = side.size();
    if (side.size() == 1) {
      holder = 0;
    } else {
      for (const Point& q : polygon.holes[k]) {
        if (std::any_of(side.begin(), side.end(), [&](const Polygon& p) { return nearBoundary(q, p.outer); })) continue;
        std::size_t found = 0;
        for (std::size_t j = 0; j < side.size(); ++j) {
          if (pointInRing(q, side[j].outer)) {
            holder = j;
            ++found;
          }
        }
        if (found != 1) return false;
        break;
      }
    }
    if (holder >= side.size()) return false;
    side[holder].holes.push_back(polygon.holes[k]);
  }
  for (auto* side : {&pieces.left, &pieces.right}) {
    for (Polygon& p : *side) {
      if (!p.holes.empty() && !normalise(p)) return false;
    }
  }
  out = std::move(pieces);
  return true;
}
}  // namespace

bool splitByLineFast(const Polygon& polygon, const Point& pivot, const Point& dir, SplitPieces& out) {
  return polygon.holes.empty() ? splitRingFast(polygon, pivot, dir, out) : splitHoledFast(polygon, pivot, dir, out);
}

// Off the line (by more than `onLine`) lie only vertices of the polygon: the
// fast split computes its crossings on the line, rounded by some 1e-16 of the
// coordinates. An edge of the piece with both ends off the line therefore
// joins two vertices that follow each other in the polygon's ring: it is an
// edge of the polygon, and two such edges meet only where they did there, at
// a shared vertex. Every other edge (along a cut, or a polygon edge shortened
// to a crossing, whose rounding may move it) must be longer than the margin,
// must not fold back onto its neighbours, and must keep farther than the
// margin from every edge but its neighbours. The margin, 1e-12 of the
// coordinates' magnitude, is far above the rounding of the distances computed;
// `onLine` far above that of the crossings.
bool splitPieceIsSimple(const Ring& r, const Box& b, const Point& pivot, const Point& dir, bool cutsClear) {
  const std::size_t n = r.size();
  if (n < 3) return false;
  const double size = b.width() + b.height();
  const double onLine = 1e-9 * size + 1e-12;
  const double magnitude =
      std::max(std::max(std::fabs(b.minX), std::fabs(b.maxX)), std::max(std::fabs(b.minY), std::fabs(b.maxY)));
  const double margin = 1e-12 * (size + magnitude);
  if (!(margin > 0) || !std::isfinite(margin)) return false;
  const bool skipCuts = cutsClear && 1e-6 * size > margin;  // the caller's clearance covers the margin
  thread_local std::vector<char> on;
  on.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    on[i] = std::fabs((r[i].x - pivot.x) * dir.y - (r[i].y - pivot.y) * dir.x) <= onLine;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    if (!on[i] && !on[j]) continue;
    if (skipCuts && on[i] && on[j]) continue;
    const Point& p = r[i];
    const Point& q = r[j];
    if (!(norm(q.x - p.x, q.y - p.y) > margin)) return false;
    if (foldsBack(r[(i + n - 1) % n], p, q) || foldsBack(p, q, r[(i + 2) % n])) return false;
    const Box near =
        Box{std::min(p.x, q.x), std::min(p.y, q.y), std::max(p.x, q.x), std::max(p.y, q.y)}.expanded(margin);
    for (std::size_t k = 0; k < n; ++k) {
      if (k == i || k == j || (k + 1) % n == i) continue;  // itself, its neighbours
      const Point& c = r[k];
      const Point& d = r[(k + 1) % n];
      if (std::max(c.x, d.x) < near.minX || std::min(c.x, d.x) > near.maxX || std::max(c.y, d.y) < near.minY ||
          std::min(c.y, d.y) > near.maxY) {
        continue;
      }
      if (!(segmentDistance(p, q, c, d) > margin)) return false;
    }
  }
  return true;
}

namespace {
bool pointLess(const Point& a, const Point& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }
bool samePoint(const Point& a, const Point& b) { return a.x == b.x && a.y == b.y; }
struct DirectedEdge {
  Point from, to;
};
// An edge by its ends in pointLess order, and its direction.
struct KeyedEdge {
  Point lo, hi;
  bool forward;  // from lo to hi
};
void addEdge(std::vector<KeyedEdge>& edges, const Point& from, const Point& to) {
  if (pointLess(from, to)) {
    edges.push_back({from, to, true});
  } else {
    edges.push_back({to, from, false});
  }
}
}  // namespace

bool joinRingsFast(const std::vector<const Ring*>& parts, double tolerance, std::vector<Ring>& out) {
  if (!(tolerance >= 0) || !std::isfinite(tolerance)) return false;
  // Every vertex, by x, to find those lying on an edge.
  thread_local std::vector<Point> points;
  thread_local std::vector<KeyedEdge> edges;
  thread_local std::vector<DirectedEdge> kept;
  thread_local std::vector<char> used;
  thread_local std::vector<std::pair<double, Point>> inside;
  points.clear();
  edges.clear();
  double partsArea = 0;
  for (const Ring* r : parts) {
    if (r->size() < 3) return false;
    const double a = signedArea(*r);
    if (!(a > 0)) return false;
    partsArea += a;
    points.insert(points.end(), r->begin(), r->end());
  }
  std::sort(points.begin(), points.end(), pointLess);
  points.erase(std::unique(points.begin(), points.end(), samePoint), points.end());
  for (const Ring* ring : parts) {
    const Ring& r = *ring;
    for (std::size_t i = 0, n = r.size(); i < n; ++i) {
      const Point& a = r[i];
      const Point& b = r[(i + 1) % n];
      const double dx = b.x - a.x, dy = b.y - a.y, length = norm(dx, dy);
      if (!(length > 0)) return false;
      const double minX = std::min(a.x, b.x) - tolerance, maxX = std::max(a.x, b.x) + tolerance;
      const double minY = std::min(a.y, b.y) - tolerance, maxY = std::max(a.y, b.y) + tolerance;
      inside.clear();
      auto q = std::lower_bound(points.begin(), points.end(), minX, [](const Point& p, double x) { return p.x < x; });
      for (; q != points.end() && q->x <= maxX; ++q) {
        if (q->y < minY || q->y > maxY || samePoint(*q, a) || samePoint(*q, b)) continue;
        const double along = ((q->x - a.x) * dx + (q->y - a.y) * dy) / length;
        const double off = std::fabs((q->y - a.y) * dx - (q->x - a.x) * dy) / length;
        if (off <= tolerance && along > tolerance && along < length - tolerance) inside.push_back({along, *q});
      }
      std::sort(inside.begin(), inside.end(), [](const auto& x, const auto& y) {
        return x.first < y.first || (x.first == y.first && pointLess(x.second, y.second));
      });
      Point from = a;
      for (const auto& [along, p] : inside) {
        if (samePoint(p, from)) continue;
        addEdge(edges, from, p);
        from = p;
      }
      addEdge(edges, from, b);
    }
  }
  // Coinciding edges: in opposite directions they cancel; in the same
  // direction, or more than two, the parts overlap.
  std::sort(edges.begin(), edges.end(), [](const KeyedEdge& x, const KeyedEdge& y) {
    if (!samePoint(x.lo, y.lo)) return pointLess(x.lo, y.lo);
    return pointLess(x.hi, y.hi);
  });
  kept.clear();
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    const KeyedEdge& ki = edges[i];
    while (j < edges.size() && samePoint(edges[j].lo, ki.lo) && samePoint(edges[j].hi, ki.hi)) ++j;
    if (j - i == 1) {
      kept.push_back(ki.forward ? DirectedEdge{ki.lo, ki.hi} : DirectedEdge{ki.hi, ki.lo});
    } else if (j - i != 2 || edges[i].forward == edges[i + 1].forward) {
      return false;
    }
    i = j;
  }
  if (kept.empty()) return false;
  std::sort(kept.begin(), kept.end(),
            [](const DirectedEdge& x, const DirectedEdge& y) { return pointLess(x.from, y.from); });
  for (std::size_t i = 1; i < kept.size(); ++i) {
    if (samePoint(kept[i - 1].from, kept[i].from)) return false;  // two ways on: a pinch
  }
  used.assign(kept.size(), 0);
  std::vector<Ring> rings;
  double ringsArea = 0;
  for (std::size_t first = 0; first < kept.size(); ++first) {
    if (used[first]) continue;
    Ring ring;
    std::size_t at = first;
    do {
      if (used[at]) return false;  // a vertex reached twice: rings touching
      used[at] = 1;
      ring.push_back(kept[at].from);
      const Point& to = kept[at].to;
      const auto it = std::lower_bound(kept.begin(), kept.end(), to,
                                       [](const DirectedEdge& e, const Point& p) { return pointLess(e.from, p); });
      if (it == kept.end() || !samePoint(it->from, to)) return false;
      at = static_cast<std::size_t>(it - kept.begin());
    } while (at != first);
    const double a = signedArea(ring);
    if (!(a > 0)) return false;  // a hole
    ringsArea += a;
    rings.push_back(std::move(ring));
  }
  if (!(std::fabs(ringsArea - partsArea) <= 1e-9 * partsArea)) return false;
  out = std::move(rings);
  return true;
}

}  // namespace parcelscope::generation::detail
