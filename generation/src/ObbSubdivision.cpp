#include "parcelscope/generation/ObbSubdivision.h"
#include "parcelscope/generation/Styles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "BlockFailure.h"
#include "LocalShift.h"
#include "PolygonSplit.h"
#include "Random.h"
#include "parcelscope/analysis/Metrics.h"
#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/GeosOps.h"

namespace parcelscope::generation {

const std::vector<ParameterDescription>& obbParameterDescriptions() {
  static const std::vector<ParameterDescription> d = {
      realParameter("a-min", "Smallest parcel area a split may create", "m2", 0.0, 1e8, 200.0, "Bounds"),
      realParameter("a-max", "Parcels larger than this are split", "m2", 1.0, 1e8, 800.0, "Bounds"),
      realParameter("w-min", "Smallest parcel width (OBB short side) a split may create", "m", 0.0, 1e5, 8.0, "Bounds"),
      realParameter("w-max", "Parcels wider than this are split", "m", 0.1, 1e5, 30.0, "Bounds"),
      realParameter("omega",
                    "Split irregularity: the split line moves up to omega x 1/4 of the parcel's length off centre", "",
                    0.0, 1.0, 0.3, "Subdivision"),
      realParameter("xi",
                    "Street-access preference: probability that a split leaving a parcel without street access "
                    "is replaced by one that does not",
                    "", 0.0, 1.0, 1.0, "Subdivision"),
      realParameter("snap", "Split lines passing this close to a block contour vertex are moved through it", "m", 0.0,
                    1000.0, 2.0, "Subdivision"),
      analysis::minFrontageParameter(),
      integerParameter("seed", "Seed of the random choices; the same seed gives the same parcels", "", 0.0,
                       4294967295.0, 1.0, "Subdivision"),
  };
  return d;
}

ObbParameters obbParametersFrom(const ParameterValues& v) {
  ObbParameters p;
  auto get = [&](const char* name, double& target) {
    if (auto it = v.find(name); it != v.end()) target = it->second;
  };
  get("a-min", p.aMin);
  get("a-max", p.aMax);
  get("w-min", p.wMin);
  get("w-max", p.wMax);
  get("omega", p.omega);
  get("xi", p.xi);
  get("snap", p.snapDistance);
  get("min-frontage", p.minFrontage);
  return p;
}

struct ObbSplits {
  /// The split a piece got: its parts in recursion order and their street access.
  struct Split {
    std::vector<Polygon> parts;  ///< empty: no admissible split (the piece stays, oversize)
    std::vector<char> access;
    std::vector<double> areas;  ///< of the parts (area())
    std::vector<char> simple;   ///< parts whose outer ring is proven strictly simple (and that have no holes)
  };
  struct Node;
  /// What became of a part: its node (null: it fitted and was never split) and
  /// the minimum-area box width of its hull once measured (NaN before): a run
  /// reusing the split tests the part's fit without measuring it again.
  struct Child {
    std::shared_ptr<const Node> node;
    double width = std::numeric_limits<double>::quiet_NaN();
  };
  /// A piece that did not fit: its split and what became of each part.
  struct Node {
    std::shared_ptr<const Split> split;
    std::vector<Child> children;
  };
  std::shared_ptr<const Node> root;  ///< null: the block fitted as it is
};

bool obbSplitsReusable(const ObbParameters& a, const ObbParameters& b) {
  return a.aMin == b.aMin && a.wMin == b.wMin && a.omega == b.omega && a.xi == b.xi &&
         a.snapDistance == b.snapDistance && a.minFrontage == b.minFrontage;
}

namespace {

using detail::Rng;
using detail::splitmix64;
using Node = ObbSplits::Node;
using NodePtr = std::shared_ptr<const Node>;

// The OBB of Vanegas et al.: the smallest box with a side along one of the
// ring's own edges (edge-aligned, so small edits elsewhere do not turn it),
// given the ring's convex hull.
OrientedBox edgeAlignedBox(const Ring& ring, const Ring& hull) { return smallestBoxAlongEdges(hull, ring); }

// The work budget of a block (docs/algorithms/obb.md#work-budget): parcels
// made, and vertices visited by the split lines tried (the pieces' rings and
// the contour vertices a line may snap to). Counted, not timed, so that a
// block's outcome does not depend on the machine. A block beyond either comes
// back whole, failed, with the reason; real blocks stay far below (the largest
// of the shared datasets' blocks use about 1 % of each).
constexpr std::size_t kMaxParcelsPerBlock = 200000;
constexpr std::uint64_t kMaxSplitWork = 400000000;
constexpr std::uint64_t kMaxAccessWork = 4000000000;

// Thrown when a block exceeds its work budget; the message is the failure.
struct OverBudget : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Subdivider {
public:
  // `blockSimple` as Subdivision::blockSimple.
  Subdivider(const Polygon& block, const ObbParameters& p, Subdivision& out, bool record, int blockSimple)
      : block_(block), outline_{block.outer, {}}, p_(p), out_(out), record_(record), blockSimple_(blockSimple) {
    for (const Point& v : block.outer) contour_.push_back(v);
    for (const Ring& h : block.holes) contour_.insert(contour_.end(), h.begin(), h.end());
    const Box b = bounds(block);
    accessTolerance_ = std::max(1e-6, 1e-9 * (b.width() + b.height()));
    outlineEdges_ = std::make_unique<analysis::PreparedBoundary>(outline_, accessTolerance_);
    outlineVertices_.reserve(block.outer.size());
    for (std::size_t i = 0; i < block.outer.size(); ++i) outlineVertices_.push_back({block.outer[i], i});
    std::sort(outlineVertices_.begin(), outlineVertices_.end(), byPosition);
  }

  /// Subdivides the block, reusing the splits of `previous` (may be null);
  /// returns the splits made and reused when recording.
  NodePtr run(std::uint64_t seed, const NodePtr& previous) {
    double width = std::numeric_limits<double>::quiet_NaN();
    return recurse(block_, area(block_), width, seed, hasAccess(block_), 0, previous, -1);
  }

private:
  struct Candidate {
    bool rotated;   // split line along the long axis instead of across it
    double offset;  // shift of the pivot from the OBB centre (m)
  };

  bool hasAccess(const Polygon& piece) {
    if (holdsOutlineEdge(piece.outer)) return true;
    // The measure pairs the piece's edges with the outline's near them: at
    // most their product, counted against the budget.
    std::size_t pieceVertices = piece.outer.size();
    for (const Ring& h : piece.holes) pieceVertices += h.size();
    chargeAccess(static_cast<std::uint64_t>(pieceVertices) * block_.outer.size());
    return outlineEdges_->sharesAtLeast(piece, p_.minFrontage);
  }

  struct Vertex {
    Point p;
    std::size_t index;  // in the block's outer ring
  };
  static bool byPosition(const Vertex& a, const Vertex& b) {
    return a.p.x < b.p.x || (a.p.x == b.p.x && a.p.y < b.p.y);
  }

  // A shortcut of the access test: the ring has whole edges of the block's
  // outer ring (the same two vertices, in the same order, as counter-clockwise
  // rings keep them) clearly longer together than the frontage needed. Those
  // edges alone give the measured shared length, so the test would pass too.
  // (Edges of a few centimetres, as on outlines of many thousand vertices,
  // add up here; the full measure pairs edges and costs their product.)
  bool holdsOutlineEdge(const Ring& ring) const {
    const Ring& outline = block_.outer;
    const std::size_t n = ring.size(), m = outline.size();
    const double needed = p_.minFrontage * (1 + 1e-9);
    double held = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Point& a = ring[i];
      const Point& b = ring[(i + 1) % n];
      const double length = norm(b.x - a.x, b.y - a.y);
      if (!(length > 0)) continue;
      const auto at = std::lower_bound(outlineVertices_.begin(), outlineVertices_.end(), Vertex{a, 0}, byPosition);
      for (auto v = at; v != outlineVertices_.end() && v->p.x == a.x && v->p.y == a.y; ++v) {
        const Point& next = outline[(v->index + 1) % m];
        if (next.x == b.x && next.y == b.y) {
          held += length;
          if (held > needed) return true;
          break;
        }
      }
    }
    return false;
  }

  void emit(const Polygon& piece, bool access, bool oversize) {
    out_.parcels.push_back(piece);
    if (!access) ++out_.withoutAccess;
    if (oversize) ++out_.oversize;
  }

  // Moves the pivot onto a block contour vertex within the snap distance of the line.
  Point snap(const Point& pivot, const Point& dir, const Box& near) const {
    if (p_.snapDistance <= 0) return pivot;
    const Box zone = near.expanded(p_.snapDistance);
    double best = p_.snapDistance;
    Point snapped = pivot;
    for (const Point& v : contour_) {
      if (v.x < zone.minX || v.x > zone.maxX || v.y < zone.minY || v.y > zone.maxY) continue;
      const double d = std::fabs((v.x - pivot.x) * dir.y - (v.y - pivot.y) * dir.x);  // |dir| = 1
      if (d < best) {
        best = d;
        snapped = v;
      }
    }
    return snapped;
  }

  // The pieces of `piece` cut by the line through `through` along `dir`, or
  // nothing when the line misses, a piece is below A_min or W_min, or a piece
  // is not a valid polygon once rounded to doubles. The split is first made in
  // floating point (splitByLineFast) and kept when its pieces keep the piece's
  // area and pass the checks; when they fail the validity check, and whenever
  // the fast path does not apply, the exact split decides. A pinched split, and
  // one whose cut does not keep clear of the piece's other edges, is refused
  // either way: the exact split's pieces differ from the fast one's by the
  // rounding of the crossing points alone, some 1e-16 of the piece's size,
  // where the clearance is 1e-6 of it.
  // `pieceSimple`: the piece has no holes and its ring is proven strictly
  // simple. `simple` receives which parts are (see judge).
  std::vector<Polygon> admissibleSplit(const Polygon& piece, double pieceArea, const Point& through, const Point& dir,
                                       bool pieceSimple, std::vector<double>& areas, std::vector<char>& simple) const {
    detail::SplitPieces split;
    areas.clear();
    areas.reserve(4);
    if (detail::splitByLineFast(piece, through, dir, split)) {
      // A piece pinched at a point is never admissible: the exact split gives
      // it as one ring touching itself, which is not clean (nor valid).
      if (split.left.empty() || split.right.empty() || split.pinched) return {};
      std::vector<Polygon> parts = joined(std::move(split));
      double sum = 0;
      for (const Polygon& part : parts) sum += areas.emplace_back(area(part));
      if (std::fabs(sum - pieceArea) <= 1e-9 * pieceArea) {
        const Verdict v = judge(parts, areas, through, dir, pieceSimple, simple);
        if (v == Verdict::Admissible) return parts;
        if (v == Verdict::TooSmall || v == Verdict::CutNotClear) return {};
      }
    }
    split = detail::splitByLine(piece, through, dir);
    if (split.left.empty() || split.right.empty()) return {};
    std::vector<Polygon> parts = joined(std::move(split));
    areas.clear();
    for (const Polygon& part : parts) areas.push_back(area(part));
    // (The exact split's parts are judged without the piece's simplicity:
    // splitPieceIsSimple reasons about the fast split's vertices.)
    return judge(parts, areas, through, dir, false, simple) == Verdict::Admissible ? parts : std::vector<Polygon>{};
  }

  static std::vector<Polygon> joined(detail::SplitPieces&& split) {
    std::vector<Polygon> parts = std::move(split.left);
    parts.reserve(parts.size() + split.right.size());
    parts.insert(parts.end(), std::make_move_iterator(split.right.begin()), std::make_move_iterator(split.right.end()));
    return parts;
  }

  enum class Verdict { Admissible, TooSmall, CutNotClear, Invalid };
  // `areas[k]` is the area of parts[k].
  // `simple[k]` is set when parts[k] has no holes and its ring is proven
  // strictly simple; `pieceSimple` (the piece has no holes and a strictly
  // simple ring) lets a part be proven so from its new edges alone
  // (splitPieceIsSimple).
  Verdict judge(const std::vector<Polygon>& parts, const std::vector<double>& areas, const Point& through,
                const Point& dir, bool pieceSimple, std::vector<char>& simple) const {
    thread_local std::vector<Box> boxes;  // of the parts
    boxes.clear();
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const Polygon& part = parts[k];
      const double a = areas[k];
      if (a < p_.aMin) return Verdict::TooSmall;
      // A shape of area A and diameter D is at least A / D wide (its hull lies
      // in a strip of its least width, at most D long), and so is every box
      // around it: when that bound clears W_min, no box is needed.
      const Box& b = boxes.emplace_back(bounds(part));
      if (a >= p_.wMin * norm(b.width(), b.height()) * (1 + 1e-9)) continue;
      if (minimumAreaBox(part.outer).width < p_.wMin) return Verdict::TooSmall;
    }
    simple.assign(parts.size(), 0);
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const Polygon& part = parts[k];
      if (!cutIsClean(part, boxes[k], through, dir)) return Verdict::CutNotClear;
      // GEOS validity, skipped for rings proven simple (a ring with no holes
      // and non-zero area is valid when simple): from the piece's simplicity
      // and the part's new edges; else the conservative test for short rings
      // (its area, of a ring without holes, is the part's), the exact sweep
      // (after the conservative test) for long ones.
      simple[k] = part.holes.empty() &&
                  ((pieceSimple && detail::splitPieceIsSimple(part.outer, boxes[k], through, dir, true)) ||
                   (part.outer.size() <= 16 ? isClearlySimple(part.outer, boxes[k], areas[k])
                                            : detail::isStrictlySimple(part.outer)));
      if (!simple[k] && !geos::isValid(part)) return Verdict::Invalid;
    }
    return Verdict::Admissible;
  }

  // True when the edges a cut created (those on the cut line) keep a clear
  // distance from every other edge of the piece and do not fold back. A cut
  // that grazes a vertex or runs along an edge is exact, but its pieces would
  // carry slivers that rounding to doubles can turn invalid.
  // `b` is the part's bounds.
  static bool cutIsClean(const Polygon& part, const Box& b, const Point& through, const Point& dir) {
    const double size = b.width() + b.height();
    const double onLine = 1e-9 * size + 1e-12, clearance = 1e-6 * size;
    auto offLine = [&](const Point& q) { return std::fabs((q.x - through.x) * dir.y - (q.y - through.y) * dir.x); };
    const std::size_t rings = 1 + part.holes.size();
    const auto ring = [&](std::size_t k) -> const Ring& { return k == 0 ? part.outer : part.holes[k - 1]; };
    for (std::size_t ri = 0; ri < rings; ++ri) {
      const Ring& r = ring(ri);
      for (std::size_t i = 0, n = r.size(); i < n; ++i) {
        const Point& p = r[i];
        const Point& q = r[(i + 1) % n];
        if (offLine(p) > onLine || offLine(q) > onLine) continue;  // not a cut edge
        // Edges whose boxes stay farther than the clearance from the cut
        // edge's box are farther from the edge itself.
        const Box near =
            Box{std::min(p.x, q.x), std::min(p.y, q.y), std::max(p.x, q.x), std::max(p.y, q.y)}.expanded(clearance);
        for (std::size_t rj = 0; rj < rings; ++rj) {
          const Ring& t = ring(rj);
          for (std::size_t j = 0, m = t.size(); j < m; ++j) {
            if (rj == ri && (j == i || j == (i + 1) % n || (j + 1) % m == i)) continue;  // itself, neighbours
            const Point& c = t[j];
            const Point& d = t[(j + 1) % m];
            if (std::max(c.x, d.x) < near.minX || std::min(c.x, d.x) > near.maxX || std::max(c.y, d.y) < near.minY ||
                std::min(c.y, d.y) > near.maxY) {
              continue;
            }
            if (segmentDistance(p, q, c, d) <= clearance) return false;
          }
        }
        // Fold-back at either end: the neighbouring edge returns along the cut.
        if (detail::foldsBack(r[(i + n - 1) % n], p, q) || detail::foldsBack(p, q, r[(i + 2) % n])) return false;
      }
    }
    return true;
  }

  // The split of a piece that does not fit: its parts in a fixed order (along
  // the OBB axes, so seeds follow position) with their access; no parts when
  // no candidate is admissible.
  ObbSplits::Split split(const Polygon& piece, double pieceArea, const Ring& hull, bool pieceSimple, bool access,
                         bool wantAccess, double shiftAcross, double shiftAlong) {
    const OrientedBox box = edgeAlignedBox(piece.outer, hull);
    const Point u = box.u, v{-box.u.y, box.u.x};
    // Scratch kept across calls on this thread (split does not recurse).
    thread_local std::vector<Candidate> candidates;
    thread_local std::vector<char> partAccess;
    thread_local std::vector<std::size_t> order;
    thread_local std::vector<Point> centres;
    thread_local std::vector<double> areas;
    thread_local std::vector<char> partSimple;
    candidates.clear();
    candidates.push_back({false, 0.25 * box.length * shiftAcross});
    bool accessTried = false;
    auto addFallbacks = [&] {
      for (double f : {0.0, 0.15, -0.15, 0.3, -0.3}) candidates.push_back({false, f * box.length});
      for (double f : {0.25 * shiftAlong, 0.0, 0.15, -0.15, 0.3, -0.3}) candidates.push_back({true, f * box.width});
    };
    const Box near = bounds(piece);
    std::size_t pieceVertices = piece.outer.size();
    for (const Ring& h : piece.holes) pieceVertices += h.size();
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const Candidate cand = candidates[c];
      const Point dir = cand.rotated ? u : v;
      const Point shiftAxis = cand.rotated ? v : u;
      const Point pivot{box.center.x + shiftAxis.x * cand.offset, box.center.y + shiftAxis.y * cand.offset};
      // The snapped line first; if it makes an inadmissible split (for example a
      // sliver along a contour edge parallel to it), the line as drawn.
      std::vector<Polygon> parts;
      bool admissible = false;
      charge(2 * pieceVertices + (p_.snapDistance > 0 ? contour_.size() : 0));
      const Point snapped = snap(pivot, dir, near);
      for (const Point& through : {snapped, pivot}) {
        parts = admissibleSplit(piece, pieceArea, through, dir, pieceSimple, areas, partSimple);
        admissible = !parts.empty();
        if (admissible || (through.x == pivot.x && through.y == pivot.y)) break;
      }
      partAccess.assign(parts.size(), 0);
      bool allAccess = true;
      if (admissible) {
        // A part's boundary is the piece's and the cut line, which runs inside
        // the block: parts of a piece without access have none either.
        for (std::size_t k = 0; k < parts.size(); ++k) {
          partAccess[k] = access && hasAccess(parts[k]);
          allAccess = allAccess && partAccess[k];
        }
      }
      if (admissible && wantAccess && !allAccess) {
        // Vanegas et al.: rotate the split line by 90 degrees (with probability xi).
        if (!accessTried) {
          accessTried = true;
          candidates.insert(candidates.begin() + static_cast<long>(c) + 1, {true, 0.25 * box.width * shiftAlong});
        }
        admissible = false;
      }
      if (c == 0) addFallbacks();
      if (!admissible) continue;
      order.resize(parts.size());
      for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
      centres.clear();
      for (const Polygon& part : parts) centres.push_back(centroid(part));
      std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
        const double px = centres[x].x * u.x + centres[x].y * u.y, py = centres[y].x * u.x + centres[y].y * u.y;
        if (px != py) return px < py;
        return centres[x].x * v.x + centres[x].y * v.y < centres[y].x * v.x + centres[y].y * v.y;
      });
      ObbSplits::Split out;
      out.parts.reserve(parts.size());
      out.access.reserve(parts.size());
      out.areas.reserve(parts.size());
      out.simple.reserve(parts.size());
      for (std::size_t k : order) {
        out.parts.push_back(std::move(parts[k]));
        out.access.push_back(partAccess[k]);
        out.areas.push_back(areas[k]);
        out.simple.push_back(partSimple[k]);
      }
      return out;
    }
    return {};
  }

  // `a` is the piece's area; `width` its hull's minimum-area box width when
  // known (NaN otherwise), set here when measured. `simple`: 1 when the piece
  // has no holes and a strictly simple ring, 0 when not known so, -1 for the
  // block (tested when first needed).
  NodePtr recurse(const Polygon& piece, double a, double& width, std::uint64_t seed, bool access, int depth,
                  const NodePtr& previous, int simple) {
    // The hull, for the fit test and the split's box, made when first needed
    // (in storage shared by all pieces: it is not needed once the parts recurse).
    bool hullMade = false;
    const auto hullOf = [&]() -> const Ring& {
      if (!hullMade) {
        // A ring proven simple (and counter-clockwise, as pieces are) needs no sort.
        if (simple == 1 || (simple < 0 && blockSimple_ == 1)) {
          convexHullOfSimpleRing(piece.outer, hull_);
        } else {
          convexHullInto(piece.outer, hull_);
        }
      }
      hullMade = true;
      return hull_;
    };
    // The width is measured only when the area fits.
    bool fits = a <= p_.aMax;
    if (fits) {
      if (std::isnan(width)) width = minimumAreaBoxOfHull(hullOf()).width;
      fits = width <= p_.wMax;
    }
    // A safety net against pathological bounds: the recursion depth (the
    // parcels' count is in the work budget).
    if (!fits && depth <= 60 && out_.parcels.size() >= kMaxParcelsPerBlock) {
      throw OverBudget("work budget: more than " + std::to_string(kMaxParcelsPerBlock) + " parcels");
    }
    if (fits || depth > 60) {
      emit(piece, access, !fits);
      return record_ ? previous : nullptr;  // what is known below stays for smaller bounds
    }
    // Random choices and the children's seeds are drawn before any recursion.
    Rng rng{seed};
    const bool wantAccess = access && rng.uniform() < p_.xi;
    const double shiftAcross = (2 * rng.uniform() - 1) * p_.omega;
    const double shiftAlong = (2 * rng.uniform() - 1) * p_.omega;
    const std::uint64_t childBase = rng.next();

    auto node = std::make_shared<Node>();
    if (previous && previous->split) {
      node->split = previous->split;
      node->children = previous->children;  // their nodes and widths, replaced below
    } else {
      node->split = std::make_shared<const ObbSplits::Split>(split(
          piece, a, hullOf(), simple < 0 ? blockSimple() : simple == 1, access, wantAccess, shiftAcross, shiftAlong));
    }
    const ObbSplits::Split& chosen = *node->split;
    if (chosen.parts.empty()) {
      emit(piece, access, true);
      return record_ ? NodePtr(std::move(node)) : nullptr;
    }
    node->children.resize(chosen.parts.size());
    for (std::size_t k = 0; k < chosen.parts.size(); ++k) {
      ObbSplits::Child& child = node->children[k];
      const NodePtr below = std::move(child.node);
      child.node = recurse(chosen.parts[k], chosen.areas[k], child.width, splitmix64(childBase + k),
                           chosen.access[k] != 0, depth + 1, below, chosen.simple[k] != 0 ? 1 : 0);
    }
    return record_ ? NodePtr(std::move(node)) : nullptr;
  }

  // Counts edge pairs the access measure may compare against the budget.
  void chargeAccess(std::uint64_t pairs) {
    accessWork_ += pairs;
    if (accessWork_ > kMaxAccessWork) {
      throw OverBudget("work budget: street-access tests paired more than " + std::to_string(kMaxAccessWork) +
                       " edges");
    }
  }

  // Counts `vertices` visited against the block's work budget.
  void charge(std::size_t vertices) {
    work_ += vertices;
    if (work_ > kMaxSplitWork) {
      throw OverBudget("work budget: split lines visited more than " + std::to_string(kMaxSplitWork) + " vertices");
    }
  }

  // Whether the block has no holes and a strictly simple ring, tested once
  // (when first needed, unless known) and kept in out_.blockSimple.
  bool blockSimple() {
    if (blockSimple_ < 0) blockSimple_ = block_.holes.empty() && detail::isStrictlySimple(block_.outer);
    out_.blockSimple = static_cast<signed char>(blockSimple_);
    return blockSimple_ == 1;
  }

  const Polygon& block_;
  Polygon outline_;
  ObbParameters p_;
  Subdivision& out_;
  std::vector<Point> contour_;
  double accessTolerance_ = 1e-6;
  std::unique_ptr<analysis::PreparedBoundary> outlineEdges_;  // outline_, for the access test
  bool record_ = false;
  int blockSimple_ = -1;
  std::uint64_t work_ = 0;               // vertices visited by split lines (see kMaxSplitWork)
  std::uint64_t accessWork_ = 0;         // edge pairs of access tests (see kMaxAccessWork)
  Ring hull_;                            // the hull of the piece recurse() is deciding on
  std::vector<Vertex> outlineVertices_;  // of block_.outer, by position
};

}  // namespace

std::uint64_t blockSeed(std::uint64_t runSeed, std::int64_t blockId) {
  return splitmix64(splitmix64(runSeed) ^ static_cast<std::uint64_t>(blockId));
}

Subdivision subdivideObb(const Polygon& block, const ObbParameters& parameters, std::uint64_t seed,
                         const ObbReuse& reuse) {
  Subdivision out;
  ObbParameters p = parameters;
  p.aMax = std::max(p.aMax, p.aMin);
  p.wMax = std::max(p.wMax, p.wMin);
  const Point o = detail::exactShiftOrigin(block);
  Polygon local = detail::translated(block, -o.x, -o.y);
  try {
    // A block without holes is valid when its ring is strictly simple (the
    // first test of the validity check, whose answer the splits use too).
    int simple = reuse.blockChecked ? reuse.blockSimple : -1;
    const bool normalised = normalise(local);
    if (normalised && !reuse.blockChecked) {
      simple = local.outer.size() >= 3 && local.holes.empty() && detail::isStrictlySimple(local.outer);
    }
    if (!normalised || (!reuse.blockChecked && simple != 1 && !detail::isValidForSplit(local))) {
      out.failed = true;
      out.failure = "block is not a valid polygon with holes for exact splitting";
    } else if (const double least = area(local) / p.aMax; least > kMaxParcelsPerBlock) {
      // Parcels are at most A_max wherever a split is admissible: the block
      // would make about this many, without a split line drawn.
      out.failed = true;
      out.failure = "work budget: area / A_max = " + std::to_string(static_cast<long long>(std::min(least, 1e18))) +
                    " parcels, more than " + std::to_string(kMaxParcelsPerBlock);
    } else {
      out.blockSimple = static_cast<signed char>(simple);
      const NodePtr previous = reuse.previous ? reuse.previous->root : nullptr;
      NodePtr made = Subdivider(local, p, out, reuse.record, simple).run(seed, previous);
      if (reuse.record) {
        auto splits = std::make_shared<ObbSplits>();
        splits->root = std::move(made);
        out.obbSplits = std::move(splits);
      }
    }
  } catch (const std::exception& e) {
    detail::rethrowUnlessBlockFailure();
    out = Subdivision{};
    out.failed = true;
    out.failure = e.what();
  }
  if (out.failed) {
    out.parcels = {block};
    return out;
  }
  if (o.x != 0 || o.y != 0) {
    for (Polygon& parcel : out.parcels) detail::translate(parcel, o.x, o.y);
  }
  return out;
}

}  // namespace parcelscope::generation

namespace parcelscope::generation {

namespace {

// obb: OBB recursive subdivision (Vanegas et al. 2012, section 4.3).
class ObbStyle : public Style {
public:
  std::string name() const override { return "obb"; }
  std::string description() const override { return "OBB recursive subdivision (Vanegas et al. 2012, 4.3)"; }
  const std::vector<ParameterDescription>& parameters() const override { return obbParameterDescriptions(); }
  Subdivision run(const StyleRun& r) const override {
    const ObbParameters p = obbParametersFrom(r.values);
    const bool afterObb = r.previous && r.previousStyle && *r.previousStyle == "obb" && r.previousValues;
    // Splits recorded under other A_max or W_max serve a run of the same seed.
    const bool reusable = afterObb && r.previous->obbSplits && r.previousSeed == r.seed &&
                          obbSplitsReusable(obbParametersFrom(*r.previousValues), p);
    // A block an earlier OBB run subdivided passed the validity check then.
    const bool checked = afterObb && !r.previous->failed && !r.previous->fallback;
    return subdivideObb(r.block, p, r.seed,
                        {reusable ? r.previous->obbSplits.get() : nullptr, r.record, checked,
                         checked ? r.previous->blockSimple : static_cast<signed char>(-1)});
  }
};

}  // namespace

const Style& obbStyle() {
  static const ObbStyle s;
  return s;
}

}  // namespace parcelscope::generation
