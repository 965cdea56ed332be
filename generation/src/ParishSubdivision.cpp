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
  if (auto it = v.find("a-max"); it != v.end()) p.aMax = it->second;
  if (auto it = v.find("parallel-angle"); it != v.end()) p.parallelAngle = it->second;
  if (auto it = v.find("min-frontage"); it != v.end()) p.minFrontage = it->second;
  return p;
}

// Consecutive edges of a ring turning by less than this from the run they
// continue are one side of the lot: real blocks carry many vertices along a
// straight street, and a lot's "edge" in the paper's sense is the street front.
constexpr double kSideTurn = 10.0 * kPi / 180.0;
// A split must leave every piece at least this share of the lot's area (a cut
// next to a vertex would otherwise make crumbs) and none above 1 minus it (so
// every accepted split shrinks the lot and the recursion ends).
constexpr double kMinPieceShare = 0.02;
// Lots made per block and ring vertices visited by split lines, beyond which a
// block comes back whole, failed (the OBB style's budget, docs/algorithms/obb.md).
constexpr std::size_t kMaxLots = 200000;
constexpr std::uint64_t kMaxSplitWork = 400000000;

struct Side {
  Point a, b;  // first and last vertex of the run
  double length = 0;
  Point dir;  // unit, a to b
};

Point unit(const Point& a, const Point& b) {
  const double n = norm(b.x - a.x, b.y - a.y);
  return n > 0 ? Point{(b.x - a.x) / n, (b.y - a.y) / n} : Point{1, 0};
}

double angleBetween(const Point& u, const Point& v) {
  return std::atan2(std::fabs(u.x * v.y - u.y * v.x), u.x * v.x + u.y * v.y);
}

// The sides of a ring: maximal runs of edges each within kSideTurn of the
// run's chord so far. The runs start at a corner, so none wraps around.
std::vector<Side> sidesOf(const Ring& ring) {
  const std::size_t n = ring.size();
  std::vector<Side> sides;
  if (n < 3) return sides;
  auto edgeDir = [&](std::size_t i) { return unit(ring[i], ring[(i + 1) % n]); };
  std::size_t start = 0;
  double sharpest = -1;
  for (std::size_t i = 0; i < n; ++i) {
    const double turn = angleBetween(edgeDir((i + n - 1) % n), edgeDir(i));
    if (turn > sharpest) {
      sharpest = turn;
      start = i;
    }
  }
  Side run{ring[start], ring[(start + 1) % n], 0, edgeDir(start)};
  run.length = norm(run.b.x - run.a.x, run.b.y - run.a.y);
  for (std::size_t k = 1; k <= n; ++k) {
    const std::size_t i = (start + k) % n;
    if (k < n && angleBetween(run.dir, edgeDir(i)) < kSideTurn) {
      run.b = ring[(i + 1) % n];
      run.dir = unit(run.a, run.b);
      run.length = norm(run.b.x - run.a.x, run.b.y - run.a.y);
      continue;
    }
    sides.push_back(run);
    if (k < n) {
      run = {ring[i], ring[(i + 1) % n], 0, edgeDir(i)};
      run.length = norm(run.b.x - run.a.x, run.b.y - run.a.y);
    }
  }
  return sides;
}

struct Line {
  Point through, dir;
};

// The split lines of a lot, best first. First the pairs of approximately
// parallel sides facing each other (opposite directions, overlapping when
// projected on their mean direction), longest pair (sum of lengths) first:
// the line crosses both at right angles to their mean direction, halfway along
// their overlap. Then, for lots without such a pair (triangles), the line
// across each of the three longest sides at its midpoint.
std::vector<Line> splitLines(const Ring& ring, double parallelAngle) {
  const std::vector<Side> sides = sidesOf(ring);
  struct Pair {
    double score;
    Line line;
  };
  std::vector<Pair> pairs;
  const double tolerance = parallelAngle * kPi / 180.0;
  for (std::size_t i = 0; i < sides.size(); ++i) {
    for (std::size_t j = i + 1; j < sides.size(); ++j) {
      const Side &s = sides[i], &t = sides[j];
      if (angleBetween(s.dir, Point{-t.dir.x, -t.dir.y}) > tolerance) continue;
      const Point d = unit({0, 0}, {s.dir.x - t.dir.x, s.dir.y - t.dir.y});
      auto along = [&](const Point& p) { return p.x * d.x + p.y * d.y; };
      const double lo = std::max(std::min(along(s.a), along(s.b)), std::min(along(t.a), along(t.b)));
      const double hi = std::min(std::max(along(s.a), along(s.b)), std::max(along(t.a), along(t.b)));
      if (hi <= lo) continue;
      const double middle = 0.5 * (lo + hi);
      pairs.push_back({s.length + t.length, {{middle * d.x, middle * d.y}, {-d.y, d.x}}});
    }
  }
  std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.score > b.score; });
  std::vector<Line> lines;
  for (const Pair& p : pairs) lines.push_back(p.line);
  std::vector<Side> longest = sides;
  std::stable_sort(longest.begin(), longest.end(), [](const Side& a, const Side& b) { return a.length > b.length; });
  for (std::size_t i = 0; i < longest.size() && i < 3; ++i) {
    const Side& s = longest[i];
    lines.push_back({{0.5 * (s.a.x + s.b.x), 0.5 * (s.a.y + s.b.y)}, {-s.dir.y, s.dir.x}});
  }
  return lines;
}

bool validPiece(const Polygon& p) { return (p.holes.empty() && isClearlySimple(p.outer)) || geos::isValid(p); }

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
        if (assigned.size() + unassigned.size() > kMaxLots) throw OverBudget("work budget: more than 200000 lots");
        continue;
      }
      // Depth first, in the pieces' order: the first piece is finished first.
      for (auto it = pieces.rbegin(); it != pieces.rend(); ++it) pending.push_back(std::move(*it));
    }
    out.parcels = std::move(assigned);
    out.unassignedParcels = static_cast<int>(unassigned.size());
    for (Polygon& q : unassigned) out.parcels.push_back(std::move(q));
  }

  struct OverBudget : std::runtime_error {
    using std::runtime_error::runtime_error;
  };

private:
  // The pieces of the first admissible split line, or nothing.
  std::vector<Polygon> split(const Polygon& lot, double lotArea) {
    std::size_t vertices = lot.outer.size();
    for (const Ring& h : lot.holes) vertices += h.size();
    for (const Line& line : splitLines(lot.outer, p_.parallelAngle)) {
      work_ += vertices;
      if (work_ > kMaxSplitWork) throw OverBudget("work budget: more than 4e8 vertices visited by split lines");
      std::vector<Polygon> pieces = piecesOf(lot, lotArea, line);
      if (!pieces.empty()) return pieces;
    }
    return {};
  }

  // Floating point first (its pieces kept when they are valid and keep the
  // lot's area), the exact split otherwise; nothing when a piece is too small
  // or invalid.
  static std::vector<Polygon> piecesOf(const Polygon& lot, double lotArea, const Line& line) {
    detail::SplitPieces split;
    bool fast = detail::splitByLineFast(lot, line.through, line.dir, split) && !split.pinched;
    std::vector<Polygon> pieces;
    if (fast) {
      pieces = joined(std::move(split));
      double sum = 0;
      for (const Polygon& q : pieces) sum += area(q);
      fast = std::fabs(sum - lotArea) <= 1e-9 * lotArea && std::all_of(pieces.begin(), pieces.end(), validPiece);
    }
    if (!fast) {
      pieces = joined(detail::splitByLine(lot, line.through, line.dir));
      if (!std::all_of(pieces.begin(), pieces.end(), validPiece)) return {};
    }
    if (pieces.size() < 2) return {};
    for (const Polygon& q : pieces) {
      const double share = area(q) / lotArea;
      if (share < kMinPieceShare || share > 1 - kMinPieceShare) return {};
    }
    return pieces;
  }

  static std::vector<Polygon> joined(detail::SplitPieces&& split) {
    std::vector<Polygon> parts = std::move(split.left);
    parts.insert(parts.end(), std::make_move_iterator(split.right.begin()), std::make_move_iterator(split.right.end()));
    return parts;
  }

  const Polygon& block_;
  const Polygon outline_;
  ParishParameters p_;
  std::unique_ptr<analysis::PreparedBoundary> outlineEdges_;
  std::uint64_t work_ = 0;
};

Subdivision subdivideParish(const Polygon& block, const ParishParameters& p, const ObbParameters& bounds,
                            std::uint64_t seed) {
  const Point o = detail::exactShiftOrigin(block);
  Polygon local = detail::translated(block, -o.x, -o.y);
  Subdivision out;
  std::string reason;
  try {
    if (!normalise(local) || !detail::isValidForSplit(local)) {
      throw detail::StyleFailure("the block is not a valid polygon with holes");
    }
    if (const double least = area(local) / p.aMax; least > kMaxLots) {
      out.failed = true;
      out.failure = "work budget: area / A_max = " + std::to_string(static_cast<long long>(std::min(least, 1e18))) +
                    " lots, more than " + std::to_string(kMaxLots);
    } else {
      ParishSubdivider(local, p).run(out);
      if (o.x != 0 || o.y != 0) {
        for (Polygon& parcel : out.parcels) detail::translate(parcel, o.x, o.y);
      }
      detail::checkTiling(block, out);
    }
  } catch (const ParishSubdivider::OverBudget& e) {
    out = Subdivision{};
    out.failed = true;
    out.failure = e.what();
  } catch (const std::exception& e) {
    detail::rethrowUnlessBlockFailure();
    reason = e.what();
  }
  if (out.failed) {
    out.parcels = {block};
    return out;
  }
  if (!reason.empty()) out = detail::fallBackToObb(block, bounds, seed, reason);
  return out;
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
