// sexton: the parcel generation of Sexton & Watson 2010 (sections 3.3.2 to
// 3.4.1): oblong blocks get a spine along their long axis, cut from end to end;
// then the largest parcel is split again and again, across a random
// road-facing side at a normally distributed position, under the paper's
// constraints, until the block holds its target number of parcels; of many
// randomized subdivisions the one closest to the block's observed parcels is
// kept. docs/algorithms/sexton.md gives the choices the paper leaves open.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "BlockFailure.h"
#include "LocalShift.h"
#include "LotSplit.h"
#include "PolygonSplit.h"
#include "PostProcess.h"
#include "Random.h"
#include "StraightSkeleton.h"
#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/analysis/Metrics.h"
#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/BoxIndex.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/generation/Styles.h"

namespace parcelscope::generation {

namespace {

using detail::Side;
using detail::SplitLine;

const std::vector<ParameterDescription>& sextonParameterDescriptions() {
  static const std::vector<ParameterDescription> d = [] {
    std::vector<ParameterDescription> all;
    for (const ParameterDescription& p : obbParameterDescriptions()) {
      if (p.name == "a-min" || p.name == "a-max" || p.name == "w-min" || p.name == "min-frontage" || p.name == "seed") {
        all.push_back(p);
      }
    }
    all.push_back(integerParameter("parcel-count",
                                   "sexton: parcels per block; 0: the block's observed count (without observed "
                                   "parcels: its area over the mean of a-min and a-max)",
                                   "", 0.0, 2e5, 0.0, "Subdivision"));  // at most the work budget, kMaxLots
    all.push_back(integerParameter(
        "tries", "sexton: randomized subdivisions per block; the one closest to the observed parcels is kept", "", 1.0,
        1000.0, 50.0, "Subdivision"));
    all.push_back(enumParameter(
        "interior-parcels",
        "sexton: none, every parcel on a street (the paper); observed, as many parcels without street access as "
        "the block's observed share, behind a street front as deep as its observed street parcels",
        {"none", "observed"}, "observed", "Subdivision"));
    return all;
  }();
  return d;
}

struct SextonParameters {
  double aMin = 200, aMax = 800, wMin = 8, minFrontage = 1;
  int count = 0;  // 0: derived
  int tries = 50;
  bool interior = true;  // interior-parcels observed
};

SextonParameters sextonParametersFrom(const ParameterValues& v) {
  SextonParameters p;
  for (const auto& [name, target] : {std::pair{"a-min", &p.aMin}, std::pair{"a-max", &p.aMax},
                                     std::pair{"w-min", &p.wMin}, std::pair{"min-frontage", &p.minFrontage}}) {
    readValue(v, name, *target);
  }
  readValue(v, "parcel-count", p.count);
  readValue(v, "tries", p.tries);
  double interior = 1;
  readValue(v, "interior-parcels", interior);
  p.interior = interior >= 0.5;
  return p;
}

// The paper's constants (section 3.3.2 and 3.4.1).
constexpr double kOblong = 0.5;                    // blocks narrower than 1:2 (box width / length) get a spine
constexpr double kSpineTurn = 20.0 * kPi / 180.0;  // spine simplification: summed turning before a new vertex
constexpr double kMinAreaShare = 0.75;             // of a-min, the smallest parcel a split may make
constexpr double kSmallestQuantile = 0.05;  // of the observed areas: the block's smallest parcel (smallestObserved)
constexpr double kSquareEnough = 0.25;      // aspect (width / length) limit of the rectangularity rule
// Aspect (width / length) no piece goes below, even with the constraints
// relaxed, in a block without observed parcels (see leastAspect).
constexpr double kSliverAspect = 0.1;
constexpr double kThinQuantile = 0.95;  // of the observed aspect ratios: the thinnest piece of the thin quota

// The value at quantile `q` of `values` (rank q (n - 1), rounded down); `values` non-empty.
double quantileOf(std::vector<double> values, double q) {
  const auto at = values.begin() + static_cast<long>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

// The least aspect (width / length) a piece may have with the constraints
// relaxed: that of the block's observed parcels at their 90th percentile of
// aspect ratio (length / width), at most kSquareEnough; kSliverAspect without
// observed parcels. A block that reaches its count only with thinner slivers
// than its observed parcels stops short.
// An observed aspect ratio (length / width) the limits read: finite, at least 1.
bool usableRatio(double r) { return std::isfinite(r) && r >= 1; }
double leastAspect(const ObservedSample* observed) {
  std::vector<double> ratios;
  if (observed)
    std::copy_if(observed->aspectRatios.begin(), observed->aspectRatios.end(), std::back_inserter(ratios), usableRatio);
  if (ratios.empty()) return kSliverAspect;
  return std::min(kSquareEnough, 1.0 / quantileOf(std::move(ratios), 0.9));
}
// The block's thin parcels, those of its observed parcels thinner than
// `least` (leastAspect), where that is thinner than the paper's 1:4: their
// share, the aspect (width / length) of the thinnest but a few (the block's
// 95th percentile of aspect ratio) and their 10th percentile of area. A try
// may make as many pieces thinner than `least` as that share of its target,
// down to that aspect and of at least that area.
struct ThinParcels {
  double share = 0;
  double least = kSliverAspect;  // aspect
  double area = 0;
};
ThinParcels thinParcels(const ObservedSample* observed, double least) {
  ThinParcels t{0, least, 0};
  if (!observed || least >= kSquareEnough || observed->aspectRatios.size() != observed->areas.size()) return t;
  std::vector<double> ratios, areas;
  std::size_t n = 0;
  for (std::size_t i = 0; i < observed->aspectRatios.size(); ++i) {
    const double r = observed->aspectRatios[i];
    if (!usableRatio(r)) continue;
    ++n;
    ratios.push_back(r);
    if (1.0 / r < least) areas.push_back(observed->areas[i]);
  }
  if (areas.empty()) return t;
  t.share = static_cast<double>(areas.size()) / static_cast<double>(n);
  t.least = std::min(least, 1.0 / quantileOf(std::move(ratios), kThinQuantile));
  t.area = quantileOf(std::move(areas), 0.1);
  return t;
}
// The paper's smallest parcel of the block, robustly: the block's observed
// parcels' 5th percentile of area (infinite without observed parcels). The
// derived a-min (mean - k sd) is floored at a tenth of the mean, far above the
// small parcels of a block of heavy-tailed areas.
double smallestObserved(const ObservedSample* observed) {
  if (!observed || observed->areas.empty()) return std::numeric_limits<double>::infinity();
  return quantileOf(observed->areas, kSmallestQuantile);
}
// `share` of `count`, rounded down; a share of k / n of n parcels is k, not
// one fewer for its rounding.
std::size_t shareOf(double share, std::size_t count) {
  return static_cast<std::size_t>(std::floor(share * static_cast<double>(count) + 1e-9));
}
constexpr double kMinPieceShare = 0.3;  // of the parcel split, each piece's least area
constexpr double kPositionSd = 0.15;    // of the side's length: spread of the split position about its middle
constexpr int kAttempts = 10;           // random splits tried on one parcel
// When no random split is admissible: the largest parcels scanned, and the
// positions along each road side tried, middle first.
constexpr std::size_t kScanParcels = 8;
constexpr double kScanAt[] = {0.5, 0.4, 0.6, 0.3, 0.7, 0.2, 0.8, 0.1, 0.9};
// Blocks whose ring has more vertices get no spine (the skeleton's cost grows
// with them; the paper builds spines from a coarse raster).
constexpr std::size_t kMaxSpineVertices = 2000;
constexpr std::size_t kMaxSkeletonEvents = 500000;
// The work budget: lots per block, and ring vertices visited by split lines over all tries.
constexpr std::size_t kMaxLots = 200000;
constexpr std::uint64_t kMaxSplitWork = 400000000;

// The paper's constraints in force: all; then without limited variation; then
// without limited rectangularity either (it keeps parcels within 1:4, which
// the observed parcels mostly are, so it goes last). Minimum size and road access always
// hold. A later level is tried only when no parcel takes a split under the
// earlier one, so that the block still reaches its target count where its
// area and frontage allow.
enum class Relax { None = 0, Variation = 1, Rectangularity = 2 };
constexpr int kRelaxLevels = 3;

double aspectOf(const OrientedBox& b) { return b.length > 0 ? b.width / b.length : 0; }

// Parcels with what the constraints measure of them, each once: the pieces
// of a split, or a subdivision.
struct Lots {
  std::vector<Polygon> polygons;
  std::vector<double> areas;
  std::vector<OrientedBox> boxes;  // minimum-area boxes
  std::vector<char> onRoad;        // sharing at least the least frontage with the block's contour
  // Of an interior parcel, the observed areas drawn for the parcels it is to
  // become (empty: none drawn yet; one: it is one of them, and done).
  std::vector<std::vector<double>> wanted;
  // Of a road parcel, once the block has its observed share of them: no cut
  // along the street left it an interior piece, so it is not split again.
  std::vector<char> closed;
  // Of the pieces of a split: how many are thinner than the block's least
  // aspect, admitted on its thin quota.
  std::size_t thinUsed = 0;
  bool empty() const { return polygons.empty(); }
  bool done(std::size_t i) const { return closed[i] || (!onRoad[i] && wanted[i].size() == 1); }
  std::size_t size() const { return polygons.size(); }
};

// The longest path of the inner skeleton (a tree for a ring without holes):
// the farthest node from any node, then the farthest from it.
std::vector<Point> longestPath(const detail::InnerSkeleton& s) {
  const std::size_t n = s.nodes.size();
  if (n < 2 || s.edges.empty()) return {};
  std::vector<std::vector<std::pair<int, double>>> next(n);
  for (const auto& [a, b] : s.edges) {
    const double l = norm(s.nodes[b].x - s.nodes[a].x, s.nodes[b].y - s.nodes[a].y);
    next[a].push_back({b, l});
    next[b].push_back({a, l});
  }
  auto farthest = [&](int from, std::vector<int>& parent) {
    std::vector<double> dist(n, -1);
    parent.assign(n, -1);
    std::vector<int> stack{from};
    dist[from] = 0;
    int best = from;
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      if (dist[u] > dist[best]) best = u;
      for (const auto& [v, l] : next[u]) {
        if (dist[v] >= 0) continue;
        dist[v] = dist[u] + l;
        parent[v] = u;
        stack.push_back(v);
      }
    }
    return best;
  };
  std::vector<int> parent;
  const int u = farthest(s.edges.front().first, parent);
  const int v = farthest(u, parent);
  std::vector<Point> path;
  for (int k = v; k >= 0; k = parent[k]) path.push_back(s.nodes[k]);
  return path;
}

// The paper's simplification: along the spine, a vertex is kept where the
// turning summed since the last kept one exceeds 20 degrees.
std::vector<Point> simplifySpine(const std::vector<Point>& path) {
  if (path.size() < 3) return path;
  std::vector<Point> out{path.front()};
  double turning = 0;
  for (std::size_t i = 1; i + 1 < path.size(); ++i) {
    turning += detail::angleBetween(detail::unitFrom(path[i - 1], path[i]), detail::unitFrom(path[i], path[i + 1]));
    if (turning > kSpineTurn) {
      out.push_back(path[i]);
      turning = 0;
    }
  }
  out.push_back(path.back());
  return out;
}

// Where the ray from `from` along `dir` first meets the ring: the point and
// the index of the edge; edge -1 when it meets none.
std::pair<Point, int> rayHit(const Ring& ring, const Point& from, const Point& dir) {
  double bestT = std::numeric_limits<double>::infinity();
  int edge = -1;
  Point hit;
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point &a = ring[i], &b = ring[(i + 1) % n];
    const Point e{b.x - a.x, b.y - a.y};
    const double den = dir.x * e.y - dir.y * e.x;
    if (den == 0) continue;
    const Point w{a.x - from.x, a.y - from.y};
    const double t = (w.x * e.y - w.y * e.x) / den;      // along the ray
    const double u = (w.x * dir.y - w.y * dir.x) / den;  // along the edge
    if (t > 0 && u >= 0 && u <= 1 && t < bestT) {
      bestT = t;
      edge = static_cast<int>(i);
      hit = u == 0 ? a : u == 1 ? b : Point{a.x + u * e.x, a.y + u * e.y};
    }
  }
  return {hit, edge};
}

// The block cut in two along its spine (section 3.3.2): the longest path of
// its straight skeleton's inner edges (the medial axis the paper thins a
// raster to find), simplified, its ends carried on along their last segment to
// the block's contour. Empty when the block is not oblong, has holes, or the
// cut does not give two valid pieces.
std::vector<Polygon> spineSplit(const Polygon& block) {
  if (!block.holes.empty() || block.outer.size() > kMaxSpineVertices) return {};
  const OrientedBox box = minimumAreaBox(block.outer);
  if (!(box.width < kOblong * box.length)) return {};
  // The skeleton of the block's sides (its runs of nearly collinear edges, see
  // LotSplit.h), as the paper simplifies the block before subdividing:
  // vertices along a straight street would add skeleton branches into the
  // corners.
  Ring coarse;
  for (const Side& s : detail::sidesOf(block.outer)) coarse.push_back(s.a);
  if (coarse.size() < 3 || signedArea(coarse) <= 0 || !isClearlySimple(coarse)) coarse = block.outer;
  std::vector<Point> spine;
  try {
    spine = simplifySpine(longestPath(detail::innerSkeleton(coarse, kMaxSkeletonEvents)));
  } catch (const std::exception&) {
    detail::rethrowUnlessBlockFailure();
    return {};  // no skeleton: no spine, the block is split at random only
  }
  if (spine.size() < 2) return {};
  const Ring& ring = block.outer;
  const auto [h0, i0] = rayHit(ring, spine.front(), detail::unitFrom(spine[1], spine[0]));
  const auto [h1, i1] = rayHit(ring, spine.back(), detail::unitFrom(spine[spine.size() - 2], spine.back()));
  if (i0 < 0 || i1 < 0 || i0 == i1) return {};
  const std::size_t n = ring.size();
  // One piece runs along the contour from h0 to h1 and back along the spine, the other from h1 to h0.
  auto piece = [&](const Point& from, int fromEdge, const Point& to, int toEdge, bool spineForward) {
    Polygon p;
    p.outer.push_back(from);
    for (std::size_t k = (static_cast<std::size_t>(fromEdge) + 1) % n;; k = (k + 1) % n) {
      p.outer.push_back(ring[k]);
      if (k == static_cast<std::size_t>(toEdge)) break;
    }
    p.outer.push_back(to);
    if (spineForward) {
      p.outer.insert(p.outer.end(), spine.begin(), spine.end());
    } else {
      p.outer.insert(p.outer.end(), spine.rbegin(), spine.rend());
    }
    return p;
  };
  std::vector<Polygon> pieces = {piece(h0, i0, h1, i1, false), piece(h1, i1, h0, i0, true)};
  double sum = 0;
  for (Polygon& p : pieces) {
    if (!normalise(p) || !p.holes.empty() || !(isClearlySimple(p.outer) || geos::isValid(p))) return {};
    sum += area(p);
  }
  const double a = area(block);
  if (std::fabs(sum - a) > 1e-9 * a) return {};
  return pieces;
}

class SextonSubdivider {
public:
  SextonSubdivider(const Polygon& block, const SextonParameters& p, const ObservedSample* observed)
      : block_(block), outline_{block.outer, {}}, p_(p), leastAspect_(leastAspect(observed)) {
    thin_ = thinParcels(observed, leastAspect_);
    // Interior parcels: the block's observed share without street access,
    // behind a street front as deep as its observed street parcels (their
    // median depth: each one's length, or its area over its frontage where
    // that is less), split into the areas of its observed interior
    // parcels. Where access per parcel is unknown, or one kind is missing,
    // all the observed parcels stand for both.
    if (p.interior && observed && std::isfinite(observed->accessShare)) {
      const bool byAccess = observed->access.size() == observed->areas.size() &&
                            observed->access.size() == observed->widths.size() &&
                            observed->access.size() == observed->aspectRatios.size();
      auto front = [&](std::size_t i) { return !byAccess || observed->access[i] != 0; };
      const bool withFrontage = byAccess && observed->frontages.size() == observed->areas.size();
      std::vector<double> lengths, all;
      for (std::size_t i = 0; i < observed->widths.size() && i < observed->aspectRatios.size(); ++i) {
        double l = observed->widths[i] * observed->aspectRatios[i];
        if (!std::isfinite(l) || !(l > 0)) continue;
        all.push_back(l);
        // A street parcel's depth: its area over its frontage, where known and shorter than its length.
        if (withFrontage && observed->frontages[i] > 0) {
          l = std::min(l, observed->areas[i] / observed->frontages[i]);
        }
        if (front(i)) lengths.push_back(l);
      }
      if (lengths.empty()) lengths = std::move(all);
      if (!lengths.empty()) {
        depth_ = quantileOf(std::move(lengths), 0.5);
        for (std::size_t i = 0; i < observed->areas.size(); ++i) {
          if (!byAccess || observed->access[i] == 0) observedAreas_.push_back(observed->areas[i]);
        }
        if (observedAreas_.empty()) observedAreas_ = observed->areas;
        interiorShare_ = std::clamp(1 - observed->accessShare, 0.0, 1.0);
      }
    }
    minArea_ = kMinAreaShare * std::min(p.aMin, smallestObserved(observed));
    const Box b = bounds(block);
    tolerance_ = std::max(1e-6, 1e-9 * (b.width() + b.height()));
    outlineEdges_ = std::make_unique<analysis::PreparedBoundary>(outline_, tolerance_);
    frontage_ = std::max(p.minFrontage, 0.5 * p.wMin);
    const Ring& o = block.outer;
    std::vector<std::pair<IndexBox, std::size_t>> edges;
    for (std::size_t i = 0; i < o.size(); ++i) {
      edges.emplace_back(indexBox(bounds(Ring{o[i], o[(i + 1) % o.size()]}), tolerance_), i);
    }
    outlineTree_ = BoxTree<std::size_t>(edges);
  }

  // One randomized subdivision from `start`, towards `target` parcels.
  Lots subdivide(const std::vector<Polygon>& start, std::size_t target, detail::Rng rng) {
    Lots lots;
    interiorLeft_ = shareOf(interiorShare_, target);
    // Road parcels the block is to have; once there are as many, a road
    // parcel is only cut along the street (its back piece interior).
    const std::size_t roadWanted = target - std::min(target, interiorLeft_);
    std::size_t roadMade = 0;
    thinLeft_ = shareOf(thin_.share, target);
    std::vector<std::vector<Side>> road;  // each parcel's road-facing sides
    for (const Polygon& q : start) {
      lots.polygons.push_back(q);
      lots.areas.push_back(area(q));
      lots.boxes.push_back(minimumAreaBox(q.outer));
      lots.onRoad.push_back(outlineEdges_->sharesAtLeast(q, frontage_));
      lots.wanted.emplace_back();
      lots.closed.push_back(0);
      road.push_back(roadSides(q));
      roadMade += lots.onRoad.back() ? 1 : 0;
    }
    const std::vector<Polygon>& parcels = lots.polygons;
    const std::vector<double>& areas = lots.areas;
    int relaxed = 0;  // once a level is needed, the rest of this subdivision keeps it
    // Parcel `pick` replaced by the pieces of its split. The interior
    // allowance pays for each interior parcel made: a piece without street
    // access, less the parcel split when it had none itself.
    auto apply = [&](std::size_t pick, Lots& pieces) {
      const std::size_t replaced = lots.onRoad[pick] ? 0 : 1;  // interior parcels the split replaces
      std::size_t without = 0;
      for (char on : pieces.onRoad) without += !on;
      interiorLeft_ -= std::min(interiorLeft_, without > replaced ? without - replaced : 0);
      roadMade += pieces.size() - without;
      roadMade -= lots.onRoad[pick] ? 1 : 0;
      thinLeft_ -= std::min(thinLeft_, pieces.thinUsed);
      for (std::size_t k = 0; k < pieces.size(); ++k) {
        const std::size_t at = k == 0 ? pick : lots.size();
        if (k > 0) {
          lots.polygons.emplace_back();
          lots.areas.push_back(0);
          lots.boxes.emplace_back();
          lots.onRoad.push_back(0);
          lots.wanted.emplace_back();
          lots.closed.push_back(0);
          road.emplace_back();
        }
        lots.polygons[at] = std::move(pieces.polygons[k]);
        lots.areas[at] = pieces.areas[k];
        lots.boxes[at] = pieces.boxes[k];
        lots.onRoad[at] = pieces.onRoad[k];
        lots.wanted[at] = k < pieces.wanted.size() ? std::move(pieces.wanted[k]) : std::vector<double>{};
        lots.closed[at] = 0;
        road[at] = roadSides(lots.polygons[at]);
      }
    };
    while (parcels.size() < target) {
      // The largest parcel not done first; when it takes no split, random
      // ones; when none does, again with the constraints relaxed one by one
      // (see Relax).
      // Road parcels are held to cuts along the street only while an
      // interior parcel is left to split: otherwise (a block of no observed
      // road parcels starts as one road parcel; or every interior parcel is
      // done) the closed ones open again and are split as the paper's are.
      bool interiorOpen = false;
      for (std::size_t i = 0; i < parcels.size() && !interiorOpen; ++i) interiorOpen = !lots.onRoad[i] && !lots.done(i);
      roadOnly_ = roadMade >= roadWanted && interiorLeft_ > 0 && interiorOpen;
      if (!roadOnly_) std::fill(lots.closed.begin(), lots.closed.end(), 0);
      std::size_t largest = 0;
      for (std::size_t i = 1; i < parcels.size(); ++i) {
        if (lots.done(largest) || (!lots.done(i) && areas[i] > areas[largest])) largest = i;
      }
      bool done = false;
      for (int round = relaxed * (kAttempts + 1); round < kRelaxLevels * (kAttempts + 1) && !done; ++round) {
        const int level = round / (kAttempts + 1);
        const bool first = round % (kAttempts + 1) == 0;
        const std::size_t pick =
            first ? largest : static_cast<std::size_t>(rng.uniform() * static_cast<double>(parcels.size()));
        Lots pieces;
        for (int attempt = 0; attempt < (first ? kAttempts : 1) && pieces.empty(); ++attempt) {
          pieces = trySplit(parcels[pick], areas[pick], lots.boxes[pick], lots.onRoad[pick], road[pick],
                            lots.wanted[pick], target + 1 - parcels.size(), static_cast<Relax>(level), rng);
        }
        if (pieces.empty() && first && roadOnly_ && lots.onRoad[pick] && !lots.done(pick)) {
          // A road parcel too shallow for a cut along the street, once the
          // block has its road parcels: closed, and the next largest is split.
          lots.closed[pick] = 1;
          done = true;
          break;
        }
        if (pieces.empty()) continue;
        relaxed = level;
        apply(pick, pieces);
        done = true;
      }
      if (!done) {
        // No random line made it: the positions along the road sides of the
        // largest parcels, in turn, with the constraints relaxed as far as they go.
        // A block's scans are bounded (scansLeft_): a try without any left stops short.
        if (scansLeft_ == 0) break;
        --scansLeft_;
        scanning_ = true;
        auto [pick, pieces] = scanSplit(lots, road, target + 1 - parcels.size());
        scanning_ = false;
        if (pieces.empty()) break;  // no parcel takes an admissible split
        relaxed = kRelaxLevels - 1;
        apply(pick, pieces);
      }
      if (parcels.size() > kMaxLots) throw detail::WorkBudgetExceeded("work budget: more than 200000 parcels");
    }
    return lots;
  }

  bool hasAccess(const Polygon& p) const { return outlineEdges_->sharesAtLeast(p, p_.minFrontage); }

  /// Scans (scanSplit) the block's tries may make in all.
  void setScanBudget(std::size_t scans) { scansLeft_ = scans; }

private:
  // Which pieces of a split must have road access: all (the paper's
  // splits); all but one, of two (the back piece of a cut along the street);
  // none, of an interior parcel's split, as many lacking it as the block's
  // interior allowance pays for.
  enum class Access { All, Back, Interior };

  // The areas of observed parcels, drawn at random, that an interior parcel
  // of area `parcelArea` is to become: drawn until they sum to about its
  // area (the last one kept when that brings the sum closer), at most `most`.
  std::vector<double> drawAreas(double parcelArea, std::size_t most, detail::Rng& rng) const {
    std::vector<double> drawn;
    double sum = 0;
    while (sum < parcelArea && drawn.size() < std::max<std::size_t>(1, most)) {
      drawn.push_back(
          observedAreas_[static_cast<std::size_t>(rng.uniform() * static_cast<double>(observedAreas_.size()))]);
      sum += drawn.back();
    }
    if (drawn.size() > 1 && sum - parcelArea > parcelArea - (sum - drawn.back())) drawn.pop_back();
    return drawn;
  }

  // A random split of `parcel` across one of its road-facing sides, or
  // nothing when it breaks one of the paper's constraints. `box`: the
  // parcel's minimum-area box; `onRoad`: whether it has the least frontage
  // (else it is an interior parcel, even with a short road side); `wanted`:
  // an interior parcel's drawn areas (see Lots).
  Lots trySplit(const Polygon& parcel, double parcelArea, const OrientedBox& box, bool onRoad,
                const std::vector<Side>& road, std::vector<double>& wanted, std::size_t maxPieces, Relax relax,
                detail::Rng& rng) {
    const double aspect = aspectOf(box);
    if (!onRoad) return splitInterior(parcel, parcelArea, box, wanted, maxPieces, relax, rng);
    if (road.empty()) return {};  // frontage along edges, but no side wholly on the street
    const Side& s = road[static_cast<std::size_t>(rng.uniform() * static_cast<double>(road.size()))];
    if (interiorLeft_ > 0 && depth_ > 0 && (roadOnly_ || rng.uniform() < interiorShare_)) {
      // Along the street, at the observed depth: the back piece an interior parcel.
      const Point mid{0.5 * (s.a.x + s.b.x), 0.5 * (s.a.y + s.b.y)}, inward{-s.dir.y, s.dir.x};
      const SplitLine line{{mid.x + depth_ * inward.x, mid.y + depth_ * inward.y}, s.dir};
      Lots pieces = cutAlong(parcel, parcelArea, aspect, line, maxPieces, relax, Access::Back);
      if (!pieces.empty() || roadOnly_) return pieces;
    }
    const double f = std::clamp(0.5 + kPositionSd * rng.normal(), 0.05, 0.95);
    return splitAt(parcel, parcelArea, aspect, s, f, maxPieces, relax);
  }

  // An interior parcel, split again while the block's interior allowance
  // lasts into pieces that may all lack street access: the observed areas it
  // is to become (`wanted`, drawn when none are) are shuffled into two groups,
  // and the parcel is cut across its box's long axis where the first group's
  // share of their sum falls; each piece takes its group. A parcel to become
  // one drawn area is done; a list that gives no admissible cut is drawn again
  // at the next attempt.
  Lots splitInterior(const Polygon& parcel, double parcelArea, const OrientedBox& box, std::vector<double>& wanted,
                     std::size_t maxPieces, Relax relax, detail::Rng& rng) {
    if (interiorLeft_ == 0 || observedAreas_.empty() || !(box.length > 0)) return {};
    if (wanted.empty()) wanted = drawAreas(parcelArea, maxPieces, rng);
    if (wanted.size() < 2) return {};
    // Two groups of about equal sums, largest area first, each to the lighter
    // group, on a random side of the line.
    std::sort(wanted.begin(), wanted.end(), std::greater<>());
    std::vector<double> group[2];
    double sum[2] = {0, 0};
    for (double a : wanted) {
      const int g = sum[1] < sum[0] ? 1 : 0;
      group[g].push_back(a);
      sum[g] += a;
    }
    if (rng.uniform() < 0.5) {
      std::swap(group[0], group[1]);
      std::swap(sum[0], sum[1]);
    }
    const double at = (sum[0] / (sum[0] + sum[1]) - 0.5) * box.length;  // from the box's centre
    const SplitLine line{{box.center.x + at * box.u.x, box.center.y + at * box.u.y}, {-box.u.y, box.u.x}};
    Lots pieces = cutAlong(parcel, parcelArea, aspectOf(box), line, maxPieces, relax, Access::Interior);
    if (pieces.empty()) {
      // No admissible cut: the smallest area drawn joins the largest, the
      // parcel is to become one parcel fewer.
      wanted.front() += wanted.back();
      wanted.pop_back();
      return {};
    }
    if (pieces.size() == 2) {
      // The piece before the line along the box's axis takes the first group.
      auto along = [&](const OrientedBox& b) {
        return (b.center.x - box.center.x) * box.u.x + (b.center.y - box.center.y) * box.u.y;
      };
      const bool swapped = along(pieces.boxes[0]) > along(pieces.boxes[1]);
      pieces.wanted.assign(2, {});
      pieces.wanted[swapped ? 1 : 0] = std::move(group[0]);
      pieces.wanted[swapped ? 0 : 1] = std::move(group[1]);
    }
    return pieces;
  }

  // The first admissible split, at the most relaxed level, of the
  // kScanParcels largest parcels (largest first) at the positions kScanAt
  // along each of their road sides: the parcel's index and its pieces.
  std::pair<std::size_t, Lots> scanSplit(const Lots& lots, const std::vector<std::vector<Side>>& road,
                                         std::size_t maxPieces) {
    const std::vector<Polygon>& parcels = lots.polygons;
    const std::vector<double>& areas = lots.areas;
    std::vector<std::size_t> order(parcels.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    const std::size_t n = std::min(order.size(), kScanParcels);
    std::partial_sort(order.begin(), order.begin() + static_cast<long>(n), order.end(),
                      [&](std::size_t a, std::size_t b) { return areas[a] > areas[b]; });
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = order[k];
      for (const Side& s : road[i]) {
        for (double f : kScanAt) {
          Lots pieces = splitAt(parcels[i], areas[i], aspectOf(lots.boxes[i]), s, f, maxPieces, Relax::Rectangularity);
          if (!pieces.empty()) return {i, std::move(pieces)};
        }
      }
    }
    return {0, {}};
  }

  // The split of `parcel` at right angles to road side `s`, at fraction `f` along it.
  Lots splitAt(const Polygon& parcel, double parcelArea, double aspect, const Side& s, double f, std::size_t maxPieces,
               Relax relax, Access access = Access::All) {
    const SplitLine line{{s.a.x + f * (s.b.x - s.a.x), s.a.y + f * (s.b.y - s.a.y)}, {-s.dir.y, s.dir.x}};
    return cutAlong(parcel, parcelArea, aspect, line, maxPieces, relax, access);
  }

  // The split of `parcel` (aspect `before`) by `line`, when admissible.
  Lots cutAlong(const Polygon& parcel, double parcelArea, double before, const SplitLine& line, std::size_t maxPieces,
                Relax relax, Access access) {
    work_ += parcel.outer.size();
    if (work_ > kMaxSplitWork)
      throw detail::WorkBudgetExceeded("work budget: more than 4e8 vertices visited by split lines");
    Lots measured;  // of the pieces last found admissible
    auto admissible = [&](const std::vector<Polygon>& pieces) {
      // Two pieces, as the paper's splits make; more, once the constraints
      // are relaxed, where a concave parcel leaves no line that makes two
      // (never beyond the target count).
      if (pieces.size() < 2 || pieces.size() > (relax == Relax::None ? 2 : maxPieces)) return false;
      measured.areas.clear();
      measured.boxes.clear();
      measured.onRoad.clear();
      measured.thinUsed = 0;
      for (const Polygon& q : pieces) {
        const double a = area(q);
        if (a < minArea_) return false;  // minimum size
        if (relax < Relax::Variation && access != Access::Interior && a < kMinPieceShare * parcelArea) {
          return false;  // limited variation
        }
        measured.areas.push_back(a);
      }
      // The thin quota may admit what the limit refuses: a piece of a parcel
      // no thinner than the limit (of any parcel, with rectangularity
      // relaxed), down to the block's thinnest observed parcels.
      const bool quotaOpen = before > leastAspect_ || relax == Relax::Rectangularity;
      for (std::size_t k = 0; k < pieces.size(); ++k) {
        measured.boxes.push_back(minimumAreaBox(pieces[k].outer));
        const double aspect = aspectOf(measured.boxes.back());
        // Limited rectangularity, or with it relaxed, no sliver thinner than
        // the observed ones where the parcel split was none.
        const bool refused = relax < Relax::Rectangularity
                                 ? (before > leastAspect_ ? aspect < leastAspect_ : aspect <= before)
                                 : aspect < leastAspect_ && aspect < before;
        if (!refused) continue;
        if (!quotaOpen || aspect < thin_.least || measured.areas[k] < thin_.area || measured.thinUsed >= thinLeft_) {
          return false;
        }
        ++measured.thinUsed;
      }
      std::size_t without = 0;
      for (const Polygon& q : pieces) {
        measured.onRoad.push_back(outlineEdges_->sharesAtLeast(q, frontage_));  // road access
        without += !measured.onRoad.back();
      }
      switch (access) {
        case Access::All:
          return without == 0;
        case Access::Back:
          return without == 1 && pieces.size() == 2;
        case Access::Interior:
          return without <= interiorLeft_ + 1;
      }
      return false;
    };
    // Random lines are many: one the floating-point split cannot make (it meets
    // a hole) is dropped rather than made exactly, except on parcels without
    // holes, where that happens only for a line through a vertex. Only the
    // scan's lines (scanSplit) meeting a hole are made exactly: random ones
    // at every level took seoul_jamsil's holed block about ten times as long,
    // for parcels no closer to the observed ones.
    const bool exact = parcel.holes.empty() || scanning_;
    measured.polygons = detail::splitLot(parcel, parcelArea, line, exact, admissible);
    if (measured.polygons.empty()) return {};
    return measured;
  }

  // The sides of `parcel` every edge of which lies on the block's outer
  // contour (its midpoint within the tolerance of a contour edge).
  std::vector<Side> roadSides(const Polygon& parcel) const {
    std::vector<Side> road;
    const Ring& ring = parcel.outer;
    for (const Side& s : detail::sidesOf(ring)) {
      bool on = true;
      for (std::size_t k = 0; k < s.edges && on; ++k) {
        const Point& a = ring[(s.first + k) % ring.size()];
        const Point& b = ring[(s.first + k + 1) % ring.size()];
        on = onOutline({0.5 * (a.x + b.x), 0.5 * (a.y + b.y)});
      }
      if (on) road.push_back(s);
    }
    return road;
  }

  bool onOutline(const Point& m) const {
    namespace bgi = boost::geometry::index;
    const Ring& o = block_.outer;
    for (auto it = outlineTree_.qbegin(bgi::intersects(IndexPoint(m.x, m.y))); it != outlineTree_.qend(); ++it) {
      const std::size_t i = it->second;
      if (pointSegmentDistance(m, o[i], o[(i + 1) % o.size()]) <= tolerance_) return true;
    }
    return false;
  }

  const Polygon& block_;
  const Polygon outline_;
  SextonParameters p_;
  double leastAspect_ = kSliverAspect;
  double interiorShare_ = 0;           // observed share of parcels without street access
  double depth_ = 0;                   // the observed street parcels' median length
  std::vector<double> observedAreas_;  // with interior parcels: the observed interior parcels' areas
  std::size_t interiorLeft_ = 0;       // interior parcels this try may still make
  ThinParcels thin_;                   // the block's observed parcels thinner than leastAspect_
  std::size_t thinLeft_ = 0;           // pieces thinner than leastAspect_ this try may still make
  bool roadOnly_ = false;              // the block has its road parcels: road parcels only cut along the street
  double tolerance_ = 1e-6;
  double minArea_ = 0;  // the least area of a piece
  double frontage_ = 1;
  std::unique_ptr<analysis::PreparedBoundary> outlineEdges_;
  BoxTree<std::size_t> outlineTree_;  // the outer contour's edges, by index
  std::size_t scansLeft_ = 0;
  bool scanning_ = false;  // in scanSplit: lines meeting a hole are made with the exact split
  std::uint64_t work_ = 0;
};

// How far a subdivision is from the block's observed parcels: the KS of area,
// of width and of aspect ratio (MBR sides, as the metrics measure them) plus
// the relative count error; the count error alone without observed parcels.
double distanceTo(const Lots& parcels, const ObservedSample* observed, std::size_t target) {
  const double countError =
      std::fabs(static_cast<double>(parcels.size()) / static_cast<double>(std::max<std::size_t>(1, target)) - 1);
  if (!observed || observed->areas.empty()) return countError;
  std::vector<double> widths, aspects;
  for (const OrientedBox& box : parcels.boxes) {
    widths.push_back(box.width);
    aspects.push_back(box.width > 0 ? box.length / box.width : 0);
  }
  const std::vector<double>& areas = parcels.areas;
  double d = countError;
  for (const auto& [made, seen] :
       {std::pair{&areas, &observed->areas}, std::pair{&std::as_const(widths), &observed->widths},
        std::pair{&std::as_const(aspects), &observed->aspectRatios}}) {
    if (!seen->empty()) d += analysis::ksStatistic(*made, *seen);
  }
  return d;
}

Subdivision subdivideSexton(const StyleRun& r) {
  const SextonParameters p = sextonParametersFrom(r.values);
  return detail::runNearOrigin(
      r.block, obbParametersFrom(r.values), r.seed, [&](const Polygon& local, Subdivision& out) {
        double target = p.count;
        if (target <= 0 && r.observed && !r.observed->areas.empty()) {
          target = std::round(static_cast<double>(r.observed->areas.size()) * r.observedShare);
        } else if (target <= 0) {
          target = std::round(area(local) / (0.5 * (p.aMin + std::max(p.aMin, p.aMax))));
        }
        target = std::max(1.0, target);
        if (target > static_cast<double>(kMaxLots)) {
          out.failed = true;
          out.failure = "work budget: a target of " + std::to_string(static_cast<long long>(std::min(target, 1e18))) +
                        " parcels, more than " + std::to_string(kMaxLots);
          return;
        }
        const auto wanted = static_cast<std::size_t>(target);
        std::vector<Polygon> start = spineSplit(local);
        // More spine pieces than parcels wanted: the spine is dropped (3.4.1).
        if (start.empty() || start.size() > wanted) start = {local};
        SextonSubdivider subdivider(local, p, r.observed);
        subdivider.setScanBudget(wanted);  // as many scans as parcels wanted, over all tries
        // The try closest to the observed parcels among those that reached the
        // target count (when none did, among all).
        std::pair<bool, double> best{true, std::numeric_limits<double>::infinity()};
        for (int t = 0; t < std::max(1, p.tries); ++t) {
          Lots parcels = subdivider.subdivide(
              start, wanted, detail::Rng{detail::splitmix64(r.seed ^ (0x5E7701ULL + static_cast<std::uint64_t>(t)))});
          const std::pair<bool, double> d{parcels.size() != wanted, distanceTo(parcels, r.observed, wanted)};
          if (d < best) {
            best = d;
            out.parcels = std::move(parcels.polygons);
          }
        }
        out.targetParcels = static_cast<int>(wanted);
        for (const Polygon& q : out.parcels) out.withoutAccess += !subdivider.hasAccess(q);
      });
}

class SextonStyle : public Style {
public:
  std::string name() const override { return "sexton"; }
  std::string description() const override {
    return "spine along oblong blocks, then random splits of the largest parcel across a road-facing side to the "
           "observed count, best of many tries (Sexton & Watson 2010)";
  }
  const std::vector<ParameterDescription>& parameters() const override { return sextonParameterDescriptions(); }
  Subdivision run(const StyleRun& r) const override { return subdivideSexton(r); }
};

}  // namespace

const Style& sextonStyle() {
  static const SextonStyle s;
  return s;
}

}  // namespace parcelscope::generation
