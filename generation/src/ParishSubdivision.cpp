// parish: the recursive lot subdivision of Parish & Müller 2001 (section 4,
// "Division into lots"), as Vanegas et al. 2012 (section 2) describe it: a lot
// is split across its longest pair of approximately parallel edges until it is
// under a threshold area; lots without street access are discarded. The
// discarded land is kept, as parcels marked unassigned (Subdivision::
// unassignedParcels), so that the result still tiles the block and the gaps
// are measured. docs/algorithms/parish.md gives the choices the paper leaves
// open.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "BlockFailure.h"
#include "LocalShift.h"
#include "LotSplit.h"
#include "PolygonSplit.h"
#include "PostProcess.h"
#include "parcelscope/analysis/Metrics.h"
#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/generation/Styles.h"

namespace parcelscope::generation {

namespace {

const ParameterDescription& describedIn(const std::vector<ParameterDescription>& list, const std::string& name) {
  for (const ParameterDescription& d : list) {
    if (d.name == name) return d;
  }
  throw std::logic_error("no parameter " + name);
}

const std::vector<ParameterDescription>& parishParameterDescriptions() {
  static const std::vector<ParameterDescription> d = {
      describedIn(obbParameterDescriptions(), "a-max"),
      realParameter("parallel-angle",
                    "parish: two edges of a lot within this angle of each other count as approximately parallel", "deg",
                    0.0, 45.0, 15.0, "Subdivision"),
      analysis::minFrontageParameter(),
  };
  return d;
}

struct ParishParameters {
  double aMax = 800;          // m², lots above this are split
  double parallelAngle = 15;  // degrees
  double minFrontage = 1;     // m of block contour for street access
};

ParishParameters parishParametersFrom(const ParameterValues& v) {
  ParishParameters p;
  readValue(v, "a-max", p.aMax);
  readValue(v, "parallel-angle", p.parallelAngle);
  readValue(v, "min-frontage", p.minFrontage);
  return p;
}

// A split must leave every piece at least this share of the lot's area (a cut
// next to a vertex would otherwise make crumbs) and none above 1 minus it (so
// every accepted split shrinks the lot and the recursion ends).
constexpr double kMinPieceShare = 0.02;
// Lots made per block and ring vertices visited by split lines, beyond which a
// block comes back whole, failed (the OBB style's budget, docs/algorithms/obb.md).
constexpr std::size_t kMaxLots = 200000;
constexpr std::uint64_t kMaxSplitWork = 400000000;

using detail::angleBetween;
using detail::Side;
using detail::sidesOf;
using detail::SplitLine;
using detail::unitFrom;

// The split lines of a lot, best first. First the pairs of approximately
// parallel sides facing each other (opposite directions, overlapping when
// projected on their mean direction), longest pair (sum of lengths) first:
// the line crosses both at right angles to their mean direction, halfway along
// their overlap. Then, for lots without such a pair (triangles), the line
// across each of the three longest sides at its midpoint.
std::vector<SplitLine> splitLines(const Ring& ring, double parallelAngle) {
  const std::vector<Side> sides = sidesOf(ring);
  struct Pair {
    double score;
    SplitLine line;
  };
  std::vector<Pair> pairs;
  const double tolerance = parallelAngle * kPi / 180.0;
  for (std::size_t i = 0; i < sides.size(); ++i) {
    for (std::size_t j = i + 1; j < sides.size(); ++j) {
      const Side &s = sides[i], &t = sides[j];
      if (angleBetween(s.dir, Point{-t.dir.x, -t.dir.y}) > tolerance) continue;
      const Point d = unitFrom({0, 0}, {s.dir.x - t.dir.x, s.dir.y - t.dir.y});
      auto along = [&](const Point& p) { return p.x * d.x + p.y * d.y; };
      const double lo = std::max(std::min(along(s.a), along(s.b)), std::min(along(t.a), along(t.b)));
      const double hi = std::min(std::max(along(s.a), along(s.b)), std::max(along(t.a), along(t.b)));
      if (hi <= lo) continue;
      const double middle = 0.5 * (lo + hi);
      pairs.push_back({s.length + t.length, {{middle * d.x, middle * d.y}, {-d.y, d.x}}});
    }
  }
  std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.score > b.score; });
  std::vector<SplitLine> lines;
  for (const Pair& p : pairs) lines.push_back(p.line);
  std::vector<Side> longest = sides;
  std::stable_sort(longest.begin(), longest.end(), [](const Side& a, const Side& b) { return a.length > b.length; });
  for (std::size_t i = 0; i < longest.size() && i < 3; ++i) {
    const Side& s = longest[i];
    lines.push_back({{0.5 * (s.a.x + s.b.x), 0.5 * (s.a.y + s.b.y)}, {-s.dir.y, s.dir.x}});
  }
  return lines;
}

class ParishSubdivider {
public:
  ParishSubdivider(const Polygon& block, const ParishParameters& p) : block_(block), outline_{block.outer, {}}, p_(p) {
    const Box b = bounds(block);
    outlineEdges_ =
        std::make_unique<analysis::PreparedBoundary>(outline_, std::max(1e-6, 1e-9 * (b.width() + b.height())));
  }

  // The lots, assigned first, then those without street access; returns how
  // many lots did not reach the threshold (no admissible split).
  void run(Subdivision& out) {
    std::vector<Polygon> pending{block_}, assigned, unassigned;
    while (!pending.empty()) {
      Polygon lot = std::move(pending.back());
      pending.pop_back();
      const double a = area(lot);
      std::vector<Polygon> pieces;
      if (a > p_.aMax) {
        pieces = split(lot, a);
        if (pieces.empty()) ++out.oversize;
      }
      if (pieces.empty()) {
        (outlineEdges_->sharesAtLeast(lot, p_.minFrontage) ? assigned : unassigned).push_back(std::move(lot));
        if (assigned.size() + unassigned.size() > kMaxLots)
          throw detail::WorkBudgetExceeded("work budget: more than 200000 lots");
        continue;
      }
      // Depth first, in the pieces' order: the first piece is finished first.
      for (auto it = pieces.rbegin(); it != pieces.rend(); ++it) pending.push_back(std::move(*it));
    }
    out.parcels = std::move(assigned);
    out.unassignedParcels = static_cast<int>(unassigned.size());
    for (Polygon& q : unassigned) out.parcels.push_back(std::move(q));
  }

private:
  // The pieces of the first admissible split line, or nothing.
  std::vector<Polygon> split(const Polygon& lot, double lotArea) {
    std::size_t vertices = lot.outer.size();
    for (const Ring& h : lot.holes) vertices += h.size();
    for (const SplitLine& line : splitLines(lot.outer, p_.parallelAngle)) {
      work_ += vertices;
      if (work_ > kMaxSplitWork)
        throw detail::WorkBudgetExceeded("work budget: more than 4e8 vertices visited by split lines");
      std::vector<Polygon> pieces = piecesOf(lot, lotArea, line);
      if (!pieces.empty()) return pieces;
    }
    return {};
  }

  // The pieces of the split, or nothing when a piece is too small (see kMinPieceShare).
  static std::vector<Polygon> piecesOf(const Polygon& lot, double lotArea, const SplitLine& line) {
    const auto shared = [&](const std::vector<Polygon>& pieces) {
      for (const Polygon& q : pieces) {
        const double share = area(q) / lotArea;
        if (share < kMinPieceShare || share > 1 - kMinPieceShare) return false;
      }
      return true;
    };
    std::vector<Polygon> pieces = detail::splitLot(lot, lotArea, line, true, shared);
    return shared(pieces) ? pieces : std::vector<Polygon>{};
  }

  const Polygon& block_;
  const Polygon outline_;
  ParishParameters p_;
  std::unique_ptr<analysis::PreparedBoundary> outlineEdges_;
  std::uint64_t work_ = 0;
};

Subdivision subdivideParish(const Polygon& block, const ParishParameters& p, const ObbParameters& bounds,
                            std::uint64_t seed) {
  return detail::runNearOrigin(block, bounds, seed, [&](const Polygon& local, Subdivision& out) {
    if (const double least = area(local) / p.aMax; least > kMaxLots) {
      out.failed = true;
      out.failure = "work budget: area / A_max = " + std::to_string(static_cast<long long>(std::min(least, 1e18))) +
                    " lots, more than " + std::to_string(kMaxLots);
      return;
    }
    ParishSubdivider(local, p).run(out);
  });
}

class ParishStyle : public Style {
public:
  std::string name() const override { return "parish"; }
  std::string description() const override {
    return "recursive split of the longest parallel edges, lots without street access left unassigned (Parish & "
           "Muller 2001)";
  }
  const std::vector<ParameterDescription>& parameters() const override { return parishParameterDescriptions(); }
  Subdivision run(const StyleRun& r) const override {
    return subdivideParish(r.block, parishParametersFrom(r.values), obbParametersFrom(r.values), r.seed);
  }
};

}  // namespace

const Style& parishStyle() {
  static const ParishStyle s;
  return s;
}

}  // namespace parcelscope::generation
