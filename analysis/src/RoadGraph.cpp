#include "parcelscope/analysis/RoadGraph.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <utility>

#include "parcelscope/core/BoxIndex.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace parcelscope::analysis {

namespace {

namespace bgi = boost::geometry::index;
using BBox = IndexBox;
// Segments of polylines, each as (line, index of its first vertex).
using SegmentEntry = std::pair<BBox, std::pair<int, int>>;
using SegmentTree = BoxTree<std::pair<int, int>>;
using BoxEntry = std::pair<BBox, int>;

// Lines are noded on this grid (m): crossings closer than it are one node.
constexpr double kGrid = 1e-3;
// Overlays of blocks and street surfaces are snap-rounded on this grid (m).
constexpr double kOverlayGrid = 1e-6;

BBox boxAround(const Point& a, const Point& b, double pad = 0) {
  return indexBox({std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.x, b.x), std::max(a.y, b.y)}, pad);
}

BBox boxOf(const std::vector<Point>& points, double pad = 0) { return indexBox(bounds(points), pad); }

SegmentTree segmentTree(const std::vector<const Polyline*>& lines, bool closed = false) {
  std::vector<SegmentEntry> entries;
  for (std::size_t l = 0; l < lines.size(); ++l) {
    const Polyline& line = *lines[l];
    const std::size_t n = line.size();
    const std::size_t segments = closed ? n : (n ? n - 1 : 0);
    for (std::size_t i = 0; i < segments; ++i) {
      entries.push_back({boxAround(line[i], line[(i + 1) % n]), {static_cast<int>(l), static_cast<int>(i)}});
    }
  }
  return SegmentTree(entries.begin(), entries.end());
}

// The point of segment ab nearest to p, and its parameter along ab.
Point nearestOnSegment(const Point& p, const Point& a, const Point& b, double* t = nullptr) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  double u = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0;
  u = std::clamp(u, 0.0, 1.0);
  if (t) *t = u;
  return {a.x + u * dx, a.y + u * dy};
}

double distance(const Point& a, const Point& b) { return std::hypot(a.x - b.x, a.y - b.y); }

double distanceToLine(const Point& p, const Polyline& line) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const Point q = nearestOnSegment(p, line[i], line[i + 1]);
    best = std::min(best, (p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y));
  }
  return std::sqrt(best);
}

double length(const Polyline& line) {
  double s = 0;
  for (std::size_t i = 0; i + 1 < line.size(); ++i) s += distance(line[i], line[i + 1]);
  return s;
}

// The point at arc length `s` along the line, and the unit direction there.
std::pair<Point, Point> pointAt(const Polyline& line, double s) {
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const double d = distance(line[i], line[i + 1]);
    if (d <= 0) continue;
    if (s <= d || i + 2 == line.size()) {
      const double u = std::clamp(s / d, 0.0, 1.0);
      const Point dir{(line[i + 1].x - line[i].x) / d, (line[i + 1].y - line[i].y) / d};
      return {{line[i].x + u * (line[i + 1].x - line[i].x), line[i].y + u * (line[i + 1].y - line[i].y)}, dir};
    }
    s -= d;
  }
  return {line.front(), {1, 0}};
}

// Mixed into the key of a block that faces no street.
constexpr Key kStreetlessBlockKey = 0x5354524545544c53ull;

// Key cells (about 1 cm each, see KeyPlace) per cell of a position key: about
// a metre. The noded network's points lie on the local frame's 1 mm grid
// (kGrid), so they move by up to half of it when the frame moves; a key drawn
// from a point flips where the point lies that close to a cell's edge, for
// 1 in 2,000 points at a metre (1 in 20 at a centimetre). Nodes closer than a
// metre (with less snapping) share a key and are told apart by their cells.
constexpr double kPositionCell = 100;

// The key of a position: its key place, rounded to kPositionCell key cells.
Key positionKey(const KeyPlace& keyPlace, const Point& p) {
  const Point q = keyPlace ? keyPlace(p) : Point{p.x * 100, p.y * 100};
  return mixKeys(static_cast<Key>(std::llround(q.x / kPositionCell)),
                 static_cast<Key>(std::llround(q.y / kPositionCell)));
}

std::pair<long long, long long> gridCell(const Point& p, double cell) {
  return {static_cast<long long>(std::floor(p.x / cell)), static_cast<long long>(std::floor(p.y / cell))};
}

struct CellHash {
  std::size_t operator()(const std::pair<long long, long long>& c) const {
    return static_cast<std::size_t>(mixKeys(static_cast<Key>(c.first), static_cast<Key>(c.second)));
  }
};

bool lexLess(const Point& a, const Point& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

// Union-find over endpoint indices.
int findRoot(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

// Joins endpoints within `snap` of each other: each cluster moves to its
// lexicographically least member (a choice independent of the input order).
// Returns, per endpoint (2 per line), the size of its cluster.
std::vector<int> joinEndpoints(std::vector<Polyline>& lines, double snap, std::int64_t& moved) {
  const std::size_t n = 2 * lines.size();
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto endpoint = [&](std::size_t e) -> Point& {
    Polyline& l = lines[e / 2];
    return e % 2 ? l.back() : l.front();
  };
  std::unordered_map<std::pair<long long, long long>, std::vector<int>, CellHash> grid;
  const double cell = std::max(snap, kGrid);
  for (std::size_t e = 0; e < n; ++e) {
    if (lines[e / 2].size() < 2) continue;
    grid[gridCell(endpoint(e), cell)].push_back(static_cast<int>(e));
  }
  for (std::size_t e = 0; e < n; ++e) {
    if (lines[e / 2].size() < 2) continue;
    const auto [cx, cy] = gridCell(endpoint(e), cell);
    for (long long dx = -1; dx <= 1; ++dx) {
      for (long long dy = -1; dy <= 1; ++dy) {
        const auto it = grid.find({cx + dx, cy + dy});
        if (it == grid.end()) continue;
        for (int other : it->second) {
          if (static_cast<std::size_t>(other) <= e) continue;
          if (distance(endpoint(e), endpoint(static_cast<std::size_t>(other))) <= snap) {
            parent[static_cast<std::size_t>(findRoot(parent, static_cast<int>(e)))] = findRoot(parent, other);
          }
        }
      }
    }
  }
  // Ends joined link by link can chain far beyond the snap distance (ends of
  // a thousand streets 0.8 m apart on a circle made one node, and every street
  // vanished). A cluster wider than twice the snap distance is joined again
  // without chaining: its ends in coordinate order, each joining the first
  // leader within the snap distance, or leading a group of its own.
  std::unordered_map<int, Box> extent;
  for (std::size_t e = 0; e < n; ++e) {
    if (lines[e / 2].size() < 2) continue;
    const Point& p = endpoint(e);
    auto [it, added] = extent.emplace(findRoot(parent, static_cast<int>(e)), Box{p.x, p.y, p.x, p.y});
    if (!added)
      it->second = {std::min(it->second.minX, p.x), std::min(it->second.minY, p.y), std::max(it->second.maxX, p.x),
                    std::max(it->second.maxY, p.y)};
  }
  std::unordered_map<int, std::vector<int>> chained;
  for (std::size_t e = 0; e < n; ++e) {
    if (lines[e / 2].size() < 2) continue;
    const int r = findRoot(parent, static_cast<int>(e));
    const Box& b = extent.at(r);
    if (std::hypot(b.width(), b.height()) > 2 * snap) chained[r].push_back(static_cast<int>(e));
  }
  for (auto& [root, ends] : chained) {
    std::sort(ends.begin(), ends.end(), [&](int a, int b) {
      const Point &pa = endpoint(static_cast<std::size_t>(a)), &pb = endpoint(static_cast<std::size_t>(b));
      return lexLess(pa, pb) || (!lexLess(pb, pa) && a < b);
    });
    // Leaders by grid cell, each with its rank (the first within reach wins).
    std::unordered_map<std::pair<long long, long long>, std::vector<std::pair<int, int>>, CellHash> leaders;
    int ranked = 0;
    for (int e : ends) {
      const Point& p = endpoint(static_cast<std::size_t>(e));
      const auto [cx, cy] = gridCell(p, cell);
      std::pair<int, int> first{std::numeric_limits<int>::max(), e};  // (rank, end)
      for (long long dx = -1; dx <= 1; ++dx) {
        for (long long dy = -1; dy <= 1; ++dy) {
          const auto it = leaders.find({cx + dx, cy + dy});
          if (it == leaders.end()) continue;
          for (const auto& [rank, l] : it->second) {
            if (rank < first.first && distance(endpoint(static_cast<std::size_t>(l)), p) <= snap) first = {rank, l};
          }
        }
      }
      if (first.second == e) leaders[{cx, cy}].emplace_back(ranked++, e);
      parent[static_cast<std::size_t>(e)] = first.second;
    }
  }
  std::unordered_map<int, Point> least;
  std::unordered_map<int, int> size;
  for (std::size_t e = 0; e < n; ++e) {
    if (lines[e / 2].size() < 2) continue;
    const int r = findRoot(parent, static_cast<int>(e));
    auto [it, added] = least.emplace(r, endpoint(e));
    if (!added && lexLess(endpoint(e), it->second)) it->second = endpoint(e);
    ++size[r];
  }
  std::vector<int> clusterSize(n, 0);
  for (std::size_t e = 0; e < n; ++e) {
    if (lines[e / 2].size() < 2) continue;
    const int r = findRoot(parent, static_cast<int>(e));
    const Point target = least[r];
    if (target.x != endpoint(e).x || target.y != endpoint(e).y) ++moved;
    endpoint(e) = target;
    clusterSize[e] = size[r];
  }
  return clusterSize;
}

// Moves each free end (an endpoint no other endpoint joined) within `snap` of
// another line onto its nearest point there, a little past it so that the
// noding finds the crossing.
void endsOntoLines(std::vector<Polyline>& lines, const std::vector<int>& clusterSize, const std::vector<char>& apart,
                   double snap, std::int64_t& moved) {
  std::vector<const Polyline*> pointers;
  for (const Polyline& l : lines) pointers.push_back(&l);
  const SegmentTree tree = segmentTree(pointers);
  std::vector<std::pair<std::size_t, Point>> moves;
  for (std::size_t e = 0; e < 2 * lines.size(); ++e) {
    const Polyline& own = lines[e / 2];
    if (own.size() < 2 || clusterSize[e] != 1) continue;
    const Point p = e % 2 ? own.back() : own.front();
    const Point inner = e % 2 ? own[own.size() - 2] : own[1];
    // Its own line only where it is more than the snap distance away along
    // it: segments starting (from this end) within that path length are skipped.
    std::vector<double> fromEnd(own.size(), 0);  // path length from this end to vertex i
    for (std::size_t k = 1; k < own.size(); ++k) {
      const std::size_t i = e % 2 ? own.size() - 1 - k : k, prev = e % 2 ? i + 1 : i - 1;
      fromEnd[i] = fromEnd[prev] + distance(own[i], own[prev]);
    }
    double best = std::numeric_limits<double>::infinity();
    Point target{};
    for (auto it = tree.qbegin(bgi::intersects(boxAround(p, p, snap))); it != tree.qend(); ++it) {
      const auto [l, i] = it->second;
      if (static_cast<std::size_t>(l) == e / 2) {
        const std::size_t near = e % 2 ? static_cast<std::size_t>(i) + 1 : static_cast<std::size_t>(i);
        if (fromEnd[near] <= snap) continue;
      }
      const Polyline& line = lines[static_cast<std::size_t>(l)];
      const Point q = nearestOnSegment(p, line[static_cast<std::size_t>(i)], line[static_cast<std::size_t>(i) + 1]);
      const double d = distance(p, q);
      if (d < best || (d == best && lexLess(q, target))) {
        best = d;
        target = q;
      }
    }
    if (!(best <= snap) || best <= 0) continue;
    // Past the line by a grid step, along the end's own direction to it, so
    // that the noding finds the crossing; a line kept apart (a bridge) ends on
    // it, and the line is cut there (splitAt).
    const double dx = target.x - inner.x, dy = target.y - inner.y, d = std::hypot(dx, dy);
    if (d > 0 && !apart[e / 2]) target = {target.x + 2 * kGrid * dx / d, target.y + 2 * kGrid * dy / d};
    moves.push_back({e, target});
  }
  for (const auto& [e, target] : moves) {
    Polyline& line = lines[e / 2];
    (e % 2 ? line.back() : line.front()) = target;
    ++moved;
  }
}

// Splits `pieces` at the points of `at` that lie inside one of their segments
// (within the noding grid), so that lines kept apart (bridges) still meet the
// network at their ends; each point is first put on the noding grid, where the
// bridge's own end lies.
void splitAt(std::vector<Polyline>& pieces, const std::vector<Point>& at) {
  std::vector<const Polyline*> pointers;
  for (const Polyline& l : pieces) pointers.push_back(&l);
  const SegmentTree tree = segmentTree(pointers);
  struct Cut {
    std::size_t segment;
    double t;
    Point at;
  };
  std::map<std::size_t, std::vector<Cut>> cuts;  // by piece
  for (const Point& raw : at) {
    const Point p{std::round(raw.x / kGrid) * kGrid, std::round(raw.y / kGrid) * kGrid};
    for (auto it = tree.qbegin(bgi::intersects(boxAround(p, p, kGrid))); it != tree.qend(); ++it) {
      const auto [l, i] = it->second;
      const Polyline& line = pieces[static_cast<std::size_t>(l)];
      if (distance(line.front(), p) <= kGrid || distance(line.back(), p) <= kGrid) continue;
      double t = 0;
      const Point q = nearestOnSegment(p, line[static_cast<std::size_t>(i)], line[static_cast<std::size_t>(i) + 1], &t);
      if (distance(p, q) <= kGrid) cuts[static_cast<std::size_t>(l)].push_back({static_cast<std::size_t>(i), t, p});
    }
  }
  for (auto& [k, list] : cuts) {
    std::sort(list.begin(), list.end(), [](const Cut& a, const Cut& b) {
      return a.segment < b.segment || (a.segment == b.segment && a.t < b.t);
    });
    const Polyline line = pieces[k];
    std::vector<Polyline> parts(1);
    std::size_t next = 0;
    for (std::size_t i = 0; i < line.size(); ++i) {
      parts.back().push_back(line[i]);
      for (; next < list.size() && list[next].segment == i; ++next) {
        const Point& p = list[next].at;
        if (distance(parts.back().back(), p) <= kGrid)
          parts.back().back() = p;
        else
          parts.back().push_back(p);
        if (parts.back().size() >= 2) parts.push_back({p});
      }
    }
    if (parts.back().size() >= 2 && distance(parts.back()[parts.back().size() - 2], line.back()) <= kGrid &&
        parts.back().size() == 2 && parts.size() > 1) {
      parts.pop_back();  // a cut at the very end
    }
    std::vector<Polyline> kept;
    for (Polyline& part : parts) {
      if (part.size() >= 2 && length(part) > 0) kept.push_back(std::move(part));
    }
    if (kept.empty()) continue;
    pieces[k] = std::move(kept.front());
    for (std::size_t j = 1; j < kept.size(); ++j) pieces.push_back(std::move(kept[j]));
  }
}

}  // namespace

RoadGraph buildRoadGraph(const std::vector<StreetLine>& input, const RoadGraphOptions& options) {
  RoadGraph graph;
  graph.keyPlace = options.keyPlace;
  RoadGraphReport& report = graph.report;
  report.lines = static_cast<std::int64_t>(input.size());
  std::vector<Polyline> lines(input.size());
  for (std::size_t i = 0; i < input.size(); ++i) {
    for (const Point& p : input[i].line) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
      if (lines[i].empty() || lines[i].back().x != p.x || lines[i].back().y != p.y) lines[i].push_back(p);
    }
    if (lines[i].size() < 2) {
      lines[i].clear();
      ++report.skipped;
    }
  }
  const std::vector<int> clusterSize = joinEndpoints(lines, options.snap, report.endpointsJoined);
  std::vector<char> apartLine(lines.size(), 0);
  for (std::size_t i = 0; i < input.size(); ++i) apartLine[i] = input[i].noNode;
  endsOntoLines(lines, clusterSize, apartLine, options.snap, report.endpointsOnLines);

  // Noding: the lines that meet what they cross, then those that do not.
  std::vector<Polyline> regular, apart;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    (input[i].noNode ? apart : regular).push_back(lines[i]);
    report.notNoded += input[i].noNode;
  }
  std::vector<Polyline> pieces = geos::nodeLines(regular, kGrid);
  // Each line kept apart is noded on its own (where it crosses itself): it
  // meets neither the others nor another bridge or tunnel it crosses, only
  // what its ends lie on.
  std::vector<Polyline> bridges;
  std::vector<Point> bridgeEnds;
  for (const Polyline& b : apart) {
    for (Polyline& piece : geos::nodeLines({b}, kGrid)) bridges.push_back(std::move(piece));
    bridgeEnds.push_back(b.front());
    bridgeEnds.push_back(b.back());
  }
  splitAt(pieces, bridgeEnds);
  // The stubs a free end left past the line it was moved onto.
  {
    std::map<std::pair<long long, long long>, int> ends;
    auto cell = [](const Point& p) { return std::make_pair(std::llround(p.x / kGrid), std::llround(p.y / kGrid)); };
    for (const Polyline& l : pieces) {
      ++ends[cell(l.front())];
      ++ends[cell(l.back())];
    }
    pieces.erase(std::remove_if(pieces.begin(), pieces.end(),
                                [&](const Polyline& l) {
                                  return length(l) <= 4 * kGrid &&
                                         (ends[cell(l.front())] == 1 || ends[cell(l.back())] == 1);
                                }),
                 pieces.end());
  }
  const std::size_t regularPieces = pieces.size();
  for (Polyline& b : bridges) pieces.push_back(std::move(b));

  // Attributes: each piece takes the line it lies along (at its middle); where
  // several do (duplicates), the one with a known and larger width, then the
  // least key.
  std::vector<const Polyline*> regularLines, apartLines;
  std::vector<int> regularIndex, apartIndex;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    (input[i].noNode ? apartLines : regularLines).push_back(&lines[i]);
    (input[i].noNode ? apartIndex : regularIndex).push_back(static_cast<int>(i));
  }
  const SegmentTree regularTree = segmentTree(regularLines), apartTree = segmentTree(apartLines);
  auto better = [&](int a, int b) {  // is line a a better source than line b?
    if (input[static_cast<std::size_t>(a)].boundary != input[static_cast<std::size_t>(b)].boundary) {
      return !input[static_cast<std::size_t>(a)].boundary;  // a street over the boundary
    }
    const StreetLine &la = input[static_cast<std::size_t>(a)], &lb = input[static_cast<std::size_t>(b)];
    if (std::isnan(la.width) != std::isnan(lb.width)) return !std::isnan(la.width);
    if (!std::isnan(la.width) && la.width != lb.width) return la.width > lb.width;
    if (la.key != lb.key) return la.key < lb.key;
    // The same geometry twice: by its other attributes, never by input order.
    if (la.name != lb.name) return la.name < lb.name;
    return la.noNode < lb.noNode;
  };

  // Nodes by position on the noding grid.
  std::map<std::pair<long long, long long>, int> nodeAt;
  std::vector<std::pair<long long, long long>> nodeCells;
  auto nodeOf = [&](const Point& p) {
    const std::pair<long long, long long> cell{std::llround(p.x / kGrid), std::llround(p.y / kGrid)};
    auto [it, added] = nodeAt.emplace(cell, static_cast<int>(graph.nodes.size()));
    // Keyed by the place of the 1 mm cell that makes it one node (nodes of
    // one key are told apart below).
    if (added) {
      const Point centre{static_cast<double>(cell.first) * kGrid, static_cast<double>(cell.second) * kGrid};
      graph.nodes.push_back({positionKey(options.keyPlace, centre), p, 0});
      nodeCells.push_back(cell);
    }
    return it->second;
  };
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    Polyline& line = pieces[k];
    if (line.size() < 2 || length(line) <= 0) continue;
    const bool bridge = k >= regularPieces;
    const Point middle = pointAt(line, 0.5 * length(line)).first;
    const SegmentTree& tree = bridge ? apartTree : regularTree;
    const std::vector<const Polyline*>& candidates = bridge ? apartLines : regularLines;
    const std::vector<int>& index = bridge ? apartIndex : regularIndex;
    int source = -1, along = 0;
    double nearest = std::numeric_limits<double>::infinity();
    int nearestSource = -1;
    for (auto it = tree.qbegin(bgi::intersects(boxAround(middle, middle, 0.01))); it != tree.qend(); ++it) {
      const auto [l, i] = it->second;
      const Polyline& c = *candidates[static_cast<std::size_t>(l)];
      const double d = distance(
          middle, nearestOnSegment(middle, c[static_cast<std::size_t>(i)], c[static_cast<std::size_t>(i) + 1]));
      const int s = index[static_cast<std::size_t>(l)];
      if (d < nearest) {
        nearest = d;
        nearestSource = s;
      }
      if (d > 0.01) continue;
      if (source != s) ++along;
      if (source < 0 || better(s, source)) source = s;
    }
    if (source < 0) source = nearestSource;
    if (source < 0) continue;
    if (along > 1) ++report.duplicateEdges;
    RoadEdge e;
    e.from = nodeOf(line.front());
    e.to = nodeOf(line.back());
    const StreetLine& s = input[static_cast<std::size_t>(source)];
    e.width = s.width;
    e.name = s.name;
    e.noNode = s.noNode;
    e.boundary = s.boundary;
    if (e.boundary) e.width = 0;
    e.source = source;
    e.line = std::move(line);
    graph.edges.push_back(std::move(e));
  }
  // Nodes of one key (distinct cells of one key cell): told apart by their cells.
  {
    std::vector<std::size_t> byKey(graph.nodes.size());
    std::iota(byKey.begin(), byKey.end(), 0);
    std::sort(byKey.begin(), byKey.end(), [&](std::size_t a, std::size_t b) {
      return graph.nodes[a].key != graph.nodes[b].key ? graph.nodes[a].key < graph.nodes[b].key
                                                      : nodeCells[a] < nodeCells[b];
    });
    std::vector<Key> keys;
    for (std::size_t i : byKey) keys.push_back(graph.nodes[i].key);
    for (std::size_t i = 1, run = 0; i < byKey.size(); ++i) {
      run = keys[i] == keys[i - 1] ? run + 1 : 0;
      if (run) graph.nodes[byKey[i]].key = mixKeys(keys[i], run);
    }
  }
  // Keys; edges run from the node of lesser key; nodes and edges sorted by key.
  for (RoadEdge& e : graph.edges) {
    Key a = graph.nodes[static_cast<std::size_t>(e.from)].key, b = graph.nodes[static_cast<std::size_t>(e.to)].key;
    if (a > b) {
      std::reverse(e.line.begin(), e.line.end());
      std::swap(e.from, e.to);
      std::swap(a, b);
    } else if (a == b && signedArea(e.line) < 0) {
      std::reverse(e.line.begin(), e.line.end());  // a loop runs counter-clockwise
    }
    e.key = mixKeys(mixKeys(a, b), positionKey(options.keyPlace, pointAt(e.line, 0.5 * length(e.line)).first));
    ++graph.nodes[static_cast<std::size_t>(e.from)].degree;
    ++graph.nodes[static_cast<std::size_t>(e.to)].degree;
  }
  std::vector<int> order(graph.nodes.size()), rank(graph.nodes.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return graph.nodes[static_cast<std::size_t>(a)].key < graph.nodes[static_cast<std::size_t>(b)].key;
  });
  std::vector<RoadNode> nodes;
  for (std::size_t r = 0; r < order.size(); ++r) {
    rank[static_cast<std::size_t>(order[r])] = static_cast<int>(r);
    nodes.push_back(graph.nodes[static_cast<std::size_t>(order[r])]);
  }
  graph.nodes = std::move(nodes);
  for (RoadEdge& e : graph.edges) {
    e.from = rank[static_cast<std::size_t>(e.from)];
    e.to = rank[static_cast<std::size_t>(e.to)];
  }
  // Edges of one key (parallel edges between two nodes with middles within
  // 1 cm) are told apart by their vertices, whatever the input order.
  auto vertexLess = [](const Polyline& a, const Polyline& b) {
    return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end(), lexLess);
  };
  std::sort(graph.edges.begin(), graph.edges.end(), [&](const RoadEdge& a, const RoadEdge& b) {
    return a.key != b.key ? a.key < b.key : vertexLess(a.line, b.line);
  });
  std::vector<Key> edgeKeys;
  for (const RoadEdge& e : graph.edges) edgeKeys.push_back(e.key);
  for (std::size_t i = 1, run = 0; i < graph.edges.size(); ++i) {
    run = edgeKeys[i] == edgeKeys[i - 1] ? run + 1 : 0;
    if (run) graph.edges[i].key = mixKeys(edgeKeys[i], run);
  }
  std::sort(graph.edges.begin(), graph.edges.end(), [](const RoadEdge& a, const RoadEdge& b) { return a.key < b.key; });
  for (const RoadNode& n : graph.nodes) report.deadEnds += n.degree == 1;
  return graph;
}

namespace {
// Appends the cubic Bezier a, b, c, d (a excluded) flattened to `tolerance`:
// split in halves (de Casteljau) until the control points lie within
// `tolerance` of the chord, which bounds the curve's distance from it.
void flatten(const Point& a, const Point& b, const Point& c, const Point& d, double tolerance, int depth,
             Polyline& out) {
  const double chord = distance(a, d);
  auto off = [&](const Point& p) {
    return chord > 0 ? std::fabs((d.x - a.x) * (p.y - a.y) - (d.y - a.y) * (p.x - a.x)) / chord : distance(p, a);
  };
  if (depth >= 16 || std::max(off(b), off(c)) <= tolerance) {
    out.push_back(d);
    return;
  }
  auto mid = [](const Point& p, const Point& q) { return Point{0.5 * (p.x + q.x), 0.5 * (p.y + q.y)}; };
  const Point ab = mid(a, b), bc = mid(b, c), cd = mid(c, d), abc = mid(ab, bc), bcd = mid(bc, cd), m = mid(abc, bcd);
  flatten(a, ab, abc, m, tolerance, depth + 1, out);
  flatten(m, bcd, cd, d, tolerance, depth + 1, out);
}
}  // namespace

void setCurve(RoadGraph& graph, std::size_t edge, std::optional<std::array<Point, 2>> controls, double tolerance) {
  if (edge >= graph.edges.size()) throw usageError("setCurve: no edge " + std::to_string(edge));
  RoadEdge& e = graph.edges[edge];
  const Point a = graph.nodes[static_cast<std::size_t>(e.from)].at, d = graph.nodes[static_cast<std::size_t>(e.to)].at;
  e.controls = controls;
  e.line = {a};
  if (controls) {
    flatten(a, (*controls)[0], (*controls)[1], d, std::max(tolerance, 1e-6), 0, e.line);
  } else {
    e.line.push_back(d);
  }
}

std::int64_t fillStreetWidths(RoadGraph& graph, const std::vector<const Polygon*>& parcelBlocks, double defaultWidth,
                              double maxWidth) {
  std::vector<const Polyline*> rings;
  for (const Polygon* p : parcelBlocks) {
    rings.push_back(&p->outer);
    for (const Ring& h : p->holes) rings.push_back(&h);
  }
  const SegmentTree tree = segmentTree(rings, /*closed=*/true);
  const double reach = 0.5 * maxWidth;
  // Distance from p straight along unit vector n to the nearest outline, or NaN.
  auto cast = [&](const Point& p, const Point& n) {
    const Point end{p.x + reach * n.x, p.y + reach * n.y};
    double best = std::numeric_limits<double>::infinity();
    for (auto it = tree.qbegin(bgi::intersects(boxAround(p, end))); it != tree.qend(); ++it) {
      const auto [r, i] = it->second;
      const Polyline& ring = *rings[static_cast<std::size_t>(r)];
      const Point a = ring[static_cast<std::size_t>(i)], b = ring[(static_cast<std::size_t>(i) + 1) % ring.size()];
      // p + u n = a + v (b - a)
      const double ex = b.x - a.x, ey = b.y - a.y, den = n.x * (-ey) - n.y * (-ex);
      if (den == 0) continue;
      const double rx = a.x - p.x, ry = a.y - p.y;
      const double u = (rx * (-ey) - ry * (-ex)) / den, v = (n.x * ry - n.y * rx) / den;
      if (u > 0 && u <= reach && v >= 0 && v <= 1) best = std::min(best, u);
    }
    return std::isfinite(best) ? best : NAN;
  };
  std::vector<char> measured(graph.edges.size(), 0);
  parallelFor(graph.edges.size(), [&](std::size_t k) {
    RoadEdge& e = graph.edges[k];
    if (!std::isnan(e.width) || e.boundary) return;
    const double len = length(e.line);
    std::vector<double> widths;
    const double from = 0.1 * len, to = 0.9 * len;
    const int samples = std::clamp(static_cast<int>((to - from) / 5.0), 1, 200);
    for (int i = 0; i < samples; ++i) {
      const double s = samples == 1 ? 0.5 * len : from + (to - from) * (i + 0.5) / samples;
      const auto [p, dir] = pointAt(e.line, s);
      const Point left{-dir.y, dir.x}, right{dir.y, -dir.x};
      const double l = cast(p, left), r = cast(p, right);
      if (!std::isnan(l) && !std::isnan(r)) {
        widths.push_back(l + r);
      } else if (!std::isnan(l) || !std::isnan(r)) {
        widths.push_back(2 * (std::isnan(l) ? r : l));
      }
    }
    if (widths.empty()) {
      e.width = defaultWidth;
      return;
    }
    std::nth_element(widths.begin(), widths.begin() + static_cast<long>(widths.size() / 2), widths.end());
    e.width = widths[widths.size() / 2];
    measured[k] = 1;
  });
  return std::count(measured.begin(), measured.end(), 1);
}

std::vector<Polygon> streetSurface(const RoadGraph& graph, int quadrantSegments) {
  std::vector<const Polyline*> lines;
  std::vector<double> halves;
  for (const RoadEdge& e : graph.edges) {
    lines.push_back(&e.line);
    halves.push_back(0.5 * e.width);
  }
  return geos::bufferedUnion(lines, halves, quadrantSegments);
}

namespace {

Key bitsKey(const std::vector<Point>& points, Key basis) {
  return hashBytes(std::string_view(reinterpret_cast<const char*>(points.data()), points.size() * sizeof(Point)),
                   basis);
}

Key doubleKey(double x, Key basis) {
  return hashBytes(std::string_view(reinterpret_cast<const char*>(&x), sizeof x), basis);
}

}  // namespace

namespace {

struct PointHash {
  std::size_t operator()(const Point& p) const {
    // -0 and 0 are equal points: one hash.
    const double px = p.x == 0 ? 0.0 : p.x, py = p.y == 0 ? 0.0 : p.y;
    std::uint64_t x = 0, y = 0;
    std::memcpy(&x, &px, sizeof x);
    std::memcpy(&y, &py, sizeof y);
    return static_cast<std::size_t>(x * 0x9e3779b97f4a7c15ull ^ (y + 0x632be59bd9b4e019ull + (x << 6) + (x >> 2)));
  }
};
struct PointEqual {
  bool operator()(const Point& a, const Point& b) const { return a.x == b.x && a.y == b.y; }
};
bool samePoint(const Point& a, const Point& b) { return a.x == b.x && a.y == b.y; }

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
Epick::Point_2 cgal(const Point& p) { return {p.x, p.y}; }

Box withPoint(Box b, const Point& p) {
  return {std::min(b.minX, p.x), std::min(b.minY, p.y), std::max(b.maxX, p.x), std::max(b.maxY, p.y)};
}
Box withBox(const Box& a, const Box& b) {
  return {std::min(a.minX, b.minX), std::min(a.minY, b.minY), std::max(a.maxX, b.maxX), std::max(a.maxY, b.maxY)};
}

// Whether lines `changed` (indices into `lines`) meet any line, themselves
// included, anywhere but where two of them legitimately share a point: two
// consecutive segments of one line at their vertex, or two lines at an end of
// both (a node); and not there either when the two segments run along each
// other (exact predicates on the doubles).
bool linesMeet(const std::vector<Polyline>& lines, const std::vector<std::size_t>& changed,
               const std::vector<Box>& boxes) {
  for (std::size_t c : changed) {
    const Polyline& a = lines[c];
    for (std::size_t e = 0; e < lines.size(); ++e) {
      if (!boxes[c].intersects(boxes[e])) continue;
      // A pair of changed lines is tested once, from the lower index.
      if (e != c && e < c && std::binary_search(changed.begin(), changed.end(), e)) continue;
      const Polyline& b = lines[e];
      for (std::size_t i = 0; i + 1 < a.size(); ++i) {
        const Box sa = withPoint(Box{a[i].x, a[i].y, a[i].x, a[i].y}, a[i + 1]);
        if (!sa.intersects(boxes[e])) continue;
        for (std::size_t j = e == c ? i + 1 : 0; j + 1 < b.size(); ++j) {
          const Box sb = withPoint(Box{b[j].x, b[j].y, b[j].x, b[j].y}, b[j + 1]);
          if (!sa.intersects(sb)) continue;
          // The point the two segments share, if any, and whether they may.
          const Point* shared = nullptr;
          const Point *otherA = nullptr, *otherB = nullptr;
          for (int u = 0; u < 2 && !shared; ++u) {
            for (int v = 0; v < 2 && !shared; ++v) {
              if (samePoint(a[i + u], b[j + v])) {
                shared = &a[i + u];
                otherA = &a[i + 1 - u];
                otherB = &b[j + 1 - v];
                const bool consecutive = e == c && j == i + 1 && u == 1 && v == 0;
                const bool node =
                    e != c && (i + u == 0 || i + u + 1 == a.size()) && (j + v == 0 || j + v + 1 == b.size());
                if (!consecutive && !node) return true;
              }
            }
          }
          if (shared) {
            // Along each other: collinear and pointing the same way from the shared point.
            if (CGAL::orientation(cgal(*shared), cgal(*otherA), cgal(*otherB)) == CGAL::COLLINEAR &&
                (otherA->x - shared->x) * (otherB->x - shared->x) + (otherA->y - shared->y) * (otherB->y - shared->y) >=
                    0) {
              return true;
            }
            // The segments' far ends: a segment may still reach the other's far end.
            if (CGAL::do_intersect(Epick::Segment_2(cgal(a[i]), cgal(a[i + 1])), Epick::Point_2(cgal(*otherB))) ||
                CGAL::do_intersect(Epick::Segment_2(cgal(b[j]), cgal(b[j + 1])), Epick::Point_2(cgal(*otherA)))) {
              return true;
            }
            continue;
          }
          if (CGAL::do_intersect(Epick::Segment_2(cgal(a[i]), cgal(a[i + 1])),
                                 Epick::Segment_2(cgal(b[j]), cgal(b[j + 1])))) {
            return true;
          }
        }
      }
    }
  }
  return false;
}

// The line ends at `node` in counter-clockwise order of their first segments,
// from the positive x axis (exact predicates); each as 2 x line + (1 at the
// line's last point). False when two of them leave along the same direction.
bool endsAround(const std::vector<Polyline>& lines, const std::vector<std::size_t>& at, const Point& node,
                std::vector<std::size_t>& order) {
  struct End {
    std::size_t id;
    Point towards;
  };
  std::vector<End> ends;
  for (std::size_t id : at) {
    const Polyline& l = lines[id / 2];
    ends.push_back({id, id % 2 ? l[l.size() - 2] : l[1]});
  }
  const auto upper = [&](const Point& q) { return q.y > node.y || (q.y == node.y && q.x > node.x); };
  bool tie = false;
  std::sort(ends.begin(), ends.end(), [&](const End& a, const End& b) {
    const bool ua = upper(a.towards), ub = upper(b.towards);
    if (ua != ub) return ua;
    const CGAL::Orientation o = CGAL::orientation(cgal(node), cgal(a.towards), cgal(b.towards));
    if (o == CGAL::COLLINEAR) tie = tie || a.id != b.id;
    return o == CGAL::LEFT_TURN;
  });
  order.clear();
  for (const End& e : ends) order.push_back(e.id);
  return !tie;
}

// Same cyclic sequence.
bool sameCycle(const std::vector<std::size_t>& a, const std::vector<std::size_t>& b) {
  if (a.size() != b.size()) return false;
  if (a.empty()) return true;
  const auto start = std::find(b.begin(), b.end(), a.front());
  if (start == b.end()) return false;
  const std::size_t shift = static_cast<std::size_t>(start - b.begin());
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] != b[(i + shift) % b.size()]) return false;
  }
  return true;
}

// The faces of `now` from those of `before` (`faces`, GEOS's polygonisation
// of `before`, lines not kept apart) when the lines changed only by moving
// vertices without changing the network's topology: then GEOS's polygoniser
// builds the same rings, from the same edges in the same order (it follows
// the edges' order around each node and the order of the lines), with the
// moved points in place of the old ones, and assigns the same holes to the
// same shells. Nothing when that cannot be shown here (the caller
// polygonises): more than a few lines changed, a line's vertex count changed,
// a vertex moved onto another or a segment of no length, a changed line
// meeting any line but at its nodes (before or after), the order of the line
// ends around a node of a changed line not the same, lines of another
// connected part of the network in the box the changed lines swept (an
// island or a separate network whose place in the faces could change), or a
// face ring turning the other way.
std::optional<geos::LineFaces> movedFaces(const std::vector<Polyline>& before, const std::vector<Polyline>& now,
                                          const geos::LineFaces& faces) {
  if (before.size() != now.size()) return std::nullopt;
  std::vector<std::size_t> changed;
  for (std::size_t i = 0; i < now.size(); ++i) {
    if (before[i].size() != now[i].size()) return std::nullopt;
    if (before[i].size() < 2) return std::nullopt;
    if (std::memcmp(before[i].data(), now[i].data(), now[i].size() * sizeof(Point)) != 0) {
      changed.push_back(i);
      if (changed.size() > 16) return std::nullopt;
    }
  }
  if (changed.empty()) return std::nullopt;
  // The moves, old point to new; one new point per old point and the other way round.
  std::unordered_map<Point, Point, PointHash, PointEqual> moved, movedBack;
  for (std::size_t c : changed) {
    for (std::size_t k = 0; k < now[c].size(); ++k) {
      if (k > 0 && (samePoint(now[c][k], now[c][k - 1]) || samePoint(before[c][k], before[c][k - 1]))) {
        return std::nullopt;
      }
      const Point& o = before[c][k];
      const Point& n = now[c][k];
      if (samePoint(o, n)) continue;
      const auto [it, fresh] = moved.emplace(o, n);
      if (!fresh && !samePoint(it->second, n)) return std::nullopt;
      const auto [back, freshBack] = movedBack.emplace(n, o);
      if (!freshBack && !samePoint(back->second, o)) return std::nullopt;
    }
  }
  // An old point moved is no vertex of a line left as it was, nor a point
  // left in place in a changed line.
  std::vector<char> isChanged(now.size(), 0);
  for (std::size_t c : changed) isChanged[c] = 1;
  for (std::size_t i = 0; i < now.size(); ++i) {
    for (std::size_t k = 0; k < now[i].size(); ++k) {
      if (isChanged[i] && !samePoint(before[i][k], now[i][k])) continue;
      if (moved.count(now[i][k])) return std::nullopt;
    }
  }
  // No changed line meets another but at their nodes, before and after.
  std::vector<Box> boxesBefore(now.size()), boxesNow(now.size());
  for (std::size_t i = 0; i < now.size(); ++i) {
    boxesNow[i] = bounds(now[i]);
    boxesBefore[i] = isChanged[i] ? bounds(before[i]) : boxesNow[i];
  }
  if (linesMeet(now, changed, boxesNow) || linesMeet(before, changed, boxesBefore)) return std::nullopt;
  // The line ends around every node of a changed line, in the same order.
  std::vector<Point> nodesBefore, nodesNow;
  for (std::size_t c : changed) {
    for (const Polyline* l : {&before[c]}) nodesBefore.insert(nodesBefore.end(), {l->front(), l->back()});
    nodesNow.insert(nodesNow.end(), {now[c].front(), now[c].back()});
  }
  for (std::size_t k = 0; k < nodesBefore.size(); ++k) {
    std::vector<std::size_t> atBefore, atNow;
    for (std::size_t i = 0; i < now.size(); ++i) {
      if (samePoint(before[i].front(), nodesBefore[k])) atBefore.push_back(2 * i);
      if (samePoint(before[i].back(), nodesBefore[k])) atBefore.push_back(2 * i + 1);
      if (samePoint(now[i].front(), nodesNow[k])) atNow.push_back(2 * i);
      if (samePoint(now[i].back(), nodesNow[k])) atNow.push_back(2 * i + 1);
    }
    if (atBefore != atNow) return std::nullopt;
    std::vector<std::size_t> orderBefore, orderNow;
    if (!endsAround(before, atBefore, nodesBefore[k], orderBefore) || !endsAround(now, atNow, nodesNow[k], orderNow) ||
        !sameCycle(orderBefore, orderNow)) {
      return std::nullopt;
    }
  }
  // Connected parts (lines joined at shared ends): in the box the changed
  // lines swept, only lines of their own part.
  std::vector<std::size_t> parent(now.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  {
    std::unordered_map<Point, std::size_t, PointHash, PointEqual> firstAt;
    for (std::size_t i = 0; i < now.size(); ++i) {
      for (const Point* end : {&now[i].front(), &now[i].back()}) {
        const auto [it, fresh] = firstAt.emplace(*end, i);
        if (!fresh) parent[root(i)] = root(it->second);
      }
    }
  }
  const std::size_t part = root(changed.front());
  Box swept = boxesNow[changed.front()];
  for (std::size_t c : changed) {
    if (root(c) != part) return std::nullopt;
    swept = withBox(withBox(swept, boxesNow[c]), boxesBefore[c]);
  }
  for (std::size_t i = 0; i < now.size(); ++i) {
    if (root(i) != part && boxesNow[i].intersects(swept)) return std::nullopt;
  }
  // The rings with the moved points; each keeps its turn.
  geos::LineFaces out = faces;
  const auto substitute = [&](Ring& ring) {
    bool touched = false;
    for (Point& p : ring) {
      const auto it = moved.find(p);
      if (it == moved.end()) continue;
      p = it->second;
      touched = true;
    }
    return touched;
  };
  // The turn is told by the floating-point area (as `normalise` tells it
  // when GEOS's rings are collected, from another first vertex): only where
  // it is far above that sum's rounding, before and after.
  const auto clearArea = [](const Ring& ring, double a) {
    const Box b = bounds(ring);
    const double size = b.width() + b.height();
    return std::fabs(a) > 1e-12 * static_cast<double>(ring.size()) * size * size;
  };
  for (Polygon& face : out.faces) {
    for (std::size_t r = 0; r <= face.holes.size(); ++r) {
      Ring& ring = r == 0 ? face.outer : face.holes[r - 1];
      const double was = signedArea(ring);
      const bool clearBefore = clearArea(ring, was);
      if (!substitute(ring)) continue;
      const double is = signedArea(ring);
      if (!clearBefore || !clearArea(ring, is) || (is > 0) != (was > 0)) return std::nullopt;
    }
  }
  // (Dangles and cut edges with the moved points too; GEOS would list the
  // dangles in the order of their nodes' coordinates: no caller uses them.)
  for (auto* lines : {&out.dangles, &out.cutEdges}) {
    for (Polyline& l : *lines) substitute(l);
  }
  return out;
}

}  // namespace

StreetBlocks streetBlocks(const RoadGraph& graph, const StreetBlockOptions& options, const ProgressFn& progress,
                          StreetBlockCache* cache) {
  for (const RoadEdge& e : graph.edges) {
    if (!(e.width >= 0)) throw usageError("street blocks: an edge has no width (fill the widths first)");
  }
  StreetBlocks out;
  // The graph's edges are noded already, but for lines kept apart (bridges).
  std::vector<Polyline> all;
  bool apart = false;
  for (const RoadEdge& e : graph.edges) {
    all.push_back(e.line);
    apart |= e.noNode;
  }
  // The faces of the lines; the last call's when its lines were the same.
  std::optional<geos::LineFaces> polygonized;
  const auto sameBits = [](const std::vector<Polyline>& a, const std::vector<Polyline>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a[i].size() != b[i].size() ||
          (!a[i].empty() && std::memcmp(a[i].data(), b[i].data(), a[i].size() * sizeof(Point)) != 0))
        return false;
    }
    return true;
  };
  const bool sameLines = cache && cache->lineFaces && cache->linesApart == apart && sameBits(cache->lines, all);
  // Lines moved without a change of topology (a node dragged): the last
  // call's faces with the moved points, as GEOS would give them.
  if (!sameLines && cache && cache->lineFaces && !apart && !cache->linesApart) {
    polygonized = movedFaces(cache->lines, all, *cache->lineFaces);
    cache->facesMoved += polygonized.has_value();
  }
  if (!sameLines && !polygonized) polygonized = geos::polygonizeLines(apart ? geos::nodeLines(all, kGrid) : all);
  const geos::LineFaces& faces = sameLines ? *cache->lineFaces : *polygonized;
  out.faces = static_cast<std::int64_t>(faces.faces.size());
  reportProgress(progress, 0.2, "faces");

  // Each edge's surface, and an index of their boxes.
  // (The cached ones in place: the cache takes new entries only at the end.)
  std::vector<std::vector<Polygon>> builtSurfaces(graph.edges.size());
  std::vector<const std::vector<Polygon>*> surfaces(graph.edges.size());
  std::vector<Key> surfaceKeys(graph.edges.size());
  parallelFor(graph.edges.size(), [&](std::size_t k) {
    const RoadEdge& e = graph.edges[k];
    surfaceKeys[k] = doubleKey(e.width, bitsKey(e.line, static_cast<Key>(options.quadrantSegments)));
    if (cache) {
      if (const auto it = cache->surfaces.find(surfaceKeys[k]); it != cache->surfaces.end()) {
        surfaces[k] = &it->second;
        return;
      }
    }
    builtSurfaces[k] = geos::bufferedUnion({&e.line}, {0.5 * e.width}, options.quadrantSegments);
    surfaces[k] = &builtSurfaces[k];
  });
  std::vector<BoxEntry> boxes;
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    boxes.push_back({boxOf(graph.edges[k].line, 0.5 * graph.edges[k].width), static_cast<int>(k)});
  }
  const BoxTree<int> edgeTree(boxes.begin(), boxes.end());

  struct FaceBlocks {
    std::vector<StreetBlock> blocks;
    bool tooLarge = false;
    int tooSmall = 0;
  };
  std::vector<FaceBlocks> perFace(faces.faces.size());
  std::vector<Key> faceSignature(faces.faces.size(), 0);
  std::vector<char> computed(faces.faces.size(), 0);
  parallelFor(
      faces.faces.size(),
      [&](std::size_t f) {
        const Polygon& face = faces.faces[f];
        FaceBlocks& result = perFace[f];
        if (area(face) > options.maxArea) {
          result.tooLarge = true;
          return;
        }
        std::vector<int> boxed;
        for (auto it = edgeTree.qbegin(bgi::intersects(boxOf(face.outer))); it != edgeTree.qend(); ++it) {
          if (!graph.edges[static_cast<std::size_t>(it->second)].boundary) boxed.push_back(it->second);
        }
        std::sort(boxed.begin(), boxed.end());
        if (cache) {
          // The face and everything its blocks are made of: the edges near it.
          Key key = bitsKey(face.outer, 0x9e3779b97f4a7c15ull);
          for (const Ring& h : face.holes) key = bitsKey(h, key);
          for (int k : boxed) {
            key = mixKeys(mixKeys(key, static_cast<Key>(k)), graph.edges[static_cast<std::size_t>(k)].key);
            key = mixKeys(key, surfaceKeys[static_cast<std::size_t>(k)]);
          }
          faceSignature[f] = key;
          const auto it = cache->faces.find(key);
          if (it != cache->faces.end() && sameVertices(it->second.face, face)) {
            result.blocks = it->second.blocks;
            result.tooSmall = it->second.tooSmall;
            return;
          }
        }
        computed[f] = 1;
        // Of the edges whose boxes meet the face's, those whose surface reaches it.
        std::vector<const Polyline*> lines;
        std::vector<double> reach;
        for (int k : boxed) {
          lines.push_back(&graph.edges[static_cast<std::size_t>(k)].line);
          reach.push_back(0.5 * graph.edges[static_cast<std::size_t>(k)].width);
        }
        std::vector<int> near;
        for (int i : geos::linesNear(face, lines, reach)) near.push_back(boxed[static_cast<std::size_t>(i)]);
        std::vector<const Polygon*> cut;
        for (int k : near) {
          for (const Polygon& p : *surfaces[static_cast<std::size_t>(k)]) cut.push_back(&p);
        }
        for (Polygon& part : geos::difference(face, cut, kOverlayGrid)) {
          if (area(part) < options.minArea || 2 * area(part) < options.minWidth * perimeter(part)) {
            ++result.tooSmall;
            continue;
          }
          StreetBlock b;
          std::vector<Key> facedKeys;
          auto faceRing = [&](const Ring& ring) {
            std::vector<int> faced(ring.size(), -1);
            for (std::size_t i = 0; i < ring.size(); ++i) {
              const Point& a = ring[i];
              const Point& c = ring[(i + 1) % ring.size()];
              const Point mid{0.5 * (a.x + c.x), 0.5 * (a.y + c.y)};
              double best = std::numeric_limits<double>::infinity();
              for (int k : near) {
                const RoadEdge& e = graph.edges[static_cast<std::size_t>(k)];
                const double d = distanceToLine(mid, e.line) - 0.5 * e.width;
                if (d < best) {
                  best = d;
                  faced[i] = k;
                }
              }
              if (!(best <= 1.0)) faced[i] = -1;
              if (faced[i] >= 0) facedKeys.push_back(graph.edges[static_cast<std::size_t>(faced[i])].key);
            }
            b.faced.push_back(std::move(faced));
          };
          faceRing(part.outer);
          for (const Ring& h : part.holes) faceRing(h);
          std::sort(facedKeys.begin(), facedKeys.end());
          facedKeys.erase(std::unique(facedKeys.begin(), facedKeys.end()), facedKeys.end());
          // A block facing no street (closed by the parcels' outline alone)
          // is keyed by its place: setKey of no key is 0 for every such block.
          b.key = facedKeys.empty() ? mixKeys(kStreetlessBlockKey, positionKey(graph.keyPlace, centroid(part)))
                                    : setKey(facedKeys);
          b.shape = std::move(part);
          result.blocks.push_back(std::move(b));
        }
      },
      [&](std::size_t done) {
        reportProgress(progress, 0.2 + 0.8 * static_cast<double>(done) / static_cast<double>(faces.faces.size()),
                       "blocks");
      });
  if (cache) {
    for (std::size_t k = 0; k < graph.edges.size(); ++k) {
      if (surfaces[k] == &builtSurfaces[k]) cache->surfaces.try_emplace(surfaceKeys[k], std::move(builtSurfaces[k]));
    }
    for (std::size_t f = 0; f < perFace.size(); ++f) {
      if (computed[f]) {
        cache->faces[faceSignature[f]] = {faces.faces[f], perFace[f].blocks, perFace[f].tooLarge, perFace[f].tooSmall};
      }
    }
    if (!sameLines) {  // last: `faces` refers to them until here
      cache->lines = std::move(all);
      cache->linesApart = apart;
      cache->lineFaces = std::move(polygonized);
    }
  }
  for (FaceBlocks& f : perFace) {
    out.facesTooLarge += f.tooLarge;
    out.partsTooSmall += f.tooSmall;
    for (StreetBlock& b : f.blocks) out.blocks.push_back(std::move(b));
  }
  // Blocks facing the same streets (pieces of one face) are told apart by
  // their place, in an order that does not depend on the input's.
  auto place = [](const StreetBlock& b) { return centroid(b.shape); };
  std::sort(out.blocks.begin(), out.blocks.end(), [&](const StreetBlock& a, const StreetBlock& b) {
    if (a.key != b.key) return a.key < b.key;
    return lexLess(place(a), place(b));
  });
  std::vector<Key> faceKeys;
  for (const StreetBlock& b : out.blocks) faceKeys.push_back(b.key);
  for (std::size_t i = 1, run = 0; i < out.blocks.size(); ++i) {
    run = faceKeys[i] == faceKeys[i - 1] ? run + 1 : 0;
    if (run) out.blocks[i].key = mixKeys(faceKeys[i], run);
  }
  std::sort(out.blocks.begin(), out.blocks.end(),
            [](const StreetBlock& a, const StreetBlock& b) { return a.key < b.key; });
  return out;
}

std::vector<std::vector<double>> facedWidths(const RoadGraph& graph, const StreetBlock& block) {
  std::vector<std::vector<double>> widths;
  for (const std::vector<int>& ring : block.faced) {
    std::vector<double> w;
    for (int e : ring) w.push_back(e >= 0 ? graph.edges[static_cast<std::size_t>(e)].width : NAN);
    widths.push_back(std::move(w));
  }
  return widths;
}

}  // namespace parcelscope::analysis
