#include "GpkgRtree.h"

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

#include "SqliteHandles.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::io::detail {

namespace {

// A box as SQLite's rtree stores it (32-bit floats), and the node it heads.
struct Box {
  float minx, maxx, miny, maxy;
};

float down(double v) {
  float f = static_cast<float>(v);
  if (static_cast<double>(f) > v) f = std::nextafter(f, -INFINITY);
  return f;
}
float up(double v) {
  float f = static_cast<float>(v);
  if (static_cast<double>(f) < v) f = std::nextafter(f, INFINITY);
  return f;
}

Box cover(const Box& a, const Box& b) {
  return {std::min(a.minx, b.minx), std::max(a.maxx, b.maxx), std::min(a.miny, b.miny), std::max(a.maxy, b.maxy)};
}

// An entry of one level: a leaf's feature or an inner node's child.
struct Item {
  std::int64_t id;  // the feature's fid, or the child's index in the level below
  Box box;
};

// Sort-tile-recursive grouping (Leutenegger et al. 1997): sort by x, cut into
// about sqrt(nodes) vertical slices, sort each by y, cut into nodes of
// `capacity` items. Reorders `items`; returns the start of each node.
std::vector<std::size_t> pack(std::vector<Item>& items, std::size_t capacity) {
  const std::size_t n = items.size();
  const std::size_t nodes = (n + capacity - 1) / capacity;
  const auto slices = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(nodes))));
  const std::size_t perSlice = ((nodes + slices - 1) / slices) * capacity;
  auto cx = [](const Item& i) { return 0.5 * (double(i.box.minx) + i.box.maxx); };
  auto cy = [](const Item& i) { return 0.5 * (double(i.box.miny) + i.box.maxy); };
  std::sort(items.begin(), items.end(), [&](const Item& a, const Item& b) { return cx(a) < cx(b); });
  std::vector<std::size_t> starts;
  for (std::size_t s = 0; s < n; s += perSlice) {
    const std::size_t e = std::min(n, s + perSlice);
    std::sort(items.begin() + static_cast<std::ptrdiff_t>(s), items.begin() + static_cast<std::ptrdiff_t>(e),
              [&](const Item& a, const Item& b) { return cy(a) < cy(b); });
    for (std::size_t k = s; k < e; k += capacity) starts.push_back(k);
  }
  return starts;
}

void putBig(unsigned char* p, std::uint64_t v, int bytes) {
  for (int b = bytes - 1; b >= 0; --b) {
    p[b] = static_cast<unsigned char>(v & 0xffu);
    v >>= 8;
  }
}
void putFloat(unsigned char* p, float f) {
  std::uint32_t bits;
  static_assert(sizeof bits == sizeof f);
  std::memcpy(&bits, &f, sizeof bits);
  putBig(p, bits, 4);
}

}  // namespace

std::string sqlQuoted(const std::string& text, char quote) {
  std::string q(1, quote);
  for (char c : text) q += c == quote ? std::string(2, c) : std::string(1, c);
  return q + quote;
}

void fillRtree(const std::string& path, const std::string& rtreeName, std::vector<RtreeEntry> entries,
               const std::string& afterSql) {
  Connection db(path, SQLITE_OPEN_READWRITE, "cannot build the spatial index " + rtreeName + ": ");
  auto step = [&](sqlite3_stmt* s, const char* what) {
    if (sqlite3_step(s) != SQLITE_DONE) throw db.fail(what);
    sqlite3_reset(s);
  };
  // Shadow table names, quoted as identifiers.
  auto shadow = [&](const char* suffix) { return sqlQuoted(rtreeName + suffix, '"'); };

  db.exec("BEGIN");
  // Node size: that of the empty root SQLite wrote when it made the table (it
  // reads every node at the root's size).
  int nodeSize = 0;
  {
    Stmt s = db.prepare("SELECT length(data) FROM " + shadow("_node") + " WHERE nodeno = 1");
    if (sqlite3_step(s.get()) == SQLITE_ROW) nodeSize = sqlite3_column_int(s.get(), 0);
  }
  constexpr int kCellBytes = 8 + 4 * 4;  // rowid or child node, then minx, maxx, miny, maxy
  const int capacityInt = (nodeSize - 4) / kCellBytes;
  if (capacityInt < 2) throw db.fail("unexpected root node of " + std::to_string(nodeSize) + " bytes");
  const auto capacity = static_cast<std::size_t>(capacityInt);

  if (!entries.empty()) {
    db.exec("DELETE FROM " + shadow("_node"));
    db.exec("DELETE FROM " + shadow("_rowid"));
    db.exec("DELETE FROM " + shadow("_parent"));

    // Levels from the leaves up: each level's nodes (their items) and boxes.
    struct Level {
      std::vector<Item> items;         // grouped by node
      std::vector<std::size_t> start;  // each node's first item
      std::vector<Box> boxes;          // each node's box
    };
    std::vector<Level> levels;
    std::vector<Item> items;
    items.reserve(entries.size());
    for (const RtreeEntry& e : entries) items.push_back({e.id, {down(e.minx), up(e.maxx), down(e.miny), up(e.maxy)}});
    entries = {};
    while (true) {
      Level level;
      level.items = std::move(items);
      if (level.items.size() <= capacity) {
        level.start = {0};
      } else {
        level.start = pack(level.items, capacity);
      }
      for (std::size_t k = 0; k < level.start.size(); ++k) {
        const std::size_t e = k + 1 < level.start.size() ? level.start[k + 1] : level.items.size();
        Box b = level.items[level.start[k]].box;
        for (std::size_t i = level.start[k] + 1; i < e; ++i) b = cover(b, level.items[i].box);
        level.boxes.push_back(b);
      }
      const std::size_t nodes = level.start.size();
      levels.push_back(std::move(level));
      if (nodes == 1) break;
      items.clear();
      for (std::size_t k = 0; k < nodes; ++k) items.push_back({static_cast<std::int64_t>(k), levels.back().boxes[k]});
    }

    // Node numbers: the root is 1, then each level from the top, in order.
    std::vector<std::vector<std::int64_t>> number(levels.size());
    std::int64_t next = 1;
    for (std::size_t l = levels.size(); l-- > 0;) {
      number[l].resize(levels[l].start.size());
      for (auto& n : number[l]) n = next++;
    }

    Stmt node = db.prepare("INSERT INTO " + shadow("_node") + " (nodeno, data) VALUES (?, ?)");
    Stmt parent = db.prepare("INSERT INTO " + shadow("_parent") + " (nodeno, parentnode) VALUES (?, ?)");
    std::vector<std::pair<std::int64_t, std::int64_t>> leafOf;  // (fid, leaf node)
    std::vector<unsigned char> data(static_cast<std::size_t>(nodeSize));
    const auto depth = static_cast<std::uint64_t>(levels.size() - 1);
    for (std::size_t l = levels.size(); l-- > 0;) {
      const Level& level = levels[l];
      for (std::size_t k = 0; k < level.start.size(); ++k) {
        const std::size_t b = level.start[k];
        const std::size_t e = k + 1 < level.start.size() ? level.start[k + 1] : level.items.size();
        std::fill(data.begin(), data.end(), 0);
        if (l + 1 == levels.size()) putBig(data.data(), depth, 2);
        putBig(data.data() + 2, e - b, 2);
        unsigned char* cell = data.data() + 4;
        for (std::size_t i = b; i < e; ++i, cell += kCellBytes) {
          const Item& it = level.items[i];
          std::int64_t id = it.id;
          if (l > 0) {
            id = number[l - 1][static_cast<std::size_t>(it.id)];
            sqlite3_bind_int64(parent.get(), 1, id);
            sqlite3_bind_int64(parent.get(), 2, number[l][k]);
            step(parent.get(), "parent");
          } else {
            leafOf.emplace_back(id, number[l][k]);
          }
          putBig(cell, static_cast<std::uint64_t>(id), 8);
          putFloat(cell + 8, it.box.minx);
          putFloat(cell + 12, it.box.maxx);
          putFloat(cell + 16, it.box.miny);
          putFloat(cell + 20, it.box.maxy);
        }
        sqlite3_bind_int64(node.get(), 1, number[l][k]);
        sqlite3_bind_blob(node.get(), 2, data.data(), nodeSize, SQLITE_TRANSIENT);
        step(node.get(), "node");
      }
    }
    std::sort(leafOf.begin(), leafOf.end());
    Stmt rowid = db.prepare("INSERT INTO " + shadow("_rowid") + " (rowid, nodeno) VALUES (?, ?)");
    for (const auto& [fid, leaf] : leafOf) {
      sqlite3_bind_int64(rowid.get(), 1, fid);
      sqlite3_bind_int64(rowid.get(), 2, leaf);
      step(rowid.get(), "rowid");
    }
  }
  if (!afterSql.empty()) db.exec(afterSql);
  db.exec("COMMIT");
  db.close("cannot close after the spatial index");
}

}  // namespace parcelscope::io::detail
