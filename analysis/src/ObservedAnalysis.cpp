#include "parcelscope/analysis/ObservedAnalysis.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "BoxPairs.h"
#include "Contacts.h"
#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/core/Parallel.h"

namespace parcelscope::analysis {

const ParameterDescription& minFrontageParameter() {
  static const ParameterDescription d = realParameter(
      "min-frontage",
      "Length of the block's outer contour a parcel must run along to count as having street access (observed "
      "and generated parcels alike)",
      "m", 0.0, 1000.0, 1.0, "Blocks");
  return d;
}

const std::vector<ParameterDescription>& analysisParameters() {
  // k first: its group, Bounds, then comes first in compare's --help and the GUI.
  static const std::vector<ParameterDescription> d = {
      realParameter("k",
                    "Number of standard deviations in A_min/A_max = A-bar -/+ k s_A and W_min/W_max = "
                    "W-bar -/+ k s_W",
                    "", 0.0, 10.0, 2.0, "Bounds"),
      realParameter("block-tolerance",
                    "Parcels whose boundaries come this close belong to one block; gaps narrower than this are "
                    "closed in the block outline",
                    "m", 0.0, 50.0, 1.0, "Blocks"),
      enumParameter("derive",
                    "How block bounds come from observed parcels: paper (mean -/+ k standard deviations, "
                    "Vanegas et al. 2012) or robust (median -/+ k x 1.4826 MAD)",
                    {"paper", "robust"}, "paper", "Bounds"),
      minFrontageParameter(),
      booleanParameter("detect-right-of-way",
                       "Detect parcels that are streets (holes holding parcels, or network shape) and keep them "
                       "out of blocks; no: treat every parcel as a lot",
                       true, "Blocks"),
  };
  return d;
}

AnalysisOptions analysisOptionsFrom(const ParameterValues& v) {
  AnalysisOptions o;
  auto get = [&](const char* name, double fallback) {
    auto it = v.find(name);
    return it == v.end() ? fallback : it->second;
  };
  o.blockTolerance = get("block-tolerance", o.blockTolerance);
  o.k = get("k", o.k);
  o.robustBounds = get("derive", 0.0) != 0.0;
  o.minFrontage = get("min-frontage", o.minFrontage);
  o.detectRightOfWay = get("detect-right-of-way", 1.0) != 0.0;
  return o;
}

namespace {

// 1 / Phi^-1(3/4): the MAD of normal data times this is its standard deviation.
constexpr double kMadToSd = 1.4826;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const std::size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(h), v.end());
  if (v.size() % 2 == 1) return v[h];
  return 0.5 * (v[h] + *std::max_element(v.begin(), v.begin() + static_cast<long>(h)));
}

double medianAbsoluteDeviation(const std::vector<double>& v) {
  const double m = median(v);
  std::vector<double> d;
  d.reserve(v.size());
  for (double x : v) d.push_back(std::fabs(x - m));
  return median(std::move(d));
}

double mean(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

double sampleSd(const std::vector<double>& v, double m) {
  if (v.size() < 2) return 0.0;
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Minimum shared boundary (m) for two parcels to count as neighbours.
constexpr double kMinSharedBoundary = 1.0;

// Shared boundaries match edges within the block tolerance, but never farther
// than 1 m: a large tolerance joins blocks, it must not make lots across an
// alley into neighbours.
double sharedTolerance(double blockTolerance) { return std::clamp(blockTolerance, 1e-6, 1.0); }

// The block outline lies on its parcels' street edges except where the closing
// bridged a gap (at most half the tolerance away); frontage matches within that,
// between 5 cm and 0.5 m, so rear edges near the street do not count.
double frontageTolerance(double blockTolerance) { return std::clamp(0.5 * blockTolerance, 0.05, 0.5); }

// Counts, for every parcel, the others it shares at least kMinSharedBoundary with.
void countNeighbours(const std::vector<detail::Contact>& contacts, std::vector<ParcelMetrics>& metrics) {
  for (const auto& c : contacts) {
    if (c.shared >= kMinSharedBoundary) {
      ++metrics[c.a].neighbours;
      ++metrics[c.b].neighbours;
    }
  }
}

// Frontage and street access of a block's parcels, measured on its outline.
// Returns how many have street access.
int measureFrontage(const Block& block, const std::vector<const Polygon*>& shapes, double tolerance, double minFrontage,
                    std::vector<ParcelMetrics>& metrics) {
  std::vector<const Polygon*> members;
  for (int i : block.parcels) members.push_back(shapes[i]);
  std::vector<Ring> outline;
  for (const Polygon& part : block.parts) outline.push_back(part.outer);
  const auto frontage = detail::lengthAlong(members, outline, frontageTolerance(tolerance));
  int withAccess = 0;
  for (std::size_t k = 0; k < block.parcels.size(); ++k) {
    ParcelMetrics& m = metrics[block.parcels[k]];
    m.frontage = frontage[k];
    m.streetAccess = m.frontage >= minFrontage;
    withAccess += m.streetAccess;
  }
  return withAccess;
}
// Right-of-way: an MBR width at least kNetworkWidthRatio times the strip width
// 2A/P (a rectangular lot of any proportions stays below 2), and either holes
// holding other parcels or at least kNetworkMinNeighbours neighbours.
constexpr int kNetworkMinNeighbours = 10;
constexpr double kNetworkWidthRatio = 6.0;

}  // namespace

BlockStatistics blockStatistics(const std::vector<double>& areas, const std::vector<double>& widths,
                                const BoundsRule& rule) {
  BlockStatistics s;
  s.parcelCount = static_cast<int>(areas.size());
  s.meanArea = mean(areas);
  s.sdArea = sampleSd(areas, s.meanArea);
  s.meanWidth = mean(widths);
  s.sdWidth = sampleSd(widths, s.meanWidth);
  const double k = rule.k;
  // Centre and spread of the bounds: the paper's mean and standard deviation,
  // or the median and the MAD scaled to match s for normal data.
  const double aCentre = rule.robust ? median(areas) : s.meanArea;
  const double aSpread = rule.robust ? kMadToSd * medianAbsoluteDeviation(areas) : s.sdArea;
  const double wCentre = rule.robust ? median(widths) : s.meanWidth;
  const double wSpread = rule.robust ? kMadToSd * medianAbsoluteDeviation(widths) : s.sdWidth;
  s.aMax = aCentre + k * aSpread;
  s.wMax = wCentre + k * wSpread;
  const double aFloor = std::max(0.1 * aCentre, 1.0);
  const double wFloor = std::max(0.1 * wCentre, 0.5);
  s.aMin = aCentre - k * aSpread;
  s.wMin = wCentre - k * wSpread;
  if (s.aMin < aFloor) {
    s.aMin = std::min(aFloor, s.aMax);
    s.aMinClamped = true;
  }
  if (s.wMin < wFloor) {
    s.wMin = std::min(wFloor, s.wMax);
    s.wMinClamped = true;
  }
  return s;
}

bool hasRightOfWayShape(const ShapeMetrics& m) {
  const double stripWidth = 2.0 * m.area / m.perimeter;
  return !(m.width < kNetworkWidthRatio * stripWidth);
}

ObservedAnalysis analyseParcels(const std::vector<Parcel>& parcels, const AnalysisOptions& options,
                                const ProgressFn& progress) {
  const std::size_t n = parcels.size();
  const double tol = options.blockTolerance;
  ObservedAnalysis out;
  out.metrics.resize(n);
  out.rightOfWay.assign(n, RightOfWay::No);
  out.blockOf.assign(n, -1);

  out.timings.start("metrics");
  // 1. Shape metrics.
  // Boxes of every ring grown by half the contact tolerance: their pairs are
  // the candidates for contacts, and include every pair of parcels where one
  // can lie inside the other (it lies inside the other's box).
  const double contactTolerance = std::max(tol, 1e-6);
  std::vector<Box> boxes(n);
  std::vector<Point> inside(n);
  parallelFor(n, [&](std::size_t i) {
    static_cast<ShapeMetrics&>(out.metrics[i]) = shapeMetrics(parcels[i].shape);
    boxes[i] = detail::contactBox(parcels[i].shape, contactTolerance);
    inside[i] = interiorPoint(parcels[i].shape);
  });
  reportProgress(progress, 0.1, "metrics");

  out.timings.start("contacts");
  // 2. Shared boundaries (neighbours) and closeness, edge by edge.
  std::vector<const Polygon*> shapes(n);
  for (std::size_t i = 0; i < n; ++i) shapes[i] = &parcels[i].shape;
  // Overlapping boxes also find parcels lying inside others without touching them.
  const auto pairs = detail::intersectingPairs(boxes);
  // Used for neighbours (shared at least kMinSharedBoundary) and closeness
  // only: measuring a pair stops at that length.
  const auto touching = detail::contacts(shapes, pairs, contactTolerance, sharedTolerance(tol), kMinSharedBoundary);
  countNeighbours(touching, out.metrics);
  reportProgress(progress, 0.3, "neighbours");

  out.timings.start("right_of_way");
  // 3. Right-of-way parcels.
  if (options.detectRightOfWay) {
    // A street net stored as a parcel is a thin strip (its MBR is many strip
    // widths wide) that either encloses other parcels in its holes or touches
    // many of them. Lots with an enclave, or long thin lots, fail one of the two.
    std::vector<char> enclosing(n, 0);
    for (const auto& [i, j] : pairs) {
      for (const auto& [outer, inner] : {std::pair<int, int>{i, j}, std::pair<int, int>{j, i}}) {
        if (enclosing[outer]) continue;
        for (const Ring& hole : parcels[outer].shape.holes) {
          const Box hb = bounds(hole);
          const Point& p = inside[inner];
          if (p.x >= hb.minX && p.x <= hb.maxX && p.y >= hb.minY && p.y <= hb.maxY && pointInRing(p, hole)) {
            enclosing[outer] = 1;
            break;
          }
        }
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      const ParcelMetrics& m = out.metrics[i];
      if (!hasRightOfWayShape(m)) continue;
      if (enclosing[i]) {
        out.rightOfWay[i] = RightOfWay::HolesHoldParcels;
      } else if (m.neighbours >= kNetworkMinNeighbours) {
        out.rightOfWay[i] = RightOfWay::NetworkShape;
      }
    }
  }
  for (auto r : out.rightOfWay) out.rightOfWayCount += r != RightOfWay::No;

  out.timings.start("grouping");
  // 4. Blocks: connected groups of lots within the tolerance.
  DisjointSets sets(n);
  auto isLot = [&](int i) { return out.rightOfWay[i] == RightOfWay::No; };
  for (const auto& c : touching) {
    if (c.close && isLot(c.a) && isLot(c.b)) sets.join(c.a, c.b);
  }
  for (const auto& [i, j] : pairs) {
    if (!isLot(i) || !isLot(j) || sets.find(i) == sets.find(j)) continue;
    if (pointInPolygon(inside[i], parcels[j].shape) || pointInPolygon(inside[j], parcels[i].shape)) {
      sets.join(i, j);
    }
  }
  std::vector<int> rootBlock(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (out.rightOfWay[i] != RightOfWay::No) continue;
    const int r = sets.find(static_cast<int>(i));
    if (rootBlock[r] < 0) {
      rootBlock[r] = static_cast<int>(out.blocks.size());
      out.blocks.emplace_back();
      out.blocks.back().id = rootBlock[r];
    }
    out.blockOf[i] = rootBlock[r];
    out.blocks[rootBlock[r]].parcels.push_back(static_cast<int>(i));
  }
  // Each block's key, and its members in the order of their keys: sums over
  // them (the statistics, the outline's union) are then the same to the bit
  // whatever the order of the input's features.
  for (Block& block : out.blocks) {
    std::vector<std::pair<Key, int>> members;
    members.reserve(block.parcels.size());
    for (int i : block.parcels) members.emplace_back(parcelKey(parcels[i]), i);
    std::sort(members.begin(), members.end());
    std::vector<Key> keys;
    keys.reserve(members.size());
    for (std::size_t m = 0; m < members.size(); ++m) {
      keys.push_back(members[m].first);
      block.parcels[m] = members[m].second;
    }
    block.key = setKey(std::move(keys));
  }

  // 5. Block outlines, frontage and statistics.
  out.timings.start("block_outlines");
  // Largest blocks first, so that one big block does not finish last alone.
  std::vector<std::size_t> bySize(out.blocks.size());
  std::iota(bySize.begin(), bySize.end(), 0);
  std::stable_sort(bySize.begin(), bySize.end(), [&](std::size_t x, std::size_t y) {
    return out.blocks[x].parcels.size() > out.blocks[y].parcels.size();
  });
  parallelFor(
      out.blocks.size(),
      [&](std::size_t k) {
        const std::size_t b = bySize[k];
        std::vector<const Polygon*> members;
        for (int i : out.blocks[b].parcels) members.push_back(shapes[i]);
        out.blocks[b].parts = geos::unionAndClose(members, tol);
      },
      [&](std::size_t done) {
        reportProgress(progress, 0.5 + 0.4 * static_cast<double>(done) / static_cast<double>(out.blocks.size()),
                       "blocks");
      });
  out.timings.start("frontage_and_statistics");
  // Blocks in parallel: each writes only its own parcels' frontage.
  out.statistics.resize(out.blocks.size());
  parallelFor(out.blocks.size(), [&](std::size_t b) {
    const Block& block = out.blocks[b];
    const int withAccess = measureFrontage(block, shapes, tol, options.minFrontage, out.metrics);
    std::vector<double> areas, widths;
    for (int i : block.parcels) {
      areas.push_back(out.metrics[i].area);
      widths.push_back(out.metrics[i].width);
    }
    BlockStatistics s = blockStatistics(areas, widths, options.bounds());
    s.blockId = block.id;
    for (const Polygon& part : block.parts) s.blockArea += area(part);
    s.streetAccessShare = static_cast<double>(withAccess) / static_cast<double>(block.parcels.size());
    out.statistics[b] = s;
  });
  for (std::size_t b = 0; b < out.blocks.size(); ++b) {
    if (out.blocks[b].parts.size() > 1) ++out.multipartBlocks;
    out.clampedAMin += out.statistics[b].aMinClamped;
    out.clampedWMin += out.statistics[b].wMinClamped;
  }
  reportProgress(progress, 1.0, "blocks");
  out.timings.stop();
  return out;
}

void rederiveBlockBounds(ObservedAnalysis& a, const BoundsRule& rule) {
  a.clampedAMin = a.clampedWMin = 0;
  for (std::size_t b = 0; b < a.blocks.size(); ++b) {
    if (a.blocks[b].parcels.empty()) continue;  // a street block without parcels keeps the run's bounds
    std::vector<double> areas, widths;
    for (int i : a.blocks[b].parcels) {
      areas.push_back(a.metrics[i].area);
      widths.push_back(a.metrics[i].width);
    }
    const BlockStatistics old = a.statistics[b];
    BlockStatistics& s = a.statistics[b];
    s = blockStatistics(areas, widths, rule);
    s.blockId = old.blockId;
    s.blockArea = old.blockArea;
    s.streetAccessShare = old.streetAccessShare;
    a.clampedAMin += s.aMinClamped;
    a.clampedWMin += s.wMinClamped;
  }
}

std::vector<ParcelMetrics> measureShapes(const std::vector<Polygon>& shapes) {
  std::vector<ParcelMetrics> metrics(shapes.size());
  parallelFor(shapes.size(), [&](std::size_t i) { static_cast<ShapeMetrics&>(metrics[i]) = shapeMetrics(shapes[i]); });
  return metrics;
}

void measureContext(const std::vector<Polygon>& shapes, const std::vector<Block>& blocks, double tolerance,
                    double minFrontage, std::vector<ParcelMetrics>& metrics) {
  for (ParcelMetrics& m : metrics) {
    m.neighbours = 0;
    m.frontage = 0;
    m.streetAccess = false;
  }
  std::vector<const Polygon*> all;
  all.reserve(shapes.size());
  for (const Polygon& s : shapes) all.push_back(&s);
  // Only whether each pair shares kMinSharedBoundary counts here.
  countNeighbours(detail::contacts(all, std::max(tolerance, 1e-6), sharedTolerance(tolerance), kMinSharedBoundary),
                  metrics);
  parallelFor(blocks.size(), [&](std::size_t b) { measureFrontage(blocks[b], all, tolerance, minFrontage, metrics); });
}

std::vector<ParcelMetrics> measureParcels(const std::vector<Polygon>& shapes, const std::vector<Block>& blocks,
                                          double tolerance, double minFrontage) {
  std::vector<ParcelMetrics> metrics = measureShapes(shapes);
  measureContext(shapes, blocks, tolerance, minFrontage, metrics);
  return metrics;
}

std::vector<Column> metricColumns() {
  std::vector<Column> columns;
  for (const ParcelQuantity& q : parcelMetrics()) {
    columns.push_back({q.name, q.integer ? Column::Type::Integer : Column::Type::Real, q.unit});
  }
  return columns;
}

std::vector<Value> metricValues(const ParcelMetrics& m) {
  const auto& metrics = parcelMetrics();
  std::vector<Value> values;
  values.reserve(metrics.size());
  for (const ParcelQuantity& q : metrics) {
    if (q.integer) {
      values.emplace_back(static_cast<std::int64_t>(q.value(m)));
    } else {
      values.emplace_back(q.value(m));
    }
  }
  return values;
}

RowSource parcelRows(const std::vector<Parcel>& parcels, const ObservedAnalysis& a) {
  using T = Column::Type;
  RowSource t;
  t.columns = {{"parcel_id", T::Integer, ""}, {"parcel_key", T::String, ""},   {"source_fid", T::Integer, ""},
               {"part", T::Integer, ""},      {"block_id", T::Integer, ""},    {"block_key", T::String, ""},
               {"role", T::String, ""},       {"stack_count", T::Integer, ""}, {"repaired", T::Integer, ""}};
  for (Column& c : metricColumns()) t.columns.push_back(std::move(c));
  t.rows = parcels.size();
  t.row = [&parcels, &a](std::size_t i, std::vector<Value>& row) {
    static const char* roles[] = {"lot", "right_of_way_holes", "right_of_way_network"};
    const int block = a.blockOf[i];
    row = {std::int64_t(i),
           keyText(parcelKey(parcels[i])),
           std::int64_t(parcels[i].sourceFid),
           std::int64_t(parcels[i].part),
           std::int64_t(block),
           block >= 0 ? keyText(a.blocks[static_cast<std::size_t>(block)].key) : std::string(),
           std::string(roles[static_cast<int>(a.rightOfWay[i])]),
           std::int64_t(parcels[i].stackCount),
           std::int64_t(parcels[i].repaired)};
    for (Value& v : metricValues(a.metrics[i])) row.push_back(std::move(v));
  };
  return t;
}

Table parcelTable(const std::vector<Parcel>& parcels, const ObservedAnalysis& a) {
  return parcelRows(parcels, a).table();
}

Table blockTable(const ObservedAnalysis& a) {
  using T = Column::Type;
  Table t;
  t.columns = {{"block_id", T::Integer, ""},      {"block_key", T::String, ""},
               {"parcel_count", T::Integer, ""},  {"block_area", T::Real, "m2"},
               {"parts", T::Integer, ""},         {"mean_area", T::Real, "m2"},
               {"sd_area", T::Real, "m2"},        {"mean_width", T::Real, "m"},
               {"sd_width", T::Real, "m"},        {"a_min", T::Real, "m2"},
               {"a_max", T::Real, "m2"},          {"w_min", T::Real, "m"},
               {"w_max", T::Real, "m"},           {"a_min_clamped", T::Integer, ""},
               {"w_min_clamped", T::Integer, ""}, {"street_access_share", T::Real, ""}};
  for (std::size_t b = 0; b < a.blocks.size(); ++b) {
    const BlockStatistics& s = a.statistics[b];
    t.rows.push_back({std::int64_t(s.blockId), keyText(a.blocks[b].key), std::int64_t(s.parcelCount), s.blockArea,
                      std::int64_t(a.blocks[b].parts.size()), s.meanArea, s.sdArea, s.meanWidth, s.sdWidth, s.aMin,
                      s.aMax, s.wMin, s.wMax, std::int64_t(s.aMinClamped), std::int64_t(s.wMinClamped),
                      s.streetAccessShare});
  }
  return t;
}

}  // namespace parcelscope::analysis
