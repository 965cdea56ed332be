// Editing the street network: only the blocks an edit changes are
// subdivided again, the others keep their parcels bit for bit; matched
// parcels keep their keys and labels; undo gives back the state before, bit
// for bit; the incremental state is the one a fresh build of the edited
// network gives.
#include "parcelscope/pipeline/StreetEditor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/GeosOps.h"

namespace parcelscope::pipeline {
namespace {

GenerateRequest sampleStreets(const std::string& style = "skeleton") {
  GenerateRequest r;
  r.streets = io::StreetReadOptions{};
  r.streets->path = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_streets.geojson";
  r.streets->widthField = "width";
  r.style = style;
  r.parameters["seed"] = 3;
  return r;
}

// Every block's parcels and keys, by block key.
struct Snapshot {
  std::map<Key, std::vector<Polygon>> parcels;
  std::map<Key, std::vector<Key>> keys;
};

Snapshot snapshot(const StreetEditor& e) {
  Snapshot s;
  const GeneratedParcels& g = e.parcels();
  for (std::size_t b = 0; b < g.blocks.size(); ++b) {
    for (int i : g.blocks[b].parcels) {
      s.parcels[g.blockKeys[b]].push_back(g.parcels[static_cast<std::size_t>(i)]);
      s.keys[g.blockKeys[b]].push_back(e.parcelKeys()[static_cast<std::size_t>(i)]);
    }
  }
  return s;
}

bool sameParcels(const std::vector<Polygon>& a, const std::vector<Polygon>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!test::sameBits(a[i], b[i])) return false;
  }
  return true;
}

bool sameState(const Snapshot& a, const Snapshot& b) {
  if (a.parcels.size() != b.parcels.size() || a.keys != b.keys) return false;
  for (const auto& [key, parcels] : a.parcels) {
    const auto it = b.parcels.find(key);
    if (it == b.parcels.end() || !sameParcels(parcels, it->second)) return false;
  }
  return true;
}

// The node of highest degree (an intersection inside the network).
Key busiestNode(const StreetEditor& e) {
  const auto& nodes = e.network().graph.nodes;
  std::size_t best = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].degree > nodes[best].degree) best = i;
  }
  return nodes[best].key;
}

StreetEdit moveNodeBy(const StreetEditor& e, Key node, double dx, double dy) {
  StreetEdit edit;
  edit.op = StreetEdit::Op::MoveNode;
  edit.node = node;
  for (const auto& n : e.network().graph.nodes) {
    if (n.key == node) edit.to = {n.at.x + dx, n.at.y + dy};
  }
  return edit;
}

TEST(StreetEditor, AMoveRegeneratesOnlyTheBlocksAroundTheNodeAndUndoRestoresEverything) {
  StreetEditor editor(sampleStreets());
  const Snapshot before = snapshot(editor);
  ASSERT_EQ(before.parcels.size(), 10u);
  const Key node = busiestNode(editor);
  const EditReport r = editor.apply(moveNodeBy(editor, node, 2, 1));
  ASSERT_FALSE(r.blocksAffected.empty());
  EXPECT_LT(r.blocksAffected.size(), before.parcels.size());
  EXPECT_TRUE(r.blocksRemoved.empty());
  const Snapshot after = snapshot(editor);
  // Block keys survive a geometric edit.
  ASSERT_EQ(after.parcels.size(), before.parcels.size());
  for (const auto& [key, parcels] : before.parcels) {
    ASSERT_TRUE(after.parcels.count(key)) << keyText(key);
    const bool affected = std::binary_search(r.blocksAffected.begin(), r.blocksAffected.end(), key);
    if (!affected) {
      EXPECT_TRUE(sameParcels(parcels, after.parcels.at(key))) << keyText(key) << " changed without being affected";
      EXPECT_EQ(before.keys.at(key), after.keys.at(key));
    }
  }
  // After a 2.2 m move most parcels of the affected blocks keep their key.
  EXPECT_GT(r.parcelsBefore, 0);
  EXPECT_GE(static_cast<double>(r.matched), 0.8 * static_cast<double>(std::min(r.parcelsBefore, r.parcelsAfter)))
      << r.matched << " of " << r.parcelsBefore;
  // Undo: the state before, bit for bit; redo: the state after.
  ASSERT_TRUE(editor.undo());
  EXPECT_TRUE(sameState(snapshot(editor), before));
  ASSERT_TRUE(editor.redo());
  EXPECT_TRUE(sameState(snapshot(editor), after));
  EXPECT_FALSE(editor.redo());
}

TEST(StreetEditor, RandomEditsGiveWhatAFreshBuildOfTheEditedNetworkGives) {
  StreetEditor editor(sampleStreets());
  auto rng = test::seededRandom(11, "street edits");
  std::uniform_real_distribution<double> shift(-3, 3);
  std::vector<Key> nodes, edges;
  for (const auto& n : editor.network().graph.nodes) {
    if (n.degree >= 3) nodes.push_back(n.key);
  }
  for (const auto& e : editor.network().graph.edges) {
    if (!e.boundary) edges.push_back(e.key);
  }
  ASSERT_FALSE(nodes.empty());
  for (int step = 0; step < 8; ++step) {
    StreetEdit edit;
    switch (step % 4) {
      case 0:
        edit = moveNodeBy(editor, nodes[rng() % nodes.size()], shift(rng), shift(rng));
        break;
      case 1:
        edit.op = StreetEdit::Op::SetWidth;
        edit.edge = edges[rng() % edges.size()];
        edit.width = 8 + std::fabs(shift(rng)) * 3;
        break;
      case 2:
        edit.op = StreetEdit::Op::MoveEdge;
        edit.edge = edges[rng() % edges.size()];
        edit.by = {shift(rng), shift(rng)};
        break;
      case 3:
        edit.op = StreetEdit::Op::SetBlock;
        edit.block = editor.parcels().blockKeys[rng() % editor.parcels().blockKeys.size()];
        edit.style = step % 2 ? "obb" : "offset";
        break;
    }
    editor.apply(edit);
    const GeneratedParcels fresh = editor.freshParcels();
    const GeneratedParcels& now = editor.parcels();
    ASSERT_EQ(fresh.parcels.size(), now.parcels.size()) << "step " << step;
    for (std::size_t i = 0; i < now.parcels.size(); ++i) {
      ASSERT_TRUE(test::sameBits(fresh.parcels[i], now.parcels[i])) << "step " << step << " parcel " << i;
    }
    // Keys stay unique.
    std::set<Key> keys(editor.parcelKeys().begin(), editor.parcelKeys().end());
    EXPECT_EQ(keys.size(), now.parcels.size()) << "step " << step;
  }
}

TEST(StreetEditor, AWidthChangeTouchesTheBlocksFacingTheStreetAndLabelsFollowTheirParcels) {
  StreetEditor editor(sampleStreets());
  const auto& edges = editor.network().graph.edges;
  const auto street = std::find_if(edges.begin(), edges.end(), [](const auto& e) { return !e.boundary; });
  ASSERT_NE(street, edges.end());
  const Key edge = street->key;
  // Label every parcel, then widen the street by 1 m.
  const std::vector<Key> keys = editor.parcelKeys();
  for (Key k : keys) editor.setLabel(k, "lot " + keyText(k));
  StreetEdit widen;
  widen.op = StreetEdit::Op::SetWidth;
  widen.edge = edge;
  widen.width = street->width + 1;
  const EditReport r = editor.apply(widen);
  ASSERT_FALSE(r.blocksAffected.empty());
  // The blocks on either side, and those at its ends where its round end
  // reaches: every affected block lies within the street's width of it.
  Box line{1e300, 1e300, -1e300, -1e300};
  for (const Point& p : street->line) {
    line = {std::min(line.minX, p.x), std::min(line.minY, p.y), std::max(line.maxX, p.x), std::max(line.maxY, p.y)};
  }
  const GeneratedParcels& g = editor.parcels();
  for (Key k : r.blocksAffected) {
    for (std::size_t b = 0; b < g.blocks.size(); ++b) {
      if (g.blockKeys[b] != k) continue;
      const Box x = bounds(g.blocks[b].parts[0]);
      const double gap = std::max({x.minX - line.maxX, line.minX - x.maxX, x.minY - line.maxY, line.minY - x.maxY});
      EXPECT_LE(gap, widen.width) << keyText(k);
    }
  }
  EXPECT_LT(r.blocksAffected.size(), g.blocks.size());
  EXPECT_EQ(static_cast<std::int64_t>(editor.labels().size()),
            static_cast<std::int64_t>(keys.size()) - r.parcelsBefore + r.matched);
  for (const auto& [key, label] : editor.labels()) EXPECT_EQ(label, "lot " + keyText(key));
  // A label on a key no parcel has is refused.
  EXPECT_THROW(editor.setLabel(0x1234, "x"), Error);
}

// Vanegas et al. 2012, Figure 7's six edits on the sample's network, each
// undone: (a) a dead end moved across the next street, enclosing a block;
// (b) a street moved; (c) two streets curved; (d) a street widened; (e) a
// block's style changed; (f) the whole network scaled. Each states the share
// of the affected blocks' parcels that keep their key; each undo gives the
// state before, bit for bit.
TEST(StreetEditor, Figure7sSixEditsKeepMostKeysAndEachUndoRestoresTheStateBefore) {
  StreetEditor editor(sampleStreets());
  const auto& g = editor.network().graph;
  const auto deadEnd = std::find_if(g.nodes.begin(), g.nodes.end(), [](const auto& n) { return n.degree == 1; });
  ASSERT_NE(deadEnd, g.nodes.end()) << "the sample has a cul-de-sac";
  std::vector<Key> streets, all;
  for (const auto& e : g.edges) {
    if (!e.boundary && e.line.size() == 2 && e.from != e.to) streets.push_back(e.key);
  }
  for (const auto& n : g.nodes) all.push_back(n.key);
  ASSERT_GE(streets.size(), 2u);
  const Snapshot start = snapshot(editor);
  const std::size_t blocksBefore = start.parcels.size();

  std::vector<std::pair<std::string, StreetEdit>> edits;
  {
    // (a) The cul-de-sac's end carried on along its street to 5 m past the
    // first street it meets.
    const auto& n = *deadEnd;
    const int index = static_cast<int>(&n - &g.nodes[0]);
    const auto& e =
        *std::find_if(g.edges.begin(), g.edges.end(), [&](const auto& x) { return x.from == index || x.to == index; });
    const Point other = e.from == index ? e.line[1] : e.line[e.line.size() - 2];
    const double l = std::hypot(n.at.x - other.x, n.at.y - other.y);
    const Point u{(n.at.x - other.x) / l, (n.at.y - other.y) / l};
    double nearest = 1e300;  // along u from the dead end to the first street crossed
    for (const auto& x : g.edges) {
      if (&x == &e) continue;
      for (std::size_t i = 0; i + 1 < x.line.size(); ++i) {
        const Point p = x.line[i], q = x.line[i + 1];
        const double den = u.x * (q.y - p.y) - u.y * (q.x - p.x);
        if (std::fabs(den) < 1e-12) continue;
        const double t = ((p.x - n.at.x) * (q.y - p.y) - (p.y - n.at.y) * (q.x - p.x)) / den;
        const double s = ((p.x - n.at.x) * u.y - (p.y - n.at.y) * u.x) / den;
        if (t > 0 && s >= 0 && s <= 1) nearest = std::min(nearest, t);
      }
    }
    ASSERT_LT(nearest, 1e3) << "the cul-de-sac points at a street";
    StreetEdit a;
    a.op = StreetEdit::Op::MoveNode;
    a.node = n.key;
    a.to = {n.at.x + (nearest + 5) * u.x, n.at.y + (nearest + 5) * u.y};
    edits.emplace_back("enclose", a);
  }
  StreetEdit b;
  b.op = StreetEdit::Op::MoveEdge;
  b.edge = streets[0];
  b.by = {2, 1};
  edits.emplace_back("move edge", b);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& e = *std::find_if(g.edges.begin(), g.edges.end(), [&](const auto& x) { return x.key == streets[k]; });
    const Point p = e.line.front(), q = e.line.back();
    const Point n{-(q.y - p.y) * 0.1, (q.x - p.x) * 0.1};  // a tenth of the length sideways
    StreetEdit c;
    c.op = StreetEdit::Op::SetCurve;
    c.edge = e.key;
    c.controls = std::array<Point, 2>{Point{p.x + (q.x - p.x) / 3 + n.x, p.y + (q.y - p.y) / 3 + n.y},
                                      Point{p.x + 2 * (q.x - p.x) / 3 + n.x, p.y + 2 * (q.y - p.y) / 3 + n.y}};
    edits.emplace_back("curve", c);
  }
  StreetEdit d;
  d.op = StreetEdit::Op::SetWidth;
  d.edge = streets[1];
  d.width = 18;
  edits.emplace_back("width", d);
  StreetEdit e;
  e.op = StreetEdit::Op::SetBlock;
  e.block = start.parcels.begin()->first;
  e.style = "obb";
  edits.emplace_back("style", e);
  StreetEdit f;
  f.op = StreetEdit::Op::TransformNodes;
  f.nodes = all;
  f.scale = 1.1;
  edits.emplace_back("scale", f);

  for (const auto& [name, edit] : edits) {
    const Snapshot before = snapshot(editor);
    const EditReport r = editor.apply(edit);
    const double share = r.parcelsBefore > 0 ? static_cast<double>(r.matched) / r.parcelsBefore : 1.0;
    std::printf("  Figure 7 %-10s blocks affected %zu, removed %zu, parcels %lld -> %lld, keys kept %lld (%.0f %%)\n",
                name.c_str(), r.blocksAffected.size(), r.blocksRemoved.size(), static_cast<long long>(r.parcelsBefore),
                static_cast<long long>(r.parcelsAfter), static_cast<long long>(r.matched), 100 * share);
    ASSERT_FALSE(r.blocksAffected.empty()) << name;
    if (name == "enclose") EXPECT_GT(snapshot(editor).parcels.size(), blocksBefore) << "a block was enclosed";
    if (name != "style" && name != "enclose") EXPECT_GE(share, 0.8) << name;
    ASSERT_TRUE(editor.undo());
    EXPECT_TRUE(sameState(snapshot(editor), before)) << name;
    ASSERT_TRUE(editor.redo());
  }
}

// Edits of the topology: a street added across the largest block splits it in
// two (the new blocks inherit its parcels' keys by overlap), deleting it joins
// them again; a node inserted on a street splits the street in two. Each
// undo gives the state before, and the state is a fresh build's.
TEST(StreetEditor, AStreetAddedSplitsABlockDeletedJoinsItAndANodeInsertedSplitsAStreet) {
  StreetEditor editor(sampleStreets());
  const GeneratedParcels& g0 = editor.parcels();
  std::size_t largest = 0;
  for (std::size_t b = 0; b < g0.blocks.size(); ++b) {
    if (area(g0.blocks[b].parts[0]) > area(g0.blocks[largest].parts[0])) largest = b;
  }
  const Key split = g0.blockKeys[largest];
  const Box box = bounds(g0.blocks[largest].parts[0]);
  const double blockArea = area(g0.blocks[largest].parts[0]);
  const std::size_t blocks = g0.blocks.size(), nodes = editor.network().graph.nodes.size(),
                    edges = editor.network().graph.edges.size();
  const Snapshot start = snapshot(editor);

  StreetEdit add;
  add.op = StreetEdit::Op::AddStreet;
  const double y = 0.5 * (box.minY + box.maxY);
  add.from = {box.minX - 30, y};
  add.to = {box.maxX + 30, y};
  add.width = 10;
  add.name = "New Street";
  const EditReport r = editor.apply(add);
  // The block split, and the blocks beside it whose side streets got a node
  // (their faced edges are new) are gone.
  EXPECT_TRUE(std::binary_search(r.blocksRemoved.begin(), r.blocksRemoved.end(), split));
  EXPECT_GE(editor.parcels().blocks.size(), blocks + 1);
  EXPECT_GT(r.matched, 0);
  std::printf("  add_street: blocks %zu -> %zu, parcels %lld -> %lld, keys kept %lld\n", blocks,
              editor.parcels().blocks.size(), static_cast<long long>(r.parcelsBefore),
              static_cast<long long>(r.parcelsAfter), static_cast<long long>(r.matched));
  const GeneratedParcels fresh = editor.freshParcels();
  ASSERT_EQ(fresh.parcels.size(), editor.parcels().parcels.size());
  for (std::size_t i = 0; i < fresh.parcels.size(); ++i)
    ASSERT_TRUE(test::sameBits(fresh.parcels[i], editor.parcels().parcels[i]));
  const Snapshot added = snapshot(editor);

  // Delete it: as many blocks as at the start, the split block whole again.
  StreetEdit remove;
  remove.op = StreetEdit::Op::DeleteStreet;
  for (const auto& e : editor.network().graph.edges) {
    const double x0 = std::min(e.line.front().x, e.line.back().x), x1 = std::max(e.line.front().x, e.line.back().x);
    if (e.name == "New Street" && x0 < box.maxX && x1 > box.minX) remove.edge = e.key;
  }
  ASSERT_NE(remove.edge, 0u);
  editor.apply(remove);
  // The stubs beyond the side streets stay (only the edge across the block was deleted).
  double largestArea = 0;
  for (const Block& b : editor.parcels().blocks) largestArea = std::max(largestArea, area(b.parts[0]));
  EXPECT_NEAR(largestArea, blockArea, 1e-6 * blockArea);
  ASSERT_TRUE(editor.undo());
  EXPECT_TRUE(sameState(snapshot(editor), added));
  ASSERT_TRUE(editor.undo());
  EXPECT_TRUE(sameState(snapshot(editor), start));

  // A node inserted halfway along a street: one node and one edge more, as many blocks.
  const auto& street = *std::find_if(editor.network().graph.edges.begin(), editor.network().graph.edges.end(),
                                     [](const auto& e) { return !e.boundary && e.line.size() == 2; });
  StreetEdit insert;
  insert.op = StreetEdit::Op::InsertNode;
  insert.edge = street.key;
  insert.to = {0.5 * (street.line[0].x + street.line[1].x) + 3, 0.5 * (street.line[0].y + street.line[1].y) + 3};
  const EditReport ri = editor.apply(insert);
  EXPECT_EQ(editor.network().graph.nodes.size(), nodes + 1);
  EXPECT_EQ(editor.network().graph.edges.size(), edges + 1);
  EXPECT_EQ(editor.parcels().blocks.size(), blocks);
  EXPECT_GE(static_cast<double>(ri.matched), 0.8 * static_cast<double>(ri.parcelsBefore));
}

// Keys are drawn from positions to about a metre; a node inserted 1.2 m from
// an intersection shares its key cell. It must not take the intersection's
// key (which the intersection keeps), nor its two streets that of the street
// cut: every node and edge key stays unique, and a move by the intersection's
// key moves the intersection.
TEST(StreetEditor, ANodeInsertedBesideAnotherTakesAKeyOfItsOwn) {
  StreetEditor editor(sampleStreets());
  const Key node = busiestNode(editor);
  const auto& g = editor.network().graph;
  std::size_t at = 0;
  while (g.nodes[at].key != node) ++at;
  const auto street = std::find_if(g.edges.begin(), g.edges.end(), [&](const auto& e) {
    return !e.boundary && e.line.size() == 2 &&
           (static_cast<std::size_t>(e.from) == at || static_cast<std::size_t>(e.to) == at);
  });
  ASSERT_NE(street, g.edges.end());
  const Point from = g.nodes[at].at,
              other = static_cast<std::size_t>(street->from) == at ? street->line.back() : street->line.front();
  const double length = std::hypot(other.x - from.x, other.y - from.y);
  ASSERT_GT(length, 5.0);
  auto unique = [](std::vector<Key> keys) {
    std::sort(keys.begin(), keys.end());
    return std::adjacent_find(keys.begin(), keys.end()) == keys.end();
  };
  for (const double d : {1.2, 0.6, 0.3}) {
    SCOPED_TRACE(d);
    StreetEditor e(sampleStreets());
    StreetEdit insert;
    insert.op = StreetEdit::Op::InsertNode;
    insert.edge = street->key;
    insert.to = {from.x + d * (other.x - from.x) / length, from.y + d * (other.y - from.y) / length};
    e.apply(insert);
    std::vector<Key> nodes, edges;
    for (const auto& n : e.network().graph.nodes) nodes.push_back(n.key);
    for (const auto& x : e.network().graph.edges) edges.push_back(x.key);
    EXPECT_TRUE(unique(nodes)) << "node keys";
    EXPECT_TRUE(unique(edges)) << "edge keys";
    EXPECT_EQ(std::count(edges.begin(), edges.end(), street->key), 0) << "the street cut keeps its key";
    for (const auto& n : e.network().graph.nodes) {
      if (n.key == node) EXPECT_EQ(n.degree, g.nodes[at].degree) << "the intersection keeps its key";
    }
  }
}

// Lipp et al. 2011's anchored assignment: a locked parcel keeps its geometry
// and key when its block is subdivided again around it, and the block is
// still tiled by valid parcels.
TEST(StreetEditor, ALockedParcelKeepsItsGeometryWhileItsBlockIsSubdividedAroundIt) {
  StreetEditor editor(sampleStreets());
  const Key node = busiestNode(editor);
  const StreetEdit move = moveNodeBy(editor, node, 2, 1);
  const EditReport dry = editor.apply(move);
  std::map<Key, Polygon> moved;  // the affected blocks after the move
  for (const auto& b : editor.network().blocks.blocks) moved.emplace(b.key, b.shape);
  ASSERT_TRUE(editor.undo());
  ASSERT_FALSE(dry.blocksAffected.empty());
  // Of the first affected block whose parcel farthest from the node still lies
  // inside it after the move, that parcel.
  const GeneratedParcels& g = editor.parcels();
  Point at;
  for (const auto& n : editor.network().graph.nodes) {
    if (n.key == node) at = n.at;
  }
  Key block = 0;
  int chosen = -1;
  for (const Key candidate : dry.blocksAffected) {
    int farthestParcel = -1;
    double farthest = -1;
    for (std::size_t b = 0; b < g.blocks.size(); ++b) {
      if (g.blockKeys[b] != candidate) continue;
      for (int i : g.blocks[b].parcels) {
        const Point c = centroid(g.parcels[static_cast<std::size_t>(i)]);
        if (std::hypot(c.x - at.x, c.y - at.y) > farthest) {
          farthest = std::hypot(c.x - at.x, c.y - at.y);
          farthestParcel = i;
        }
      }
    }
    const auto m = moved.find(candidate);
    if (farthestParcel < 0 || m == moved.end()) continue;
    const Polygon& p = g.parcels[static_cast<std::size_t>(farthestParcel)];
    if (geos::intersectionArea(p, m->second) >= (1 - 1e-9) * area(p)) {
      block = candidate;
      chosen = farthestParcel;
      break;
    }
  }
  ASSERT_GE(chosen, 0);
  const Key locked = editor.parcelKeys()[static_cast<std::size_t>(chosen)];
  const Polygon shape = g.parcels[static_cast<std::size_t>(chosen)];
  editor.setLock(locked, true);
  editor.apply(move);
  const GeneratedParcels& after = editor.parcels();
  const auto it = std::find(editor.parcelKeys().begin(), editor.parcelKeys().end(), locked);
  ASSERT_NE(it, editor.parcelKeys().end()) << "the locked parcel kept its key";
  EXPECT_TRUE(test::sameBits(after.parcels[static_cast<std::size_t>(it - editor.parcelKeys().begin())], shape));
  EXPECT_EQ(editor.locked().count(locked), 1u);
  for (std::size_t b = 0; b < after.blocks.size(); ++b) {
    if (after.blockKeys[b] != block) continue;
    double sum = 0;
    for (int i : after.blocks[b].parcels) {
      const Polygon& p = after.parcels[static_cast<std::size_t>(i)];
      EXPECT_TRUE(geos::isValid(p)) << "parcel " << i;
      sum += area(p);
    }
    const double whole = area(after.blocks[b].parts[0]);
    EXPECT_NEAR(sum, whole, 1e-6 * whole) << "the block is tiled";
    EXPECT_NEAR(geos::unionArea(
                    [&] {
                      std::vector<const Polygon*> all;
                      for (int i : after.blocks[b].parcels) all.push_back(&after.parcels[static_cast<std::size_t>(i)]);
                      return all;
                    }(),
                    0),
                whole, 1e-6 * whole)
        << "without overlaps";
  }
  std::set<Key> keys(editor.parcelKeys().begin(), editor.parcelKeys().end());
  EXPECT_EQ(keys.size(), after.parcels.size());
  // Unlocked, the next subdivision of the block no longer keeps it.
  editor.setLock(locked, false);
  EXPECT_TRUE(editor.locked().empty());
}

// The application edits the network it compares: the editor of a comparison
// starts from the comparison's parcels, bit for bit (per-block bounds from the
// observed parcels included), and a block keeps its derived bounds while it
// keeps its key.
TEST(StreetEditor, TheEditorOfAComparisonStartsFromItsParcelsAndKeepsEachBlocksBounds) {
  CompareRequest request;
  request.input.path = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
  request.input.where = "use <> 'ROW'";
  request.streets = sampleStreets().streets;
  request.style = "skeleton";
  request.parameters["seed"] = 3;
  auto observed = std::make_shared<const ObservedData>(
      loadObservedInStreetBlocks(request.input, &*request.streets, request.parameters));
  const CompareResult compared = compare(request, observed);
  StreetEditor editor(request, observed);
  const GeneratedParcels& g = editor.parcels();
  ASSERT_EQ(g.parcels.size(), compared.generated.parcels.size());
  for (std::size_t i = 0; i < g.parcels.size(); ++i) {
    ASSERT_TRUE(test::sameBits(g.parcels[i], compared.generated.parcels[i])) << "parcel " << i;
  }
  EXPECT_EQ(g.blockKeys, compared.generated.blockKeys);
  // The editor draws in the comparison's frame.
  const Point p = editor.toLocal({-71.1, 42.37});
  const Point q = observed->layer.frame.toLocal(-71.1, 42.37);
  EXPECT_EQ(p.x, q.x);
  EXPECT_EQ(p.y, q.y);
  // After a move, the blocks not affected keep their parcels and the affected
  // ones are subdivided with their own bounds again (as a fresh comparison of
  // the moved network would, were its observed parcels the same).
  const Key node = busiestNode(editor);
  const EditReport r = editor.apply(moveNodeBy(editor, node, 1.5, -1));
  EXPECT_FALSE(r.blocksAffected.empty());
  EXPECT_GE(static_cast<double>(r.matched), 0.8 * static_cast<double>(std::min(r.parcelsBefore, r.parcelsAfter)));
  ASSERT_TRUE(editor.undo());
  for (std::size_t i = 0; i < g.parcels.size(); ++i) {
    ASSERT_TRUE(test::sameBits(editor.parcels().parcels[i], compared.generated.parcels[i])) << "parcel " << i;
  }
  // A snapshot stays as it was while the editor goes on.
  const StreetEditor::Snapshot shot = editor.snapshot();
  const std::size_t count = shot.parcels().parcels.size();
  editor.apply(moveNodeBy(editor, node, 3, 3));
  EXPECT_EQ(shot.parcels().parcels.size(), count);
  EXPECT_EQ(shot.parcelKeys().size(), count);
}

// The edits written as an edits file (coordinates through the input's
// geographic CRS and back) and replayed on a fresh editor give the same
// network, parcels and keys.
TEST(StreetEditor, EditsWrittenAndReplayedGiveTheSameParcelsAndKeys) {
  CompareRequest request;
  request.input.path = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
  request.input.where = "use <> 'ROW'";
  request.streets = sampleStreets().streets;
  auto observed = std::make_shared<const ObservedData>(
      loadObservedInStreetBlocks(request.input, &*request.streets, request.parameters));
  StreetEditor editor(request, observed);
  ASSERT_TRUE(editor.network().layer.frame.isGeographic());
  std::vector<StreetEdit> edits;
  const Key node = busiestNode(editor);
  edits.push_back(moveNodeBy(editor, node, 3, 1));
  editor.apply(edits.back());
  StreetEdit label;
  label.op = StreetEdit::Op::SetLabel;
  label.parcel = editor.parcelKeys().back();
  label.label = "blue house";
  edits.push_back(label);
  editor.apply(label);
  const auto& g = editor.network().graph;
  Key street = 0;
  for (const auto& e : g.edges) {
    if (!e.boundary && e.line.size() == 2 && g.nodes[static_cast<std::size_t>(e.from)].key != node &&
        g.nodes[static_cast<std::size_t>(e.to)].key != node) {
      street = e.key;
    }
  }
  ASSERT_NE(street, 0u);
  StreetEdit width;
  width.op = StreetEdit::Op::SetWidth;
  width.edge = street;
  width.width = 21;
  edits.push_back(width);
  editor.apply(width);
  StreetEdit remove;
  remove.op = StreetEdit::Op::DeleteStreet;
  remove.edge = street;
  edits.push_back(remove);
  editor.apply(remove);
  StreetEdit add;
  add.op = StreetEdit::Op::AddStreet;
  add.node = node;
  for (const auto& n : editor.network().graph.nodes) {
    if (n.key == node) add.to = {n.at.x + 40, n.at.y};
  }
  add.width = 10;
  edits.push_back(add);
  editor.apply(add);

  test::TempDir dir;
  const std::string path = dir.file("edits.json");
  writeEdits(path, edits, editor.network().layer.frame, {});
  StreetEditor replay(request, observed);
  const std::vector<StreetEdit> read = readEdits(path, [&](const Point& p) { return replay.toLocal(p); });
  ASSERT_EQ(read.size(), edits.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].op, edits[i].op);
    EXPECT_NEAR(read[i].to.x, edits[i].to.x, 1e-6);
    EXPECT_NEAR(read[i].to.y, edits[i].to.y, 1e-6);
    replay.apply(read[i]);
    EXPECT_EQ(replay.network().graph.nodes.size(), replay.network().graph.nodes.size());
  }
  std::vector<Key> a, b;
  for (const auto& n : editor.network().graph.nodes) a.push_back(n.key);
  for (const auto& n : replay.network().graph.nodes) b.push_back(n.key);
  EXPECT_EQ(a, b) << "node keys";
  a.clear();
  b.clear();
  for (const auto& e : editor.network().graph.edges) a.push_back(e.key);
  for (const auto& e : replay.network().graph.edges) b.push_back(e.key);
  EXPECT_EQ(a, b) << "edge keys";
  EXPECT_EQ(editor.parcels().blockKeys, replay.parcels().blockKeys);
  EXPECT_EQ(editor.parcelKeys(), replay.parcelKeys());
  EXPECT_EQ(editor.labels(), replay.labels());
}

// Bug: an override naming a block the network lacks was dropped with exit 0
// (compare and generate refuse it).
TEST(StreetEditor, AnOverrideOfABlockTheNetworkLacksIsRefused) {
  GenerateRequest r = sampleStreets();
  StreetEditor plain(r);
  const Key known = plain.parcels().blockKeys.front();
  r.overrides[known].style = "obb";
  EXPECT_NO_THROW(StreetEditor{r});
  r.overrides[0x0123456789abcdefull].style = "obb";
  try {
    StreetEditor editor(r);
    FAIL() << "an override of no block is refused";
  } catch (const Error& error) {
    EXPECT_EQ(error.kind(), Error::Kind::Usage);
    EXPECT_NE(std::string(error.what()).find("block 0123456789abcdef: no such block"), std::string::npos)
        << error.what();
  }
}

TEST(StreetEditor, ABadEditNamesWhatIsWrongAndChangesNothing) {
  StreetEditor editor(sampleStreets());
  const Snapshot before = snapshot(editor);
  StreetEdit e;
  e.op = StreetEdit::Op::MoveNode;
  e.node = 0x0123456789abcdefull;
  try {
    editor.apply(e);
    FAIL() << "an unknown node is refused";
  } catch (const Error& error) {
    EXPECT_EQ(error.kind(), Error::Kind::Usage);
    EXPECT_NE(std::string(error.what()).find("0123456789abcdef"), std::string::npos) << error.what();
  }
  e.op = StreetEdit::Op::SetWidth;
  e.edge = editor.network().graph.edges.front().key;
  e.width = -2;
  EXPECT_THROW(editor.apply(e), Error);
  // Bug: these gave NaN coordinates or emptied every block, written with exit 0.
  e.width = 1e300;  // wider than any street
  EXPECT_THROW(editor.apply(e), Error);
  StreetEdit scale;  // nodes sent beyond reach
  scale.op = StreetEdit::Op::TransformNodes;
  scale.nodes = {editor.network().graph.nodes.front().key};
  scale.scale = 1e12;
  scale.centre = {-1, -1};
  EXPECT_THROW(editor.apply(scale), Error);
  StreetEdit curve;  // control points beyond reach
  curve.op = StreetEdit::Op::SetCurve;
  curve.edge = e.edge;
  curve.controls = std::array<Point, 2>{Point{1e10, 1e10}, Point{-1e10, -1e10}};
  EXPECT_THROW(editor.apply(curve), Error);
  StreetEdit far;  // a node moved to where no coordinate is finite
  far.op = StreetEdit::Op::MoveNode;
  far.node = editor.network().graph.nodes.front().key;
  far.to = {NAN, 0};
  try {
    editor.apply(far);
    ADD_FAILURE() << "a node moved to NaN was accepted";
  } catch (const Error& error) {
    EXPECT_EQ(error.kind(), Error::Kind::Usage);
    EXPECT_NE(std::string(error.what()).find("moves a node"), std::string::npos) << error.what();
  }
  // Bug: insert_node at NaN or infinity was "applied" and changed nothing (exit 0).
  for (const Point at : {Point{NAN, 0}, Point{INFINITY, 1}, Point{0, 1e300}}) {
    StreetEdit insert;
    insert.op = StreetEdit::Op::InsertNode;
    insert.edge = e.edge;
    insert.to = at;
    try {
      editor.apply(insert);
      ADD_FAILURE() << "insert_node at (" << at.x << ", " << at.y << ") was accepted";
    } catch (const Error& error) {
      EXPECT_EQ(error.kind(), Error::Kind::Usage);
      EXPECT_NE(std::string(error.what()).find("insert_node"), std::string::npos) << error.what();
    }
  }
  EXPECT_TRUE(sameState(snapshot(editor), before));
  EXPECT_EQ(editor.undoSize(), 0u);
}

TEST(StreetEditor, AnEditsFileIsReadWithItsErrorsNamed) {
  test::TempDir dir;
  auto write = [&](const std::string& text) {
    const std::string path = dir.file("edits.json");
    std::ofstream(path) << text;
    return path;
  };
  const auto identity = [](const Point& p) { return p; };
  const std::vector<StreetEdit> edits =
      readEdits(write(R"([{"op": "move_node", "node": "00000000000000ff", "to": [1, 2]},
                {"op": "set_width", "edge": "00000000000000aa", "width": 12},
                {"op": "set_block", "block": "00000000000000bb", "style": "obb", "parameters": {"a-max": 900}},
                {"op": "transform_nodes", "nodes": ["0000000000000001"], "scale": 2, "rotate": 90}])"),
                identity);
  ASSERT_EQ(edits.size(), 4u);
  EXPECT_EQ(edits[0].node, 0xffu);
  EXPECT_EQ(edits[0].to.y, 2);
  EXPECT_EQ(edits[1].width, 12);
  EXPECT_EQ(edits[2].parameters.at("a-max"), 900);
  EXPECT_EQ(edits[3].scale, 2);
  auto message = [&](const std::string& text) {
    try {
      readEdits(write(text), identity);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"([{"op": "fly"}])").find("edit 0: op 'fly' is not an edit"), std::string::npos);
  EXPECT_NE(message(R"([{"op": "move_node", "node": "xyz", "to": [1, 2]}])").find("edit 0: member node is not a key"),
            std::string::npos);
  EXPECT_NE(message(R"([{"op": "set_width", "edge": "00000000000000aa"}])").find("edit 0: member width is missing"),
            std::string::npos);
  EXPECT_NE(message(R"({"op": "set_width"})").find("holds a list of edits"), std::string::npos);
}

}  // namespace
}  // namespace parcelscope::pipeline
