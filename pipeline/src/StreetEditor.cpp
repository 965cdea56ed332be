#include "parcelscope/pipeline/StreetEditor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <set>
#include <sstream>
#include <unordered_set>
#include <utility>

#include "CompareStages.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/generation/ParcelMatching.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/StreetReader.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/BlockSource.h"

namespace parcelscope::pipeline {

const char* editOpName(StreetEdit::Op op) {
  switch (op) {
    case StreetEdit::Op::MoveNode:
      return "move_node";
    case StreetEdit::Op::MoveEdge:
      return "move_edge";
    case StreetEdit::Op::SetWidth:
      return "set_width";
    case StreetEdit::Op::SetCurve:
      return "set_curve";
    case StreetEdit::Op::TransformNodes:
      return "transform_nodes";
    case StreetEdit::Op::SetBlock:
      return "set_block";
    case StreetEdit::Op::SetLabel:
      return "set_label";
    case StreetEdit::Op::InsertNode:
      return "insert_node";
    case StreetEdit::Op::AddStreet:
      return "add_street";
    case StreetEdit::Op::DeleteStreet:
      return "delete_street";
    case StreetEdit::Op::SetLock:
      return "set_lock";
  }
  return "?";
}

// One state of the document: what an undo goes back to, whole.
struct StreetEditor::State {
  std::shared_ptr<const StreetNetwork> network;
  BlockInputs inputs;
  std::vector<BlockPlan> plans;
  std::vector<std::shared_ptr<const BlockOutcome>> outcomes;  // per entry; shared with the states before
  std::vector<std::vector<Key>> entryKeys;                    // per entry, its parcels' keys
  BlockOverrides overrides;
  Attributes attributes;  // labels and locks, by parcel key
  GeneratedParcels parcels;
  std::vector<Key> parcelKeys;  // of parcels.parcels
};

namespace {

bool sameWidths(const StreetWidths& a, const StreetWidths& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t r = 0; r < a.size(); ++r) {
    if (a[r].size() != b[r].size()) return false;
    for (std::size_t i = 0; i < a[r].size(); ++i) {
      const double x = a[r][i], y = b[r][i];
      if (!(x == y || (std::isnan(x) && std::isnan(y)))) return false;
    }
  }
  return true;
}

// Key of a parcel that inherits none: its block part's key, the edit that made
// it (0: the first build) and its index in the block.
Key freshKey(Key blockKey, int part, std::uint64_t serial, std::size_t index) {
  return mixKeys(mixKeys(partKey(blockKey, part), serial), static_cast<Key>(index));
}

// Index of the node or edge of key `key`; Error(Usage) naming it (`what`) when none.
template <typename Item>
std::size_t indexOf(const std::vector<Item>& items, Key key, const char* what) {
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (items[i].key == key) return i;
  }
  throw usageError(std::string("the network has no ") + what + " " + keyText(key));
}
// How far from the network's centre (the local frame's origin) an edit may
// take a node or a street's point: 1,000 km.
constexpr double kReach = 1e6;

void requireWithinReach(const Point& p, const char* what) {
  if (!(std::fabs(p.x) <= kReach && std::fabs(p.y) <= kReach)) {
    throw usageError(std::string(what) + " beyond 1,000 km of the network's centre (a place that is not finite, " +
                     "or a scale or move far too large)");
  }
}

std::size_t indexOf(const std::vector<analysis::RoadNode>& nodes, Key key) { return indexOf(nodes, key, "node"); }
std::size_t indexOf(const std::vector<analysis::RoadEdge>& edges, Key key) { return indexOf(edges, key, "edge"); }

// Moves the nodes of `graph` by `move` (a node's new position from its old),
// the ends of the edges at them with them; the inner vertices and control
// points of edges whose ends both move, moved the same way.
void moveNodes(analysis::RoadGraph& graph, const std::set<std::size_t>& nodes,
               const std::function<Point(const Point&)>& move) {
  for (std::size_t n : nodes) graph.nodes[n].at = move(graph.nodes[n].at);
  for (std::size_t e = 0; e < graph.edges.size(); ++e) {
    analysis::RoadEdge& edge = graph.edges[e];
    const bool from = nodes.count(static_cast<std::size_t>(edge.from)) > 0;
    const bool to = nodes.count(static_cast<std::size_t>(edge.to)) > 0;
    if (!from && !to) continue;
    if (from && to) {
      for (Point& p : edge.line) p = move(p);
      if (edge.controls) {
        for (Point& c : *edge.controls) c = move(c);
      }
    }
    if (edge.controls) {
      analysis::setCurve(graph, e, edge.controls);  // flattened again between its nodes
      continue;
    }
    edge.line.front() = graph.nodes[static_cast<std::size_t>(edge.from)].at;
    edge.line.back() = graph.nodes[static_cast<std::size_t>(edge.to)].at;
  }
}

// Keys unique again after some `items` (nodes or edges) took the keys of
// their counterparts before (`kept`): buildRoadGraph keys positions to about a
// metre and tells items of one key apart by their order, so an item new to the
// network may have drawn a key an item before had (one kept, or a street cut
// in two). Such an item takes another, mixed from its own (in the items'
// order: deterministic).
template <typename Item>
void uniqueKeys(std::vector<Item>& items, const std::vector<char>& kept, const std::vector<Item>& before) {
  std::set<Key> used;
  for (const Item& b : before) used.insert(b.key);
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (kept[i]) used.insert(items[i].key);
  }
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (kept[i]) continue;
    while (used.count(items[i].key)) items[i].key = mixKeys(items[i].key, 0x52454b4559ull);
    used.insert(items[i].key);
  }
}

// `graph` with the edges `removed` left out and the lines `added`, noded again
// (analysis::buildRoadGraph). A node where a node was keeps its key; an edge
// with the same vertices as an edge before keeps its key and its curve's
// control points (another curved edge keeps its flattened line).
analysis::RoadGraph renoded(const analysis::RoadGraph& graph, const std::set<std::size_t>& removed,
                            const std::vector<analysis::StreetLine>& added, double snap) {
  std::vector<analysis::StreetLine> lines;
  for (std::size_t e = 0; e < graph.edges.size(); ++e) {
    if (removed.count(e)) continue;
    const analysis::RoadEdge& x = graph.edges[e];
    lines.push_back({x.line, x.width, x.name, x.noNode, x.key, x.boundary});
  }
  lines.insert(lines.end(), added.begin(), added.end());
  analysis::RoadGraphOptions options;
  options.snap = snap;
  options.keyPlace = graph.keyPlace;
  analysis::RoadGraph out = analysis::buildRoadGraph(lines, options);
  // A node within the noding grid's cell (1 mm) of a node before is that node:
  // noding may move a node by a rounding, and an edit replayed from a file
  // (coordinates through the input's CRS and back) by about as little.
  constexpr double kSame = 1e-3;
  std::map<std::pair<long long, long long>, std::vector<std::size_t>> cells;
  const auto cellOf = [](const Point& p) {
    return std::make_pair(static_cast<long long>(std::floor(p.x / kSame)),
                          static_cast<long long>(std::floor(p.y / kSame)));
  };
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) cells[cellOf(graph.nodes[i].at)].push_back(i);
  std::set<std::size_t> taken;
  std::vector<char> nodeKept(out.nodes.size(), 0);
  for (std::size_t ni = 0; ni < out.nodes.size(); ++ni) {
    analysis::RoadNode& n = out.nodes[ni];
    const auto [cx, cy] = cellOf(n.at);
    double nearest = kSame;
    long best = -1;
    for (long long dx = -1; dx <= 1; ++dx) {
      for (long long dy = -1; dy <= 1; ++dy) {
        const auto it = cells.find({cx + dx, cy + dy});
        if (it == cells.end()) continue;
        for (std::size_t i : it->second) {
          const double d = std::hypot(graph.nodes[i].at.x - n.at.x, graph.nodes[i].at.y - n.at.y);
          if (d <= nearest && !taken.count(i)) {
            nearest = d;
            best = static_cast<long>(i);
          }
        }
      }
    }
    if (best < 0) continue;
    taken.insert(static_cast<std::size_t>(best));
    n.key = graph.nodes[static_cast<std::size_t>(best)].key;
    nodeKept[ni] = 1;
  }
  uniqueKeys(out.nodes, nodeKept, graph.nodes);
  // An edge whose end nodes are those of an edge before (by key) and whose
  // vertices lie within 1 mm of its vertices, either way along, is that edge.
  const auto along = [&](const std::vector<Point>& a, const std::vector<Point>& b, bool reversed) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const Point& q = reversed ? b[b.size() - 1 - i] : b[i];
      if (std::hypot(a[i].x - q.x, a[i].y - q.y) > kSame) return false;
    }
    return true;
  };
  std::map<std::pair<Key, Key>, std::vector<std::size_t>> edgesBetween;
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    if (removed.count(k)) continue;
    const analysis::RoadEdge& e = graph.edges[k];
    const Key a = graph.nodes[static_cast<std::size_t>(e.from)].key,
              b = graph.nodes[static_cast<std::size_t>(e.to)].key;
    edgesBetween[std::minmax(a, b)].push_back(k);
  }
  std::set<std::size_t> edgeTaken;
  std::vector<char> edgeKept(out.edges.size(), 0);
  for (std::size_t ei = 0; ei < out.edges.size(); ++ei) {
    analysis::RoadEdge& e = out.edges[ei];
    const Key a = out.nodes[static_cast<std::size_t>(e.from)].key, b = out.nodes[static_cast<std::size_t>(e.to)].key;
    const auto it = edgesBetween.find(std::minmax(a, b));
    if (it == edgesBetween.end()) continue;
    for (std::size_t k : it->second) {
      const analysis::RoadEdge& old = graph.edges[k];
      if (edgeTaken.count(k)) continue;
      const bool forward = along(e.line, old.line, false);
      if (!forward && !along(e.line, old.line, true)) continue;
      edgeTaken.insert(k);
      e.key = old.key;
      edgeKept[ei] = 1;
      if (old.controls && forward && graph.nodes[static_cast<std::size_t>(old.from)].key == a)
        e.controls = old.controls;
      break;
    }
  }
  uniqueKeys(out.edges, edgeKept, graph.edges);
  // Sorted by key again, as buildRoadGraph leaves them.
  std::vector<std::size_t> order(out.nodes.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return out.nodes[a].key < out.nodes[b].key; });
  std::vector<int> rank(order.size());
  std::vector<analysis::RoadNode> nodes;
  for (std::size_t r = 0; r < order.size(); ++r) {
    rank[order[r]] = static_cast<int>(r);
    nodes.push_back(out.nodes[order[r]]);
  }
  out.nodes = std::move(nodes);
  for (analysis::RoadEdge& e : out.edges) {
    e.from = rank[static_cast<std::size_t>(e.from)];
    e.to = rank[static_cast<std::size_t>(e.to)];
  }
  std::sort(out.edges.begin(), out.edges.end(),
            [](const analysis::RoadEdge& a, const analysis::RoadEdge& b) { return a.key < b.key; });
  return out;
}

// Block entry `entry` subdivided by `plan` around the parcels `anchored` (kept
// as they are, first): the rest of the block, in pieces, each subdivided with
// the plan's style and values and a seed of its own; measured in the block.
BlockOutcome runAround(const BlockInputs& inputs, std::size_t entry, const BlockPlan& plan,
                       std::vector<Polygon> anchored, double minFrontage) {
  BlockOutcome o;
  std::vector<const Polygon*> cut;
  for (const Polygon& a : anchored) cut.push_back(&a);
  std::vector<Polygon> rest = geos::difference(inputs.entries[entry].shape, cut, 1e-6);
  o.subdivision.parcels = std::move(anchored);
  for (std::size_t i = 0; i < rest.size(); ++i) {
    Subdivision piece = generation::subdivideBlock(rest[i], plan.style, plan.values, mixKeys(plan.seed, i + 1));
    for (Polygon& p : piece.parcels) o.subdivision.parcels.push_back(std::move(p));
  }
  o.metrics = analysis::measureShapes(o.subdivision.parcels);
  o.contextMeasured = false;
  measureOutcomeContext(inputs, entry, o, minFrontage);
  return o;
}

}  // namespace

std::shared_ptr<const StreetEditor::State> StreetEditor::build(std::shared_ptr<const StreetNetwork> network,
                                                               BlockOverrides overrides, Attributes attributes,
                                                               const State* previous, EditReport* report) const {
  auto s = std::make_shared<State>();
  s->network = network;
  s->inputs = streetNetworkInputs(network);
  for (BlockInputs::Entry& e : s->inputs.entries) {
    const auto it = derived_.find({e.blockKey, e.part});
    if (it == derived_.end()) continue;
    Polygon shape = std::move(e.shape);
    const std::int64_t id = e.blockId;
    e = it->second;
    e.shape = std::move(shape);
    e.blockId = id;
  }
  // The observed layer itself, shared (not copied on every edit).
  if (observed_) s->inputs.source = std::shared_ptr<const io::ParcelLayer>(observed_, &observed_->layer);
  // An override stays with its block's key; a block gone takes its override
  // with it. The first state's overrides must name blocks of the network, as
  // compare and generate require.
  std::set<Key> keys;
  for (const BlockInputs::Entry& e : s->inputs.entries) keys.insert(e.blockKey);
  for (const auto& [key, o] : previous ? BlockOverrides{} : overrides) {
    if (!keys.count(key)) throw usageError("block " + keyText(key) + ": no such block (override)");
  }
  for (auto it = overrides.begin(); it != overrides.end();) {
    it = keys.count(it->first) ? std::next(it) : overrides.erase(it);
  }
  GenerateRequest r = request_;
  r.overrides = overrides;
  r.overridesById.clear();
  s->overrides = std::move(overrides);
  // Each entry's counterpart before: the same block part (key and part).
  std::map<std::pair<Key, int>, std::size_t> before;
  if (previous) {
    for (std::size_t k = 0; k < previous->inputs.entries.size(); ++k) {
      const BlockInputs::Entry& e = previous->inputs.entries[k];
      before.emplace(std::make_pair(e.blockKey, e.part), k);
    }
  }
  // A block part as it was (same outline, same override) keeps its plan: a
  // plan depends on nothing else the editor changes.
  std::vector<char> planned(s->inputs.entries.size(), 0);
  std::vector<long> samePart(s->inputs.entries.size(), -1);
  for (std::size_t k = 0; previous && k < s->inputs.entries.size(); ++k) {
    const BlockInputs::Entry& e = s->inputs.entries[k];
    const auto it = before.find({e.blockKey, e.part});
    if (it == before.end()) continue;
    const std::size_t p = it->second;
    const auto now = s->overrides.find(e.blockKey);
    const auto then = previous->overrides.find(e.blockKey);
    const bool sameOverride = (now == s->overrides.end()) == (then == previous->overrides.end()) &&
                              (now == s->overrides.end() || (now->second.style == then->second.style &&
                                                             now->second.parameters == then->second.parameters));
    if (sameOverride && sameVertices(e.shape, previous->inputs.entries[p].shape)) {
      planned[k] = 1;
      samePart[k] = static_cast<long>(p);
    }
  }
  s->plans = planBlocks(r, s->inputs, nullptr, &planned);
  for (std::size_t k = 0; k < samePart.size(); ++k) {
    if (samePart[k] >= 0) s->plans[k] = previous->plans[static_cast<std::size_t>(samePart[k])];
  }
  const std::size_t n = s->inputs.entries.size();
  s->outcomes.resize(n);
  s->entryKeys.resize(n);
  std::vector<std::size_t> todo;
  std::vector<long> counterpart(n, -1);
  for (std::size_t k = 0; k < n; ++k) {
    const BlockInputs::Entry& e = s->inputs.entries[k];
    const auto it = before.find({e.blockKey, e.part});
    if (it != before.end()) {
      const std::size_t p = it->second;
      counterpart[k] = static_cast<long>(p);
      if (sameVertices(e.shape, previous->inputs.entries[p].shape) &&
          sameWidths(s->inputs.widths[k], previous->inputs.widths[p]) && s->plans[k] == previous->plans[p]) {
        s->outcomes[k] = previous->outcomes[p];
        s->entryKeys[k] = previous->entryKeys[p];
        continue;
      }
    }
    todo.push_back(k);
  }
  // A block whose key is new (its faces or the streets it faces changed)
  // inherits from the block gone from the network that it overlaps most.
  std::vector<std::size_t> gone;
  if (previous) {
    for (std::size_t p = 0; p < previous->inputs.entries.size(); ++p) {
      if (keys.count(previous->inputs.entries[p].blockKey) == 0) gone.push_back(p);
    }
  }
  for (std::size_t k : todo) {
    if (counterpart[k] >= 0 || gone.empty()) continue;
    const Polygon& shape = s->inputs.entries[k].shape;
    const Box box = bounds(shape);
    double most = 0;
    for (std::size_t p : gone) {
      const Polygon& old = previous->inputs.entries[p].shape;
      const Box b = bounds(old);
      if (b.minX > box.maxX || box.minX > b.maxX || b.minY > box.maxY || box.minY > b.maxY) continue;
      const double shared = geos::intersectionArea(shape, old);
      if (shared > most) {
        most = shared;
        counterpart[k] = static_cast<long>(p);
      }
    }
  }

  const double minFrontage = generation::obbParametersFrom(request_.parameters).minFrontage;
  auto lap = std::chrono::steady_clock::now();
  auto seconds = [&lap] {
    const auto now = std::chrono::steady_clock::now();
    return std::chrono::duration<double>(now - std::exchange(lap, now)).count();
  };
  // Locked parcels of a block's counterpart that still lie inside the block
  // stay as they are; the rest of the block is subdivided around them.
  std::vector<std::vector<Key>> anchoredKeys(n);
  parallelFor(todo.size(), [&](std::size_t t) {
    const std::size_t k = todo[t];
    std::vector<Polygon> anchored;
    if (counterpart[k] >= 0 && !attributes.locked.empty()) {
      const std::size_t p = static_cast<std::size_t>(counterpart[k]);
      const std::vector<Polygon>& then = previous->outcomes[p]->subdivision.parcels;
      for (std::size_t i = 0; i < then.size(); ++i) {
        const Key key = previous->entryKeys[p][i];
        if (!attributes.locked.count(key)) continue;
        if (geos::intersectionArea(then[i], s->inputs.entries[k].shape) < (1 - 1e-9) * area(then[i])) continue;
        anchored.push_back(then[i]);
        anchoredKeys[k].push_back(key);
      }
    }
    s->outcomes[k] = std::make_shared<const BlockOutcome>(
        anchored.empty() ? runBlock(s->inputs, k, s->plans[k], minFrontage)
                         : runAround(s->inputs, k, s->plans[k], std::move(anchored), minFrontage));
  });

  const double subdivideSeconds = seconds();
  // Keys: a regenerated block's parcels inherit those of the parcels they
  // match in its counterpart; a key goes to one parcel only (a block split in
  // two passes each key to one of them).
  std::vector<bool> regenerated(n, false);
  for (std::size_t k : todo) regenerated[k] = true;
  // The keys taken: those of the blocks kept and of the anchored parcels
  // (sorted), then those inherited here.
  std::vector<Key> kept;
  for (std::size_t k = 0; k < n; ++k) {
    if (!regenerated[k]) kept.insert(kept.end(), s->entryKeys[k].begin(), s->entryKeys[k].end());
    kept.insert(kept.end(), anchoredKeys[k].begin(), anchoredKeys[k].end());
  }
  std::sort(kept.begin(), kept.end());
  std::unordered_set<Key> inheritedKeys;
  auto take = [&](Key key) {
    return !std::binary_search(kept.begin(), kept.end(), key) && inheritedKeys.insert(key).second;
  };
  // Each regenerated block's parcels matched to its counterpart's (blocks in parallel).
  std::vector<generation::ParcelMatches> matches(todo.size());
  parallelFor(todo.size(), [&](std::size_t t) {
    const std::size_t k = todo[t];
    if (counterpart[k] < 0) return;
    const std::size_t p = static_cast<std::size_t>(counterpart[k]);
    matches[t] = generation::matchParcels(previous->inputs.entries[p].shape, previous->outcomes[p]->subdivision.parcels,
                                          s->inputs.entries[k].shape, s->outcomes[k]->subdivision.parcels);
  });
  std::int64_t parcelsAfter = 0, matched = 0;
  std::set<std::size_t> involved;  // entries before whose parcels were replaced
  for (std::size_t t = 0; t < todo.size(); ++t) {
    const std::size_t k = todo[t];
    const BlockInputs::Entry& e = s->inputs.entries[k];
    const std::vector<Polygon>& now = s->outcomes[k]->subdivision.parcels;
    std::vector<Key>& out = s->entryKeys[k];
    out.resize(now.size());
    for (std::size_t i = 0; i < now.size(); ++i) out[i] = freshKey(e.blockKey, e.part, serial_, i);
    // The anchored parcels come first, with their keys.
    std::copy(anchoredKeys[k].begin(), anchoredKeys[k].end(), out.begin());
    matched += static_cast<std::int64_t>(anchoredKeys[k].size());
    parcelsAfter += static_cast<std::int64_t>(now.size());
    if (counterpart[k] < 0) continue;
    const std::size_t p = static_cast<std::size_t>(counterpart[k]);
    involved.insert(p);
    const generation::ParcelMatches& m = matches[t];
    for (std::size_t i = anchoredKeys[k].size(); i < now.size(); ++i) {
      if (m.before[i] < 0) continue;
      const Key inherited = previous->entryKeys[p][static_cast<std::size_t>(m.before[i])];
      if (!take(inherited)) continue;
      out[i] = inherited;
      ++matched;
    }
  }
  for (std::size_t p : gone) involved.insert(p);
  if (report) {
    report->secondsSubdivide = subdivideSeconds;
    report->secondsMatch = seconds();
    for (std::size_t p : involved) {
      report->parcelsBefore += static_cast<std::int64_t>(previous->outcomes[p]->subdivision.parcels.size());
    }
    report->parcelsAfter = parcelsAfter;
    report->matched = matched;
    for (std::size_t k : todo) report->blocksAffected.push_back(s->inputs.entries[k].blockKey);
    for (std::size_t p : gone) report->blocksRemoved.push_back(previous->inputs.entries[p].blockKey);
    for (auto* list : {&report->blocksAffected, &report->blocksRemoved}) {
      std::sort(list->begin(), list->end());
      list->erase(std::unique(list->begin(), list->end()), list->end());
    }
  }

  std::vector<const BlockOutcome*> pointers;
  for (const auto& o : s->outcomes) pointers.push_back(o.get());
  s->parcels =
      assembleParcels(s->inputs, s->plans, pointers, static_cast<std::uint64_t>(request_.parameters.at("seed")));
  s->parcelKeys.assign(s->parcels.parcels.size(), 0);
  for (std::size_t k = 0; k < s->parcels.blocks.size(); ++k) {
    const std::vector<int>& indices = s->parcels.blocks[k].parcels;
    for (std::size_t i = 0; i < indices.size() && i < s->entryKeys[k].size(); ++i) {
      s->parcelKeys[static_cast<std::size_t>(indices[i])] = s->entryKeys[k][i];
    }
  }
  // Labels and locks follow their parcels' keys; a parcel gone takes them with it.
  if (!attributes.labels.empty() || !attributes.locked.empty()) {
    std::vector<Key> present = s->parcelKeys;
    std::sort(present.begin(), present.end());
    auto isPresent = [&](Key key) { return std::binary_search(present.begin(), present.end(), key); };
    auto& labels = attributes.labels;
    for (auto it = labels.begin(); it != labels.end();) it = isPresent(it->first) ? std::next(it) : labels.erase(it);
    auto& locked = attributes.locked;
    for (auto it = locked.begin(); it != locked.end();) it = isPresent(*it) ? std::next(it) : locked.erase(it);
  }
  s->attributes = std::move(attributes);
  return s;
}

StreetEditor::StreetEditor(const GenerateRequest& request, const ProgressFn& progress) : request_(request) {
  if (!request_.streets) throw usageError("editing needs a street network (--streets)");
  if (request_.fromParcels) throw usageError("editing works on a street network without observed parcels");
  for (const ParameterDescription& d : streetParameters()) request_.parameters.emplace(d.name, d.defaultValue);
  request_.parameters.emplace("seed", 1.0);
  auto network = std::make_shared<StreetNetwork>(
      buildStreetNetwork(*request_.streets, request_.parameters, nullptr, scaledProgress(progress, 0, 0.5)));
  network->blocks = analysis::streetBlocks(network->graph, blockOptions(), {}, &cache_);  // the same, cached
  current_ = build(network, request_.overrides, {}, nullptr, nullptr);
  reportProgress(progress, 1.0, "subdividing");
}

StreetEditor::StreetEditor(const CompareRequest& request, std::shared_ptr<const ObservedData> observed,
                           const ProgressFn& progress)
    : request_(detail::generateRequest(request, observed.get())), observed_(std::move(observed)) {
  if (!observed_ || !observed_->streets) throw usageError("editing needs a street network (--streets)");
  request_.streets = request.streets;
  for (const ParameterDescription& d : streetParameters()) request_.parameters.emplace(d.name, d.defaultValue);
  request_.parameters.emplace("seed", 1.0);
  // The values each block part takes from its observed parcels, as generate() derives them.
  GenerateRequest derive = request_;
  derive.fromParcels = true;
  derive.observed = observed_.get();
  derive.overrides.clear();
  derive.overridesById.clear();
  BlockInputs inputs = prepareBlocks(derive, scaledProgress(progress, 0, 0.3));
  for (BlockInputs::Entry& e : inputs.entries) {
    e.shape = {};
    derived_.emplace(std::make_pair(e.blockKey, e.part), std::move(e));
  }
  // The network as compared, its blocks from the cache from now on.
  auto network = std::make_shared<StreetNetwork>(*observed_->streets);
  network->blocks = analysis::streetBlocks(network->graph, blockOptions(), {}, &cache_);
  request_.fromParcels = false;
  request_.observed = nullptr;
  current_ = build(network, request_.overrides, {}, nullptr, nullptr);
  reportProgress(progress, 1.0, "subdividing");
}

StreetEditor::~StreetEditor() = default;

StreetEditor::Snapshot StreetEditor::snapshot() const {
  Snapshot s;
  s.state_ = current_;
  return s;
}
const StreetNetwork& StreetEditor::Snapshot::network() const { return *state_->network; }
const GeneratedParcels& StreetEditor::Snapshot::parcels() const { return state_->parcels; }
const std::vector<Key>& StreetEditor::Snapshot::parcelKeys() const { return state_->parcelKeys; }
const std::map<Key, std::string>& StreetEditor::Snapshot::labels() const { return state_->attributes.labels; }
const std::set<Key>& StreetEditor::Snapshot::locked() const { return state_->attributes.locked; }
const BlockOverrides& StreetEditor::Snapshot::overrides() const { return state_->overrides; }

analysis::StreetBlockOptions StreetEditor::blockOptions() const {
  analysis::StreetBlockOptions options;
  options.maxArea = request_.parameters.at("max-block-area");
  return options;
}

EditReport StreetEditor::apply(const StreetEdit& edit) {
  const auto started = std::chrono::steady_clock::now();
  EditReport report;
  report.op = editOpName(edit.op);
  if (edit.op == StreetEdit::Op::SetLabel || edit.op == StreetEdit::Op::SetLock) {
    if (edit.op == StreetEdit::Op::SetLabel) {
      setLabel(edit.parcel, edit.label);
    } else {
      setLock(edit.parcel, edit.locked);
    }
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return report;
  }
  const State& now = *current_;
  BlockOverrides overrides = now.overrides;
  std::shared_ptr<const StreetNetwork> network = now.network;
  if (edit.op == StreetEdit::Op::SetBlock) {
    if (std::none_of(now.inputs.entries.begin(), now.inputs.entries.end(),
                     [&](const BlockInputs::Entry& e) { return e.blockKey == edit.block; })) {
      throw usageError("the network has no block " + keyText(edit.block));
    }
    if (edit.style.empty() && edit.parameters.empty()) {
      overrides.erase(edit.block);
    } else {
      overrides[edit.block] = {edit.style, edit.parameters};
    }
  } else {
    // Everything but the blocks, which are built again below.
    auto edited = std::make_shared<StreetNetwork>();
    edited->layer = network->layer;
    edited->graph = network->graph;
    edited->widthsGiven = network->widthsGiven;
    edited->widthsMeasured = network->widthsMeasured;
    edited->widthsDefault = network->widthsDefault;
    edited->boundaryLines = network->boundaryLines;
    edited->timings = network->timings;
    analysis::RoadGraph& g = edited->graph;
    switch (edit.op) {
      case StreetEdit::Op::MoveNode: {
        const Point to = edit.to;
        moveNodes(g, {indexOf(g.nodes, edit.node)}, [&](const Point&) { return to; });
        break;
      }
      case StreetEdit::Op::MoveEdge: {
        const std::size_t e = indexOf(g.edges, edit.edge);
        const Point by = edit.by;
        auto move = [&](const Point& p) { return Point{p.x + by.x, p.y + by.y}; };
        moveNodes(g, {static_cast<std::size_t>(g.edges[e].from), static_cast<std::size_t>(g.edges[e].to)}, move);
        break;
      }
      case StreetEdit::Op::SetWidth: {
        const std::size_t e = indexOf(g.edges, edit.edge);
        if (!std::isfinite(edit.width) || edit.width <= 0 || edit.width > io::kMaxStreetWidth) {
          throw usageError("edge " + keyText(edit.edge) + ": a width must be a positive number of metres, at most " +
                           std::to_string(static_cast<int>(io::kMaxStreetWidth)));
        }
        if (g.edges[e].boundary)
          throw usageError("edge " + keyText(edit.edge) + " is the study area's edge, not a street");
        g.edges[e].width = edit.width;
        break;
      }
      case StreetEdit::Op::SetCurve:
        if (edit.controls) {
          for (const Point& c : *edit.controls) requireWithinReach(c, "a control point lies");
        }
        analysis::setCurve(g, indexOf(g.edges, edit.edge), edit.controls);
        break;
      case StreetEdit::Op::TransformNodes: {
        if (!(edit.scale > 0) || !std::isfinite(edit.scale) || !std::isfinite(edit.rotate)) {
          throw usageError("transform_nodes: the scale must be positive and the rotation finite");
        }
        std::set<std::size_t> nodes;
        for (Key k : edit.nodes) nodes.insert(indexOf(g.nodes, k));
        const double a = edit.rotate * M_PI / 180.0, c = std::cos(a) * edit.scale, s = std::sin(a) * edit.scale;
        const Point o = edit.centre, by = edit.by;
        moveNodes(g, nodes, [&](const Point& p) {
          const double x = p.x - o.x, y = p.y - o.y;
          return Point{o.x + c * x - s * y + by.x, o.y + s * x + c * y + by.y};
        });
        break;
      }
      case StreetEdit::Op::InsertNode: {
        const std::size_t e = indexOf(g.edges, edit.edge);
        requireWithinReach(edit.to, "the point of insert_node lies");  // NaN cut nowhere and changed nothing
        const analysis::RoadEdge& x = g.edges[e];
        // The point of the edge nearest `to`, and the edge cut there in two.
        std::size_t segment = 0;
        Point at = x.line.front();
        double nearest = HUGE_VAL;
        for (std::size_t i = 0; i + 1 < x.line.size(); ++i) {
          const Point a = x.line[i], b = x.line[i + 1];
          const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
          const double t = l2 > 0 ? std::clamp(((edit.to.x - a.x) * dx + (edit.to.y - a.y) * dy) / l2, 0.0, 1.0) : 0;
          const Point p{a.x + t * dx, a.y + t * dy};
          const double d = std::hypot(p.x - edit.to.x, p.y - edit.to.y);
          if (d < nearest) {
            nearest = d;
            at = p;
            segment = i;
          }
        }
        std::vector<Point> first(x.line.begin(), x.line.begin() + static_cast<long>(segment) + 1), second{at};
        first.push_back(at);
        second.insert(second.end(), x.line.begin() + static_cast<long>(segment) + 1, x.line.end());
        g = renoded(g, {e},
                    {{first, x.width, x.name, x.noNode, mixKeys(x.key, 1), false},
                     {second, x.width, x.name, x.noNode, mixKeys(x.key, 2), false}},
                    request_.parameters.at("street-snap"));
        break;
      }
      case StreetEdit::Op::AddStreet: {
        auto end = [&](Key node, const Point& p) { return node ? g.nodes[indexOf(g.nodes, node)].at : p; };
        if (!std::isfinite(edit.width) || edit.width <= 0 || edit.width > io::kMaxStreetWidth) {
          throw usageError("add_street: a width must be a positive number of metres, at most " +
                           std::to_string(static_cast<int>(io::kMaxStreetWidth)));
        }
        const Point a = end(edit.node, edit.from), b = end(edit.node2, edit.to);
        if (a.x == b.x && a.y == b.y) throw usageError("add_street: the street's ends are one point");
        g = renoded(g, {}, {{{a, b}, edit.width, edit.name, false, hashBytes("added street"), false}},
                    request_.parameters.at("street-snap"));
        break;
      }
      case StreetEdit::Op::DeleteStreet: {
        const std::size_t e = indexOf(g.edges, edit.edge);
        if (g.edges[e].boundary)
          throw usageError("edge " + keyText(edit.edge) + " is the study area's edge, not a street");
        g = renoded(g, {e}, {}, request_.parameters.at("street-snap"));
        break;
      }
      case StreetEdit::Op::SetBlock:
      case StreetEdit::Op::SetLabel:
      case StreetEdit::Op::SetLock:
        break;
    }
    // Every node and street still at a finite place within reach (a scale of
    // 1e12 gave coordinates of NaN).
    for (const analysis::RoadNode& n : g.nodes) requireWithinReach(n.at, "the edit moves a node");
    for (const analysis::RoadEdge& e : g.edges) {
      for (const Point& p : e.line) requireWithinReach(p, "the edit moves a street");
    }
    const auto blocksStarted = std::chrono::steady_clock::now();
    if (cache_.faces.size() > 8 * std::max<std::size_t>(1, network->blocks.blocks.size())) cache_ = {};
    edited->blocks = analysis::streetBlocks(g, blockOptions(), {}, &cache_);
    report.secondsBlocks = std::chrono::duration<double>(std::chrono::steady_clock::now() - blocksStarted).count();
    network = std::move(edited);
  }
  // The depth of the state this edit makes: an edit undone and made again
  // (as a drag does with each move) gives its new parcels the same keys.
  serial_ = undo_.size() + 1;
  std::shared_ptr<const State> next = build(network, std::move(overrides), now.attributes, &now, &report);
  undo_.push_back(current_);
  redo_.clear();
  current_ = std::move(next);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

namespace {

// Moves the current state onto `onto` and takes the last of `from` as current.
template <typename Stack, typename State>
bool step(Stack& from, Stack& onto, State& current) {
  if (from.empty()) return false;
  onto.push_back(std::move(current));
  current = std::move(from.back());
  from.pop_back();
  return true;
}

}  // namespace

bool StreetEditor::undo() { return step(undo_, redo_, current_); }
bool StreetEditor::redo() { return step(redo_, undo_, current_); }

std::size_t StreetEditor::undoSize() const { return undo_.size(); }
std::size_t StreetEditor::redoSize() const { return redo_.size(); }

void StreetEditor::changeAttributes(Key parcel, const std::function<void(Attributes&)>& change) {
  const State& now = *current_;
  if (std::find(now.parcelKeys.begin(), now.parcelKeys.end(), parcel) == now.parcelKeys.end()) {
    throw usageError("no parcel " + keyText(parcel));
  }
  auto next = std::make_shared<State>(now);
  change(next->attributes);
  undo_.push_back(current_);
  redo_.clear();
  current_ = std::move(next);
}

void StreetEditor::setLabel(Key parcel, const std::string& label) {
  changeAttributes(parcel, [&](Attributes& a) {
    if (label.empty()) {
      a.labels.erase(parcel);
    } else {
      a.labels[parcel] = label;
    }
  });
}

void StreetEditor::setLock(Key parcel, bool locked) {
  changeAttributes(parcel, [&](Attributes& a) {
    if (locked) {
      a.locked.insert(parcel);
    } else {
      a.locked.erase(parcel);
    }
  });
}

GeneratedParcels StreetEditor::freshParcels() const {
  return build(current_->network, current_->overrides, {}, nullptr, nullptr)->parcels;
}

const StreetNetwork& StreetEditor::network() const { return *current_->network; }
const GeneratedParcels& StreetEditor::parcels() const { return current_->parcels; }
const std::vector<Key>& StreetEditor::parcelKeys() const { return current_->parcelKeys; }
const std::map<Key, std::string>& StreetEditor::labels() const { return current_->attributes.labels; }
const std::set<Key>& StreetEditor::locked() const { return current_->attributes.locked; }
const BlockOverrides& StreetEditor::overrides() const { return current_->overrides; }
Point StreetEditor::toLocal(const Point& source) const {
  return current_->network->layer.frame.toLocal(source.x, source.y);
}

namespace {

// One edit of an edits file; `where` names it in errors.
StreetEdit readEdit(const Json& j, const std::string& where, const std::function<Point(const Point&)>& toLocal) {
  auto bad = [&](const std::string& what) { return inputError(where + ": " + what); };
  if (!j.isObject()) throw bad("an edit is an object {\"op\": ...}");
  auto member = [&](const char* name) -> const Json& {
    const Json* v = j.find(name);
    if (!v || v->isNull()) throw bad(std::string("member ") + name + " is missing");
    return *v;
  };
  auto number = [&](const char* name) {
    const Json& v = member(name);
    if (!v.isNumber()) throw bad(std::string("member ") + name + " is not a number");
    return v.number();
  };
  auto key = [&](const Json& v, const std::string& name) {
    const std::optional<Key> k = v.isString() ? parseKey(v.string()) : std::nullopt;
    if (!k) throw bad("member " + name + " is not a key (16 hexadecimal digits)");
    return *k;
  };
  auto point = [&](const Json& v, const std::string& name, bool local) {
    const std::vector<Json> xy = v.elements();
    if (!v.isArray() || xy.size() != 2 || !xy[0].isNumber() || !xy[1].isNumber()) {
      throw bad("member " + name + " is not a point [x, y]");
    }
    const Point p{xy[0].number(), xy[1].number()};
    return local ? toLocal(p) : p;
  };
  // A displacement in the input's CRS: the difference of two converted points.
  auto vector = [&](const Json& v, const std::string& name) {
    const Point d = point(v, name, false);
    const Point a = toLocal({0, 0}), b = toLocal(d);
    return Point{b.x - a.x, b.y - a.y};
  };
  const Json& op = member("op");
  if (!op.isString()) throw bad("member op is not a string");
  StreetEdit e;
  const std::string& name = op.string();
  if (name == "move_node") {
    e.op = StreetEdit::Op::MoveNode;
    e.node = key(member("node"), "node");
    e.to = point(member("to"), "to", true);
  } else if (name == "move_edge") {
    e.op = StreetEdit::Op::MoveEdge;
    e.edge = key(member("edge"), "edge");
    e.by = vector(member("by"), "by");
  } else if (name == "set_width") {
    e.op = StreetEdit::Op::SetWidth;
    e.edge = key(member("edge"), "edge");
    e.width = number("width");
  } else if (name == "set_curve") {
    e.op = StreetEdit::Op::SetCurve;
    e.edge = key(member("edge"), "edge");
    if (const Json* c = j.find("controls"); c && !c->isNull()) {
      const std::vector<Json> pair = c->elements();
      if (pair.size() != 2) throw bad("member controls is not two points");
      e.controls = std::array<Point, 2>{point(pair[0], "controls", true), point(pair[1], "controls", true)};
    }
  } else if (name == "transform_nodes") {
    e.op = StreetEdit::Op::TransformNodes;
    const Json& nodes = member("nodes");
    if (!nodes.isArray()) throw bad("member nodes is not a list of keys");
    for (const Json& n : nodes.elements()) e.nodes.push_back(key(n, "nodes"));
    e.centre = j.find("centre") ? point(member("centre"), "centre", true) : toLocal({0, 0});
    if (j.find("by")) e.by = vector(member("by"), "by");
    if (j.find("rotate")) e.rotate = number("rotate");
    if (j.find("scale")) e.scale = number("scale");
  } else if (name == "set_block") {
    e.op = StreetEdit::Op::SetBlock;
    e.block = key(member("block"), "block");
    if (const Json* st = j.find("style"); st && !st->isNull()) {
      if (!st->isString()) throw bad("member style is not a string");
      e.style = st->string();
    }
    if (const Json* ps = j.find("parameters"); ps && !ps->isNull()) {
      if (!ps->isObject()) throw bad("member parameters is not an object");
      for (const auto& [k, v] : ps->members()) {
        if (!v.isNumber()) throw bad("parameter " + k + " is not a number");
        e.parameters[k] = v.number();
      }
    }
  } else if (name == "insert_node") {
    e.op = StreetEdit::Op::InsertNode;
    e.edge = key(member("edge"), "edge");
    e.to = point(member("at"), "at", true);
  } else if (name == "add_street") {
    e.op = StreetEdit::Op::AddStreet;
    // Each end a node's key or a point.
    auto endOf = [&](const char* name, Key& node, Point& at) {
      const Json& v = member(name);
      if (v.isString()) {
        node = key(v, name);
      } else {
        at = point(v, name, true);
      }
    };
    endOf("from", e.node, e.from);
    endOf("to", e.node2, e.to);
    e.width = number("width");
    if (const Json* n = j.find("name"); n && n->isString()) e.name = n->string();
  } else if (name == "delete_street") {
    e.op = StreetEdit::Op::DeleteStreet;
    e.edge = key(member("edge"), "edge");
  } else if (name == "set_lock") {
    e.op = StreetEdit::Op::SetLock;
    e.parcel = key(member("parcel"), "parcel");
    if (const Json* v = j.find("locked"); v && !v->isNull()) {
      try {
        e.locked = v->boolean();
      } catch (const std::logic_error&) {
        throw bad("member locked is not true or false");
      }
    }
  } else if (name == "set_label") {
    e.op = StreetEdit::Op::SetLabel;
    e.parcel = key(member("parcel"), "parcel");
    const Json& label = member("label");
    if (!label.isString()) throw bad("member label is not a string");
    e.label = label.string();
  } else {
    throw bad("op '" + name +
              "' is not an edit (move_node, move_edge, set_width, set_curve, transform_nodes, insert_node, add_street, "
              "delete_street, set_block, set_label, set_lock)");
  }
  return e;
}

}  // namespace

std::vector<StreetEdit> readEdits(const std::string& path, const std::function<Point(const Point&)>& toLocal) {
  const Json root = io::readJson(path);
  if (!root.isArray()) throw inputError(path + ": an edits file holds a list of edits");
  std::vector<StreetEdit> edits;
  const std::vector<Json> list = root.elements();
  for (std::size_t i = 0; i < list.size(); ++i) {
    edits.push_back(readEdit(list[i], path + ": edit " + std::to_string(i), toLocal));
  }
  return edits;
}

Json editsJson(const std::vector<StreetEdit>& edits, const io::LocalFrame& frame) {
  const auto point = [&](const Point& local) {
    const Point p = frame.toSource(local);
    return Json::array().push(p.x).push(p.y);
  };
  // readEdit's displacement is toLocal(d) - toLocal(0, 0): its inverse.
  const Point zero = frame.toLocal(0, 0);
  const auto vector = [&](const Point& by) { return point({by.x + zero.x, by.y + zero.y}); };
  Json list = Json::array();
  for (const StreetEdit& e : edits) {
    Json j = Json::object().set("op", editOpName(e.op));
    switch (e.op) {
      case StreetEdit::Op::MoveNode:
        j.set("node", keyText(e.node)).set("to", point(e.to));
        break;
      case StreetEdit::Op::MoveEdge:
        j.set("edge", keyText(e.edge)).set("by", vector(e.by));
        break;
      case StreetEdit::Op::SetWidth:
        j.set("edge", keyText(e.edge)).set("width", e.width);
        break;
      case StreetEdit::Op::SetCurve:
        j.set("edge", keyText(e.edge));
        j.set("controls",
              e.controls ? Json::array().push(point((*e.controls)[0])).push(point((*e.controls)[1])) : Json());
        break;
      case StreetEdit::Op::TransformNodes: {
        Json nodes = Json::array();
        for (Key k : e.nodes) nodes.push(keyText(k));
        j.set("nodes", nodes).set("centre", point(e.centre)).set("by", vector(e.by));
        j.set("rotate", e.rotate).set("scale", e.scale);
        break;
      }
      case StreetEdit::Op::SetBlock: {
        Json parameters = Json::object();
        for (const auto& [name, value] : e.parameters) parameters.set(name, value);
        j.set("block", keyText(e.block)).set("style", e.style).set("parameters", parameters);
        break;
      }
      case StreetEdit::Op::SetLabel:
        j.set("parcel", keyText(e.parcel)).set("label", e.label);
        break;
      case StreetEdit::Op::InsertNode:
        j.set("edge", keyText(e.edge)).set("at", point(e.to));
        break;
      case StreetEdit::Op::AddStreet:
        j.set("from", e.node != 0 ? Json(keyText(e.node)) : point(e.from));
        j.set("to", e.node2 != 0 ? Json(keyText(e.node2)) : point(e.to));
        j.set("width", e.width).set("name", e.name);
        break;
      case StreetEdit::Op::DeleteStreet:
        j.set("edge", keyText(e.edge));
        break;
      case StreetEdit::Op::SetLock:
        j.set("parcel", keyText(e.parcel)).set("locked", e.locked);
        break;
    }
    list.push(j);
  }
  return list;
}

void writeEdits(const std::string& path, const std::vector<StreetEdit>& edits, const io::LocalFrame& frame,
                const std::vector<std::string>& inputs) {
  io::StagedFile file(path, inputs);
  io::writeJson(file.path(), editsJson(edits, frame));
  file.commit();
}

Table persistenceTable(const std::vector<EditReport>& reports) {
  Table t;
  using T = Column::Type;
  t.columns = {{"edit", T::Integer, ""},
               {"op", T::String, ""},
               {"blocks_affected", T::Integer, ""},
               {"blocks_removed", T::Integer, ""},
               {"parcels_before", T::Integer, ""},
               {"parcels_after", T::Integer, ""},
               {"keys_kept", T::Integer, ""},
               {"keys_kept_share", T::Real, ""},
               {"seconds", T::Real, "s"},
               {"seconds_blocks", T::Real, "s"},
               {"seconds_subdivide", T::Real, "s"},
               {"seconds_match", T::Real, "s"},
               {"affected_block_keys", T::String, ""}};
  for (std::size_t i = 0; i < reports.size(); ++i) {
    const EditReport& r = reports[i];
    std::string keys;
    for (Key k : r.blocksAffected) keys += (keys.empty() ? "" : ";") + keyText(k);
    t.rows.push_back(
        {static_cast<std::int64_t>(i), r.op, static_cast<std::int64_t>(r.blocksAffected.size()),
         static_cast<std::int64_t>(r.blocksRemoved.size()), r.parcelsBefore, r.parcelsAfter, r.matched,
         r.parcelsBefore > 0 ? static_cast<double>(r.matched) / static_cast<double>(r.parcelsBefore) : std::nan(""),
         r.seconds, r.secondsBlocks, r.secondsSubdivide, r.secondsMatch, keys});
  }
  return t;
}

Table editedParcelTable(const StreetEditor& editor, std::vector<std::vector<Polygon>>* geometries) {
  Table t = generatedParcelTable(editor.parcels(), geometries);
  const std::size_t keyColumn = t.column("parcel_key");
  t.columns.push_back({"label", Column::Type::String, ""});
  t.columns.push_back({"locked", Column::Type::Integer, ""});
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const Key k = editor.parcelKeys()[i];
    t.rows[i][keyColumn] = keyText(k);
    const auto it = editor.labels().find(k);
    t.rows[i].push_back(it == editor.labels().end() ? std::string() : it->second);
    t.rows[i].push_back(static_cast<std::int64_t>(editor.locked().count(k)));
  }
  return t;
}

namespace {

// runEdit with the editor `make` builds (given its share of the progress).
JobOutcome runEditWith(const std::function<std::unique_ptr<StreetEditor>(const ProgressFn&)>& make,
                       const std::string& style, const ParameterValues& parameters, std::vector<std::string> inputs,
                       const std::string& editsPath, const std::string& outDir, const ProgressFn& progress) {
  inputs.push_back(editsPath);
  io::OutputDirectory out(outDir, inputs);
  try {
    const std::unique_ptr<StreetEditor> made = make(scaledProgress(progress, 0.0, 0.3));
    StreetEditor& editor = *made;
    const std::vector<StreetEdit> edits = readEdits(editsPath, [&](const Point& p) { return editor.toLocal(p); });
    std::vector<EditReport> reports;
    for (std::size_t i = 0; i < edits.size(); ++i) {
      reportProgress(progress, 0.3 + 0.6 * static_cast<double>(i) / static_cast<double>(edits.size()), "editing");
      try {
        reports.push_back(editor.apply(edits[i]));
      } catch (const Error& e) {
        // An edit the editor refuses is bad content of the edits file: an
        // input error (exit 1, one line), whatever the editor calls it.
        const Error::Kind kind = e.kind() == Error::Kind::Usage ? Error::Kind::Input : e.kind();
        throw Error(kind,
                    editsPath + ": edit " + std::to_string(i) + " (" + editOpName(edits[i].op) + "): " + e.what());
      }
    }
    reportProgress(progress, 0.9, "writing");
    std::vector<std::vector<Polygon>> geometries;
    const Table parcels = editedParcelTable(editor, &geometries);
    const GeneratedParcels& g = editor.parcels();
    auto written = writeStreetLayers(out, editor.network());
    written.emplace_back("parcels.gpkg", io::writePolygonLayer(out.stage("parcels.gpkg"), "parcels", geometries,
                                                               parcels, g.source->frame, g.source->crs));
    io::writeCsv(out.stage("persistence.csv"), persistenceTable(reports));
    Json run = runRecord("edit", parameters)
                   .set("style", style)
                   .set("edits",
                        Json::object().set("path", editsPath).set("applied", static_cast<std::int64_t>(reports.size())))
                   .set("counts", Json::object()
                                      .set("blocks", static_cast<std::int64_t>(g.blocks.size()))
                                      .set("parcels", static_cast<std::int64_t>(g.parcels.size()))
                                      .set("labels", static_cast<std::int64_t>(editor.labels().size())));
    run.set("streets", streetRecord(editor.network()));
    run.set("written", writtenLayersJson(written));
    run.set("outputs", Json::array()
                           .push("parcels.gpkg")
                           .push("blocks.gpkg")
                           .push("streets.gpkg")
                           .push("street_surface.gpkg")
                           .push("persistence.csv")
                           .push("run.json"));
    io::writeJson(out.stage("run.json"), run);
    out.commit();
    reportProgress(progress, 1.0, "writing");
    std::int64_t before = 0, kept = 0;
    for (const EditReport& r : reports) {
      before += r.parcelsBefore;
      kept += r.matched;
    }
    std::ostringstream s;
    s << reports.size() << " edits applied to " << editsPath << "'s network: " << g.blocks.size() << " blocks, "
      << g.parcels.size() << " parcels; " << kept << " of " << before
      << " parcels of the blocks the edits subdivided again kept their keys";
    return {run, s.str()};
  } catch (const Error& e) {
    throw out.explain(e);
  }
}

}  // namespace

JobOutcome runEdit(const GenerateRequest& request, const std::string& editsPath, const std::string& outDir,
                   const ProgressFn& progress) {
  std::vector<std::string> inputs;
  if (request.streets) inputs.push_back(request.streets->path);
  return runEditWith([&](const ProgressFn& p) { return std::make_unique<StreetEditor>(request, p); }, request.style,
                     request.parameters, inputs, editsPath, outDir, progress);
}

JobOutcome runEdit(const CompareRequest& request, const std::string& editsPath, const std::string& outDir,
                   const ProgressFn& progress) {
  if (!request.streets) throw usageError("editing needs a street network (--streets)");
  return runEditWith(
      [&](const ProgressFn& p) {
        auto observed = std::make_shared<const ObservedData>(loadObservedInStreetBlocks(
            request.input, &*request.streets, request.parameters, scaledProgress(p, 0, 0.6)));
        return std::make_unique<StreetEditor>(request, observed, scaledProgress(p, 0.6, 1.0));
      },
      request.style, request.parameters, inputPaths(request), editsPath, outDir, progress);
}

}  // namespace parcelscope::pipeline
