#include "parcelscope/generation/SkeletonSubdivision.h"
#include "parcelscope/generation/Styles.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Straight_skeleton_builder_2.h>
#include <CGAL/create_straight_skeleton_2.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <unordered_map>

#include "BlockFailure.h"
#include "Exact.h"
#include "LocalShift.h"
#include "PolygonSplit.h"
#include "PostProcess.h"
#include "Random.h"
#include "StraightSkeleton.h"
#include "parcelscope/analysis/Metrics.h"
#include "parcelscope/core/GeosOps.h"

namespace parcelscope::generation {

const std::vector<ParameterDescription>& skeletonParameterDescriptions() {
  static const std::vector<ParameterDescription> d = {
      realParameter(
          "offset",
          "d_offset: depth of the parcel strips from the street; a patio fills what lies deeper. 0: no "
          "patio, parcels reach the skeleton's centre line (style offset: 0 means the block's mean observed parcel "
          "length, or 30 m without observed parcels)",
          "m", 0.0, 1e5, 0.0, "Skeleton"),
      realParameter("street-angle", "Contour corners turning by less than this continue the same logical street", "deg",
                    0.0, 180.0, 30.0, "Skeleton"),
      enumParameter("corner-rule",
                    "Which street a corner parcel faces: street-width, the wider one (the longer one when "
                    "widths are equal or unknown); street-length, the longer one",
                    {"street-width", "street-length"}, "street-width", "Skeleton"),
      enumParameter(
          "slice-widths",
          "Widths of the parcels cut along a street: even, the paper's (W_min + W_max) / 2 displaced by "
          "omega; observed, drawn from the block's observed parcel widths and scaled to fill each street (their "
          "spread is the irregularity: omega moves no cut; even where the block has no observed parcel)",
          {"even", "observed"}, "observed", "Skeleton"),
      booleanParameter("patio-obb",
                       "Subdivide patios with the OBB style; no: each patio is one parcel (style offset: always "
                       "yes)",
                       false, "Skeleton"),
  };
  return d;
}

SkeletonParameters skeletonParametersFrom(const ParameterValues& values) {
  SkeletonParameters p;
  p.bounds = obbParametersFrom(values);
  auto get = [&](const char* name, double fallback) {
    auto it = values.find(name);
    return it == values.end() ? fallback : it->second;
  };
  p.offset = get("offset", p.offset);
  p.streetAngle = get("street-angle", p.streetAngle);
  p.corner = get("corner-rule", 0) >= 0.5 ? CornerRule::StreetLength : CornerRule::StreetWidth;
  p.subdividePatios = get("patio-obb", 0) >= 0.5;
  p.observedSliceWidths = get("slice-widths", 1) >= 0.5;
  return p;
}

namespace {

using detail::K;
using detail::P2;
using detail::PWH;
using detail::Region;
using Kc = CGAL::Exact_predicates_inexact_constructions_kernel;
using Skeleton = CGAL::Straight_skeleton_2<Kc>;

// Watches CGAL's skeleton construction. CGAL 5.5 tidies the finished wavefront
// by walking each face's cycle of halfedges (MergeCoincidentNodes) without a
// bound: on a structure that nearly degenerate input has left broken, it loops
// until memory runs out or crashes. Before the tidying starts, every face cycle
// is walked here with a bound; a broken one stops the construction (CGAL turns
// the exception into a null skeleton).
// It also counts the events the construction creates (each holds a few
// hundred bytes until the construction ends) against the block's work budget
// (kMaxSkeletonEvents), and stops it beyond.
struct GuardVisitor : CGAL::Dummy_straight_skeleton_builder_2_visitor<Skeleton> {
  using Halfedge = Skeleton::Halfedge_const_handle;
  using Vertex = Skeleton::Vertex_const_handle;
  mutable std::vector<Halfedge> contour;
  mutable bool broken = false;
  mutable bool overBudget = false;
  mutable std::size_t events = 0;
  std::size_t maxEvents = 0;

  explicit GuardVisitor(std::size_t budget) : maxEvents(budget) {}

  void on_contour_edge_entered(const Halfedge& h) const { contour.push_back(h); }
  void on_edge_event_created(const Vertex&, const Vertex&) const { count(); }
  void on_split_event_created(const Vertex&) const { count(); }
  void on_pseudo_split_event_created(const Vertex&, const Vertex&) const { count(); }

  void on_cleanup_started() const {
    const std::size_t limit = 64 * contour.size() + 1024;
    for (const Halfedge& c : contour) {
      const auto face = c->face();
      if (face == Skeleton::Face_const_handle()) return fail();
      const Halfedge first = face->halfedge();
      Halfedge h = first;
      std::size_t steps = 0;
      do {
        h = h->next();
        if (h == Halfedge() || ++steps > limit) return fail();
      } while (h != first);
    }
  }

private:
  void fail() const {
    broken = true;
    throw std::runtime_error("broken skeleton face");
  }
  void count() const {
    if (++events <= maxEvents) return;
    overBudget = true;
    throw std::runtime_error("skeleton events over budget");
  }
};
using SkeletonTraits = CGAL::Straight_skeleton_builder_traits_2<Kc>;
using SkeletonMaker = CGAL::Straight_skeleton_builder_2<SkeletonTraits, Skeleton, GuardVisitor>;

// Thrown inside the builder when the skeleton route cannot handle a block; the
// block then goes to the OBB style (the shared post-processing, PostProcess.h).
using Fallback = detail::StyleFailure;
struct SkeletonFolds : Fallback {
  SkeletonFolds() : Fallback("a skeleton face is not simple once rounded") {}
};
// The block exceeds its work budget (docs/algorithms/skeleton.md#work-budget):
// no other try can do better, it goes to the OBB style at once.
struct OverBudget : Fallback {
  explicit OverBudget(const std::string& what) : Fallback("work budget: " + what) {}
};

K::Point_2 exact(const Point& p) { return {p.x, p.y}; }

// A contour edge of the skeleton: the chord between two kept vertices of a
// ring (see simplifiedRing), standing for the chain of block vertices between.
struct Edge {
  int ring = 0;
  Point a, b;
  std::vector<Point> chain;  // the block's vertices from a to b, both included
  double length = 0;         // of the chord
  double width = std::numeric_limits<double>::quiet_NaN();
};

// Vertices within this distance of the chord between their neighbours that
// are kept do not get skeleton faces of their own. Block outlines made from
// observed parcels carry many such vertices, and the skeleton's cost grows
// faster than linearly with the vertex count.
// Tried in turn: a skeleton whose faces fold over once rounded (or where a
// dropped vertex's jog crosses a skeleton arc) is usually fine with another
// set of kept vertices; the last try keeps every vertex, for blocks of up to
// kMaxFullVertices vertices.
constexpr double kChordTolerances[] = {0.5, 1.0, 0.25, 0.0};  // m
constexpr std::size_t kMaxFullVertices = 1500;

// The work budget of a block, counted rather than timed so that the outcome
// does not depend on the machine (docs/algorithms/skeleton.md#work-budget).
// The skeleton's events grow with the square of its contour vertices in the
// worst case: a try whose kept vertices exceed kMaxSkeletonVertices doubles
// its chord tolerance, up to half of W_min, until they fit. Beyond any of
// these, the block goes to the OBB style with the reason.
constexpr std::size_t kMaxSkeletonVertices = 2000;
constexpr std::size_t kMaxSkeletonEvents = 500000;
constexpr double kMaxStripParcels = 10000;  // street length / mean parcel width

// Largest move of a contour vertex in the skeleton's input (m); see buildSkeleton.
constexpr double kJitter = 1e-6;

// Indices of the ring's vertices that the skeleton keeps (Douglas-Peucker on
// the closed ring, from its sharpest corner and the vertex furthest from it).
std::vector<std::size_t> simplifiedRing(const Ring& ring, double tolerance) {
  const std::size_t n = ring.size();
  std::vector<char> keep(n, 0);
  std::size_t first = 0;
  double sharpest = -1;
  for (std::size_t i = 0; i < n; ++i) {
    const Point &a = ring[(i + n - 1) % n], &b = ring[i], &c = ring[(i + 1) % n];
    const double t = std::fabs(std::atan2((b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x),
                                          (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y)));
    if (t > sharpest) {
      sharpest = t;
      first = i;
    }
  }
  std::size_t second = first;
  double far = -1;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = norm(ring[i].x - ring[first].x, ring[i].y - ring[first].y);
    if (d > far) {
      far = d;
      second = i;
    }
  }
  keep[first] = keep[second] = 1;
  std::vector<std::pair<std::size_t, std::size_t>> stack = {{first, second}, {second, first}};
  while (!stack.empty()) {
    const auto [from, to] = stack.back();
    stack.pop_back();
    double worst = tolerance;
    std::size_t at = n;
    for (std::size_t i = (from + 1) % n; i != to; i = (i + 1) % n) {
      const double d = pointSegmentDistance(ring[i], ring[from], ring[to]);
      if (d > worst) {
        worst = d;
        at = i;
      }
    }
    if (at == n) continue;
    keep[at] = 1;
    stack.push_back({from, at});
    stack.push_back({at, to});
  }
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < n; ++i) {
    if (keep[i]) kept.push_back(i);
  }
  return kept;
}

struct SkVertex {
  Point p;
  double time = 0;
};

// One skeleton face: the cycle of its vertices, starting at its contour edge's
// start, and for each cycle edge (vertex k to k+1) the contour edge whose face
// lies across it (-1 across the contour).
struct Face {
  std::vector<int> vertices;
  std::vector<int> across;
};

struct Strip {
  std::vector<int> edges;     // contour edges in order along the ring
  double start = 0, end = 0;  // the part of the street chain that keeps its own parcels (m along it)
  double length = 0;
};

struct Candidate {
  // Exact route (held apart: an empty PWH allocates, and vectors of
  // candidates move rather than copy them as they grow).
  std::unique_ptr<PWH> shape;
  Polygon fast;  // floating-point route: the shape as cut and joined in doubles (no holes)
  Polygon rounded;
  double area = 0;
  bool access = false;
  bool triangular = false;  // of the rounded shape (SkeletonBuilder::triangular)
  bool stuck = false;       // no neighbour it could merge into
};

// Step 1 for one chord tolerance: the contour edges and the skeleton.
struct SkeletonStage {
  std::vector<Edge> edges;
  std::vector<int> ringStart;
  std::vector<SkVertex> vertices;
  std::vector<Face> faces;
  double maxTime = 0;
};

// Steps 1 (offset cut) to 3: each face's part of the strips after the corner
// transfers, the patios and the strips.
struct StripStage {
  std::vector<Region> regions;
  Region patios;
  std::vector<Strip> strips;
  // The regions rounded to doubles, one counter-clockwise strictly simple ring
  // per part, for the floating-point route of steps 4 and 5; null when that
  // route does not apply (patios, a part with holes or not simple once rounded).
  std::shared_ptr<const std::vector<std::vector<Ring>>> fastRegions;
};

// The floating-point route of steps 4 and 5 could not certify a step: the
// block's steps 4 and 5 run again on the exact route.
struct NeedExact {};

// What one try (chord tolerance) has built so far and can hand to a later run.
struct LayoutAttempt {
  std::shared_ptr<const SkeletonStage> skeleton;
  std::shared_ptr<const StripStage> strips;  // only when the block is deep enough for strips
};

// Exact pieces can carry edges far below a nanometre where a cut passes
// next to a skeleton point that was rounded to doubles; once rounded, such
// an edge is a duplicate vertex or a spike. Drops those vertices (moving the
// boundary by less than `eps`).
void dropMicroFeatures(Ring& r, double eps) {
  for (bool changed = true; changed && r.size() > 3;) {
    changed = false;
    for (std::size_t i = 0, n = r.size(); i < n && n > 3; ++i) {
      const Point &a = r[(i + n - 1) % n], &b = r[i], &c = r[(i + 1) % n];
      const double abx = b.x - a.x, aby = b.y - a.y, bcx = c.x - b.x, bcy = c.y - b.y;
      const bool duplicate = norm(bcx, bcy) <= eps;
      const bool spike = abx * bcx + aby * bcy < 0 &&
                         std::fabs(abx * bcy - aby * bcx) <= eps * std::max(norm(abx, aby), norm(bcx, bcy));
      if (duplicate || spike) {
        r.erase(r.begin() + static_cast<long>(duplicate ? (i + 1) % n : i));
        changed = true;
        break;
      }
    }
  }
}

void dropMicroFeatures(Polygon& p, double eps) {
  dropMicroFeatures(p.outer, eps);
  for (Ring& h : p.holes) dropMicroFeatures(h, eps);
}

// A block's outline prepared for the access test, with the outline itself
// (the prepared edges point into it).
struct PreparedOutline {
  Polygon outline;
  std::unique_ptr<analysis::PreparedBoundary> edges;
};

class SkeletonBuilder {
public:
  // `outlineEdges`: the block's outline prepared for the access test, made
  // here when empty (it depends on the block alone: every try and every run
  // on the same block shares it).
  SkeletonBuilder(const Polygon& block, const SkeletonParameters& p, const detail::Rng& rng, const StreetWidths& widths,
                  double chordTolerance, bool exactOnly, std::shared_ptr<const PreparedOutline>& outlineEdges)
      : block_(block),
        outline_{block.outer, {}},
        p_(p),
        rng_(rng),
        rngStart_(rng),
        widths_(widths),
        chordTolerance_(chordTolerance),
        exactOnly_(exactOnly) {
    const Box b = bounds(block);
    size_ = b.width() + b.height();
    reach_ = 4.0 * size_ + 1.0;
    // Candidates are copied, not moved, when the vector grows (CGAL's
    // polygons): room for the street parcels, about twice over.
    const double expected = perimeter(outline_) / (0.5 * (p.bounds.wMin + p.bounds.wMax));
    parcels_.reserve(16 + (expected < kMaxStripParcels ? static_cast<std::size_t>(2.0 * expected) : 0));
    accessTolerance_ = std::max(1e-6, 1e-9 * size_);
    if (!outlineEdges) {
      auto prepared = std::make_shared<PreparedOutline>();
      prepared->outline = outline_;
      prepared->edges = std::make_unique<analysis::PreparedBoundary>(prepared->outline, accessTolerance_);
      outlineEdges = std::move(prepared);
    }
    outlineEdges_ = outlineEdges;
    target_ = 0.5 * (p.bounds.wMin + p.bounds.wMax);
    if (!p.sliceWidths.empty()) {  // drawn widths (at least W_min each): their mean
      double sum = 0;
      for (double w : p.sliceWidths) sum += w;
      target_ = sum / static_cast<double>(p.sliceWidths.size());
    }
  }

  // Runs every step; `memo` gives steps 1-3 when an earlier run built them
  // for this try, and receives them when this run builds them and `record`.
  void run(Subdivision& out, LayoutAttempt& memo, bool record) {
    if (memo.skeleton) {  // its vertices and faces are copied only if steps 1-3 run again (below)
      const SkeletonStage& k = *memo.skeleton;
      edges_ = k.edges;
      ringStart_ = k.ringStart;
      maxTime_ = k.maxTime;
    } else {
      buildEdges();
      buildSkeleton();
      if (record) {
        memo.skeleton =
            std::make_shared<const SkeletonStage>(SkeletonStage{edges_, ringStart_, vertices_, faces_, maxTime_});
      }
    }
    const bool oneRow = maxTime_ < p_.bounds.wMin;
    std::shared_ptr<const StripStage> stage;
    if (!oneRow) {
      stage = memo.strips;
      if (!stage) {
        if (memo.skeleton && faces_.empty()) {
          vertices_ = memo.skeleton->vertices;
          faces_ = memo.skeleton->faces;
        }
        buildRegions();
        buildStrips();
        fixDiagonals();
        settle();
        auto built = std::make_shared<StripStage>(
            StripStage{std::move(regions_), std::move(patios_), std::move(strips_), nullptr});
        built->fastRegions = roundedRegions(*built);
        stage = std::move(built);
        if (record) memo.strips = stage;
      }
      strips_ = stage->strips;
    }
    // Steps 4 and 5 in floating point when the block or its strips allow it,
    // certified step by step; on the exact route when a certificate fails.
    const bool fastApplies = !exactOnly_ && (oneRow ? block_.holes.empty() && detail::isStrictlySimple(block_.outer)
                                                    : stage->fastRegions != nullptr);
    if (fastApplies) {
      try {
        fast_ = true;
        if (oneRow) {
          singleRowFast();
        } else {
          fastRegions_ = stage->fastRegions.get();
          for (Strip& s : strips_) sliceFast(s);
          backRegionsFast();
        }
        splitLarge();
        mergeSmall();
        emit(out);
        return;
      } catch (const NeedExact&) {
        fast_ = false;
        parcels_.clear();
        rng_ = rngStart_;
      }
    }
    out.skeletonExact = true;
    if (oneRow) {
      singleRow();
    } else {
      regions_ = stage->regions;
      patios_ = stage->patios;
      for (Strip& s : strips_) slice(s);
      backRegions();
    }
    splitLarge();
    mergeSmall();
    joinBackLandToPatios();
    emit(out);
  }

private:
  // The contour edges: chords between the ring vertices kept at this try's
  // chord tolerance, with their street widths.
  void buildEdges() {
    const Polygon& block = block_;
    const StreetWidths& widths = widths_;
    const double chordTolerance = chordTolerance_;
    std::vector<const Ring*> rings{&block.outer};
    for (const Ring& h : block.holes) rings.push_back(&h);
    // The kept vertices, unless dropping the others makes the polygon invalid;
    // a coarser tolerance while they exceed the budget (see kMaxSkeletonVertices).
    std::vector<std::vector<std::size_t>> kept;
    for (double tolerance = chordTolerance;; tolerance *= 2) {
      kept.clear();
      Polygon simplified;
      for (const Ring* ring : rings) {
        kept.push_back(simplifiedRing(*ring, tolerance));
        Ring r;
        for (std::size_t i : kept.back()) r.push_back((*ring)[i]);
        (simplified.outer.empty() ? simplified.outer : simplified.holes.emplace_back()) = r;
      }
      std::size_t count = 0;
      for (const auto& k : kept) count += k.size();
      if (count > kMaxSkeletonVertices) {
        if (tolerance > 0 && 2 * tolerance <= 0.5 * p_.bounds.wMin) continue;
        throw OverBudget(std::to_string(count) + " skeleton contour vertices at a chord tolerance of " +
                         std::to_string(tolerance) + " m, more than " + std::to_string(kMaxSkeletonVertices));
      }
      bool usable = true;
      for (const auto& k : kept) usable = usable && k.size() >= 3;
      if (!usable || !detail::isValidForSplit(simplified)) {
        std::size_t all = 0;
        for (const Ring* ring : rings) all += ring->size();
        if (all > kMaxSkeletonVertices) {
          throw OverBudget(std::to_string(all) + " skeleton contour vertices (simplified, the block is not valid), " +
                           "more than " + std::to_string(kMaxSkeletonVertices));
        }
        for (std::size_t r = 0; r < rings.size(); ++r) {
          kept[r].resize(rings[r]->size());
          for (std::size_t i = 0; i < kept[r].size(); ++i) kept[r][i] = i;
        }
      }
      break;
    }
    for (std::size_t r = 0; r < rings.size(); ++r) {
      const Ring& ring = *rings[r];
      const std::size_t n = ring.size();
      ringStart_.push_back(static_cast<int>(edges_.size()));
      for (std::size_t k = 0; k < kept[r].size(); ++k) {
        Edge e;
        e.ring = static_cast<int>(r);
        const std::size_t from = kept[r][k], to = kept[r][(k + 1) % kept[r].size()];
        double widthSum = 0, lengthSum = 0;
        for (std::size_t i = from;; i = (i + 1) % n) {
          e.chain.push_back(ring[i]);
          if (i == to) break;
          const double len = norm(ring[(i + 1) % n].x - ring[i].x, ring[(i + 1) % n].y - ring[i].y);
          const double w =
              r < widths.size() && i < widths[r].size() ? widths[r][i] : std::numeric_limits<double>::quiet_NaN();
          widthSum += w * len;
          lengthSum += len;
        }
        e.a = e.chain.front();
        e.b = e.chain.back();
        e.length = norm(e.b.x - e.a.x, e.b.y - e.a.y);
        e.width = widthSum / lengthSum;  // NaN when any part is unknown
        edges_.push_back(std::move(e));
      }
    }
    ringStart_.push_back(static_cast<int>(edges_.size()));
    // Step 4 cuts the streets into parcels of the mean width (even or drawn):
    // their count is known now, before any exact construction.
    double street = 0;
    for (int g = ringStart_[0]; g < ringStart_[1]; ++g) street += edges_[g].length;
    if (!(street / target_ <= kMaxStripParcels)) {
      throw OverBudget("about " + std::to_string(static_cast<long long>(std::min(street / target_, 1e18))) +
                       " parcels along the streets, more than " +
                       std::to_string(static_cast<long long>(kMaxStripParcels)));
    }
  }

  // Computes the exact value of every constructed vertex of the regions and
  // patios. A lazy exact number's double approximation tightens once anything
  // asks for its exact value, and what later steps construct from it (and so
  // their rounded coordinates) can inherit that approximation. Settled here,
  // the steps after 3 start from the same state whether this run built steps
  // 1-3 or an earlier run did (whose later steps may have refined them), so a
  // run reusing them gives the same last bits by construction. (The tests'
  // blocks also matched without it; it costs no measurable time.)
  void settle() const {
    auto settleRing = [](const P2& ring) {
      for (auto v = ring.vertices_begin(); v != ring.vertices_end(); ++v) {
        const auto a = v->approx();
        if (a.x().inf() != a.x().sup() || a.y().inf() != a.y().sup()) v->exact();
      }
    };
    auto settleRegion = [&](const Region& region) {
      for (const PWH& part : region) {
        settleRing(part.outer_boundary());
        for (auto h = part.holes_begin(); h != part.holes_end(); ++h) settleRing(*h);
      }
    };
    for (const Region& r : regions_) settleRegion(r);
    settleRegion(patios_);
  }

  // The edge after edge g along its ring.
  int nextEdge(int g) const {
    const int r = edges_[g].ring;
    return g + 1 == ringStart_[r + 1] ? ringStart_[r] : g + 1;
  }

  // ---- 1. skeleton and initial split ------------------------------------
  void buildSkeleton() {
    // The skeleton is built on the kept vertices moved by a deterministic
    // jitter of up to kJitter: CGAL 5.5 can loop without end (allocating until
    // memory runs out) while merging exactly coincident skeleton nodes, which
    // symmetric block layouts produce. Contour vertices keep their own
    // positions in everything built from the skeleton.
    std::vector<Point> input(edges_.size());
    std::map<std::pair<double, double>, int> edgeByStart;  // by jittered start
    for (std::size_t g = 0; g < edges_.size(); ++g) {
      const Point& a = edges_[g].a;
      std::uint64_t bx, by;
      std::memcpy(&bx, &a.x, sizeof bx);
      std::memcpy(&by, &a.y, sizeof by);
      std::uint64_t h = detail::splitmix64(bx ^ detail::splitmix64(by));
      const double jx = (static_cast<double>(h >> 11) * 0x1.0p-53 * 2 - 1) * kJitter;
      h = detail::splitmix64(h);
      const double jy = (static_cast<double>(h >> 11) * 0x1.0p-53 * 2 - 1) * kJitter;
      input[g] = {a.x + jx, a.y + jy};
      if (!edgeByStart.emplace(std::make_pair(input[g].x, input[g].y), static_cast<int>(g)).second) {
        throw Fallback("two contour vertices coincide");
      }
    }
    std::vector<Kc::Point_2> outer;
    for (int g = ringStart_[0]; g < ringStart_[1]; ++g) outer.emplace_back(input[g].x, input[g].y);
    std::vector<CGAL::Polygon_2<Kc>> holes;
    for (std::size_t r = 1; r + 1 < ringStart_.size(); ++r) {
      CGAL::Polygon_2<Kc> hole;
      for (int g = ringStart_[r]; g < ringStart_[r + 1]; ++g) hole.push_back(Kc::Point_2(input[g].x, input[g].y));
      holes.push_back(std::move(hole));
    }
    GuardVisitor guard(kMaxSkeletonEvents);
    SkeletonMaker maker(boost::none, SkeletonTraits(), guard);
    maker.enter_contour(outer.begin(), outer.end());
    for (const auto& hole : holes) maker.enter_contour(hole.vertices_begin(), hole.vertices_end());
    const auto ss = maker.construct_skeleton();
    if (guard.overBudget) {
      throw OverBudget("the straight skeleton made more than " + std::to_string(kMaxSkeletonEvents) + " events");
    }
    if (!ss)
      throw Fallback(guard.broken ? "the straight skeleton came out broken" : "no straight skeleton could be built");

    std::unordered_map<const void*, int> vertexIndex;
    auto vertexOf = [&](auto v) {
      auto [it, added] = vertexIndex.emplace(&*v, static_cast<int>(vertices_.size()));
      if (added) {
        Point p{v->point().x(), v->point().y()};
        if (v->is_contour()) {
          auto e = edgeByStart.find({p.x, p.y});
          if (e == edgeByStart.end()) throw Fallback("a skeleton contour vertex is not the block's");
          p = edges_[e->second].a;
        }
        vertices_.push_back({p, v->is_contour() ? 0.0 : v->time()});
        maxTime_ = std::max(maxTime_, v->time());
      }
      return it->second;
    };
    // Contour edge of each face.
    std::unordered_map<const void*, int> edgeOfFace;
    for (auto f = ss->faces_begin(); f != ss->faces_end(); ++f) {
      const auto h = f->halfedge();
      const auto a = h->opposite()->vertex()->point(), b = h->vertex()->point();
      auto it = edgeByStart.find({a.x(), a.y()});
      if (it == edgeByStart.end() || input[nextEdge(it->second)].x != b.x() || input[nextEdge(it->second)].y != b.y()) {
        throw Fallback("a skeleton face does not match a contour edge");
      }
      if (!edgeOfFace.emplace(&*f, it->second).second) throw Fallback("two skeleton faces on one edge");
    }
    if (edgeOfFace.size() != edges_.size()) throw Fallback("contour edges without a skeleton face");
    faces_.assign(edges_.size(), {});
    double total = 0;
    for (auto f = ss->faces_begin(); f != ss->faces_end(); ++f) {
      Face& face = faces_[edgeOfFace.at(&*f)];
      Ring ring;
      auto h = f->halfedge();
      do {  // vertices[k] is the source of the k-th halfedge, which runs to vertices[k + 1]
        face.vertices.push_back(vertexOf(h->opposite()->vertex()));
        face.across.push_back(h->opposite()->is_border() ? -1 : edgeOfFace.at(&*h->opposite()->face()));
        h = h->next();
      } while (h != f->halfedge());
      ring = faceRing(edgeOfFace.at(&*f));
      const double a = signedArea(ring);
      if (!(a > 0)) throw Fallback("a skeleton face is degenerate");
      total += a;
    }
    const double blockArea = area(block_);
    if (std::fabs(total - blockArea) > 1e-9 * blockArea) throw Fallback("skeleton faces do not tile the block");
  }

  // The face of contour edge g with the block's own vertices along its base:
  // (point, time) in cycle order.
  std::vector<std::pair<Point, double>> facePoints(std::size_t g) const {
    const Face& f = faces_[g];
    std::vector<std::pair<Point, double>> out;
    const auto& chain = edges_[g].chain;
    for (std::size_t i = 0; i + 1 < chain.size(); ++i) out.push_back({chain[i], 0.0});
    for (std::size_t k = 1; k < f.vertices.size(); ++k)
      out.push_back({vertices_[f.vertices[k]].p, vertices_[f.vertices[k]].time});
    return out;
  }

  Ring faceRing(std::size_t g) const {
    Ring r;
    for (const auto& [p, t] : facePoints(g)) r.push_back(p);
    return r;
  }

  double offsetDepth() const { return p_.offset > 0 ? p_.offset : std::numeric_limits<double>::infinity(); }

  // Whether a skeleton vertex lies within d_offset of the contour. Times within
  // a nanometre-scale tolerance of d count as d: a ridge at the offset depth,
  // rounded to either side, would otherwise leave a patio corridor of no width.
  bool withinOffset(double time) const { return time <= offsetDepth() + 1e-9 * size_; }

  // The point at time d on the skeleton edge u-w, the same from both faces.
  Point crossing(int u, int w, double d) {
    if (u > w) std::swap(u, w);
    auto [it, added] = crossings_.emplace(std::make_pair(u, w), Point{});
    if (added) {
      const SkVertex &a = vertices_[u], &b = vertices_[w];
      const double s = std::clamp((d - a.time) / (b.time - a.time), 0.0, 1.0);
      it->second = {a.p.x + s * (b.p.x - a.p.x), a.p.y + s * (b.p.y - a.p.y)};
    }
    return it->second;
  }

  // Each face's part within d_offset of its edge (the whole face when the
  // offset is infinite), and the patios: what lies beyond.
  void buildRegions() {
    const double d = offsetDepth();
    regions_.assign(edges_.size(), {});
    Region patioParts;
    for (std::size_t g = 0; g < faces_.size(); ++g) {
      const Face& f = faces_[g];
      Ring full = faceRing(g), near;
      bool clipped = false;
      // The base chain has time 0; the skeleton part of the cycle runs from
      // the chord's end (vertex 1) back to its start (vertex 0).
      const auto& chain = edges_[g].chain;
      near.assign(chain.begin(), chain.end() - 1);
      for (std::size_t k = 1, n = f.vertices.size(); k < n + 1; ++k) {
        const int u = f.vertices[k % n], w = f.vertices[(k + 1) % n];
        const bool inU = withinOffset(vertices_[u].time), inW = withinOffset(vertices_[w].time);
        if (inU && k < n) near.push_back(vertices_[u].p);
        if (inU != inW) near.push_back(crossing(u, w, d));
        clipped = clipped || !inU;
      }
      full.erase(std::unique(full.begin(), full.end(),
                             [](const Point& x, const Point& y) { return x.x == y.x && x.y == y.y; }),
                 full.end());
      while (full.size() > 1 && full.front().x == full.back().x && full.front().y == full.back().y) full.pop_back();
      PWH face(detail::toExact(full));
      // Rounded skeleton points can fold a thin face over itself: such a face
      // cannot go into exact Boolean operations.
      if (!face.outer_boundary().is_simple() || face.outer_boundary().orientation() != CGAL::COUNTERCLOCKWISE) {
        throw SkeletonFolds();
      }
      if (!clipped) {
        regions_[g] = {face};
        continue;
      }
      Polygon nearPolygon{near, {}};
      if (normalise(nearPolygon)) {
        PWH strip(detail::toExact(nearPolygon.outer));
        if (!strip.outer_boundary().is_simple()) throw Fallback("an offset strip is not simple");
        regions_[g] = {strip};
        for (PWH& part : detail::subtract({face}, strip)) patioParts.push_back(std::move(part));
      } else {
        patioParts.push_back(face);
      }
    }
    patios_ = detail::join(patioParts);
  }

  // ---- 2. logical streets and alpha-strips --------------------------------
  static double turn(const Edge& in, const Edge& out) {
    const double ax = in.b.x - in.a.x, ay = in.b.y - in.a.y, bx = out.b.x - out.a.x, by = out.b.y - out.a.y;
    return std::atan2(ax * by - ay * bx, ax * bx + ay * by);
  }

  void buildStrips() {
    const int begin = ringStart_[0], end = ringStart_[1], n = end - begin;
    std::vector<double> turns(n);
    std::vector<char> breaks(n, 0);
    int count = 0;
    for (int i = 0; i < n; ++i) {
      turns[i] = std::fabs(turn(edges_[begin + (i + n - 1) % n], edges_[begin + i]));
      breaks[i] = turns[i] * 180.0 / kPi >= p_.streetAngle;
      count += breaks[i];
    }
    while (count < std::min(2, n)) {  // a ring needs two streets to make simple strips
      int best = -1;
      for (int i = 0; i < n; ++i) {
        if (!breaks[i] && (best < 0 || turns[i] > turns[best])) best = i;
      }
      breaks[best] = 1;
      ++count;
    }
    int first = 0;
    while (!breaks[first]) ++first;
    for (int k = 0; k < n; ++k) {
      const int i = (first + k) % n;
      if (breaks[i]) strips_.push_back({});
      strips_.back().edges.push_back(begin + i);
    }
    for (Strip& s : strips_) {
      for (int g : s.edges) s.length += edges_[g].length;
      s.end = s.length;
    }
  }

  // ---- 3. beta-strips -------------------------------------------------------
  // Distance along strip s's streets (chord lengths) of point q near its edge g.
  double positionAlong(const Strip& s, int g, const Point& q) const {
    double at = 0;
    for (int e : s.edges) {
      const Edge& edge = edges_[e];
      if (e == g) {
        const double t = ((q.x - edge.a.x) * (edge.b.x - edge.a.x) + (q.y - edge.a.y) * (edge.b.y - edge.a.y)) /
                         (edge.length * edge.length);
        return at + std::clamp(t, 0.0, 1.0) * edge.length;
      }
      at += edge.length;
    }
    return at;
  }

  static double averageWidth(const Strip& s, const std::vector<Edge>& edges) {
    double sum = 0, length = 0;
    for (int g : s.edges) {
      if (!std::isfinite(edges[g].width)) return std::numeric_limits<double>::quiet_NaN();
      sum += edges[g].width * edges[g].length;
      length += edges[g].length;
    }
    return sum / length;
  }

  // +1: the previous strip gains the corner region, -1: the next one, 0: none.
  int cornerDirection(const Strip& prev, const Strip& next) const {
    if (turn(edges_[prev.edges.back()], edges_[next.edges.front()]) <= 0) return 0;  // reflex or straight
    if (p_.corner == CornerRule::StreetWidth) {
      const double wp = averageWidth(prev, edges_), wn = averageWidth(next, edges_);
      if (std::isfinite(wp) && std::isfinite(wn) && std::fabs(wp - wn) > 1e-9 * (wp + wn)) return wp > wn ? 1 : -1;
    }
    if (std::fabs(prev.length - next.length) <= 1e-9 * (prev.length + next.length)) return 0;
    return prev.length > next.length ? 1 : -1;
  }

  void fixDiagonals() {
    std::vector<int> stripOf(edges_.size(), -1);
    for (std::size_t s = 0; s < strips_.size(); ++s) {
      for (int g : strips_[s].edges) stripOf[g] = static_cast<int>(s);
    }
    const std::size_t n = strips_.size();
    for (std::size_t i = 0; i < n && n > 1; ++i) {
      Strip& prev = strips_[i];
      Strip& next = strips_[(i + 1) % n];
      const int dir = cornerDirection(prev, next);
      if (dir == 0) continue;
      Strip& loser = dir > 0 ? next : prev;
      const int gain = dir > 0 ? prev.edges.back() : next.edges.front();
      const int vertex = faces_[next.edges.front()].vertices.front();  // the corner: start of next's first edge
      // The strips' shared skeleton boundary from the corner; p its point furthest from the contour.
      std::vector<Point> path = sharedPath(vertex, stripOf, static_cast<int>(i), static_cast<int>((i + 1) % n));
      if (path.size() < 2) continue;
      transferCorner(path, loser, dir > 0, gain);
    }
  }

  // Path along the skeleton edges separating strips a and b, from contour
  // vertex `start` to the furthest point (time) they share, clipped at d_offset.
  std::vector<Point> sharedPath(int start, const std::vector<int>& stripOf, int a, int b) {
    const double d = offsetDepth();
    std::map<int, std::vector<int>> adjacent;
    for (int g : strips_[a].edges) {
      const Face& f = faces_[g];
      for (std::size_t k = 0, m = f.vertices.size(); k < m; ++k) {
        if (f.across[k] < 0 || stripOf[f.across[k]] != b) continue;
        const int u = f.vertices[k], w = f.vertices[(k + 1) % m];
        adjacent[u].push_back(w);
        adjacent[w].push_back(u);
      }
    }
    std::map<int, int> parent{{start, -1}};
    std::vector<int> queue{start};
    int best = start;
    Point bestPoint = vertices_[start].p;
    double bestTime = 0;
    int bestClipFrom = -1;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int u = queue[q];
      for (int w : adjacent[u]) {
        if (parent.count(w)) continue;
        if (!withinOffset(vertices_[w].time)) {
          if (d > bestTime) {
            bestTime = d;
            best = u;
            bestClipFrom = w;
            bestPoint = crossing(u, w, d);
          }
          continue;
        }
        parent[w] = u;
        queue.push_back(w);
        if (vertices_[w].time > bestTime) {
          bestTime = vertices_[w].time;
          best = w;
          bestClipFrom = -1;
          bestPoint = vertices_[w].p;
        }
      }
    }
    std::vector<Point> path;
    if (bestClipFrom >= 0) path.push_back(bestPoint);
    for (int v = best; v >= 0; v = parent[v]) path.push_back(vertices_[v].p);
    std::reverse(path.begin(), path.end());  // corner first
    return path;
  }

  // Moves the region between the shared path (corner ... p), the cut p-q and the
  // loser's street from q back to the corner, from `loser` to the face region
  // of edge `gain`. `loserIsNext`: the corner is the loser's start.
  void transferCorner(const std::vector<Point>& path, Strip& loser, bool loserIsNext, int gain) {
    const Point& p = path.back();
    // The loser's streets as the block's own vertices, and the edge each segment belongs to.
    std::vector<Point> street;
    std::vector<int> segmentEdge;
    for (int g : loser.edges) {
      const auto& chain = edges_[g].chain;
      for (std::size_t i = street.empty() ? 0 : 1; i < chain.size(); ++i) street.push_back(chain[i]);
      segmentEdge.insert(segmentEdge.end(), chain.size() - 1, g);
    }
    struct Foot {
      double distance;
      std::size_t segment;  // street[segment] .. street[segment + 1]
      double t;             // along it, [0, 1]
    };
    std::vector<Foot> feet;
    for (std::size_t k = 0; k + 1 < street.size(); ++k) {
      const Point &a = street[k], &b = street[k + 1];
      const double dx = b.x - a.x, dy = b.y - a.y;
      const double t = std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
      feet.push_back({norm(a.x + t * dx - p.x, a.y + t * dy - p.y), k, t});
    }
    std::sort(feet.begin(), feet.end(), [](const Foot& x, const Foot& y) { return x.distance < y.distance; });
    for (std::size_t c = 0; c < std::min<std::size_t>(feet.size(), 4); ++c) {
      const Foot& foot = feet[c];
      const K::Point_2 a = exact(street[foot.segment]), b = exact(street[foot.segment + 1]);
      const K::Point_2 q = a + (b - a) * K::FT(foot.t);
      P2 ring;
      auto add = [&](const K::Point_2& x) {
        if (ring.is_empty() || *(ring.vertices_end() - 1) != x) ring.push_back(x);
      };
      for (const Point& x : path) add(exact(x));
      add(q);
      if (loserIsNext) {  // back along the street to its start, the corner
        for (std::size_t k = foot.segment + 1; k-- > 1;) add(exact(street[k]));
      } else {  // on along the street to its end, the corner
        for (std::size_t k = foot.segment + 1; k + 1 < street.size(); ++k) add(exact(street[k]));
      }
      if (ring.size() > 1 && ring[0] == ring[ring.size() - 1]) ring.erase(ring.vertices_end() - 1);
      if (ring.size() < 3 || !ring.is_simple() || ring.orientation() == CGAL::COLLINEAR) continue;
      if (ring.orientation() != CGAL::COUNTERCLOCKWISE) ring.reverse_orientation();
      const PWH region(ring);
      // The region must lie inside the loser's current strip: the rest of its
      // boundary is the strip's, so it does when the cut p-q stays inside.
      if (!cutInside(exact(p), q, loser)) continue;
      for (int g : loser.edges) regions_[g] = detail::subtract(regions_[g], region);
      Region gained = regions_[gain];
      gained.push_back(region);
      regions_[gain] = detail::join(gained);
      const double at =
          positionAlong(loser, segmentEdge[foot.segment], {CGAL::to_double(q.x()), CGAL::to_double(q.y())});
      if (loserIsNext) {
        loser.start = std::max(loser.start, at);
      } else {
        loser.end = std::min(loser.end, at);
      }
      return;
    }
  }

  // True when segment p-q crosses no boundary edge of the strip's regions and
  // its midpoint lies in or on one of them.
  bool cutInside(const K::Point_2& p, const K::Point_2& q, const Strip& strip) const {
    const K::Point_2 m = CGAL::midpoint(p, q);
    const CGAL::Bbox_2 box = p.bbox() + q.bbox();
    bool inside = false;
    for (int g : strip.edges) {
      for (const PWH& part : regions_[g]) {
        std::vector<const P2*> rings{&part.outer_boundary()};
        for (auto h = part.holes_begin(); h != part.holes_end(); ++h) rings.push_back(&*h);
        for (const P2* ring : rings) {
          for (auto e = ring->edges_begin(); e != ring->edges_end(); ++e) {
            if (!CGAL::do_overlap(box, e->bbox())) continue;
            const auto o1 = CGAL::orientation(p, q, e->source()), o2 = CGAL::orientation(p, q, e->target());
            const auto o3 = CGAL::orientation(e->source(), e->target(), p);
            const auto o4 = CGAL::orientation(e->source(), e->target(), q);
            if (o1 * o2 < 0 && o3 * o4 < 0) return false;  // a proper crossing
          }
        }
        if (inside) continue;
        bool inHole = false;
        for (auto h = part.holes_begin(); h != part.holes_end(); ++h) {
          inHole = inHole || h->bounded_side(m) == CGAL::ON_BOUNDED_SIDE;
        }
        inside = !inHole && part.outer_boundary().bounded_side(m) != CGAL::ON_UNBOUNDED_SIDE;
      }
    }
    return inside;
  }

  // ---- 4. slicing -----------------------------------------------------------
  // Cut positions along [start, end]: about equally spaced, each displaced by a
  // normal deviate of variance 3 omega.
  std::vector<double> cutPositions(double start, double end) {
    const double length = end - start;
    std::vector<double> cuts;
    if (length <= 0) return cuts;
    if (!p_.sliceWidths.empty()) return drawnCuts(start, length);
    const int n = std::max(1, static_cast<int>(std::lround(length / target_)));
    const double spacing = length / n, sigma = std::sqrt(3.0 * p_.bounds.omega);
    for (int k = 1; k < n; ++k) {
      const double shift = std::clamp(sigma * rng_.normal(), -0.45 * spacing, 0.45 * spacing);
      cuts.push_back(start + k * spacing + shift);
    }
    return cuts;
  }

  // Widths drawn from p_.sliceWidths until they cover the strip (the last
  // kept when that comes closer to its length), then scaled to fill it.
  std::vector<double> drawnCuts(double start, double length) {
    const std::vector<double>& sample = p_.sliceWidths;
    std::vector<double> widths;
    double sum = 0;
    while (sum < length && static_cast<double>(widths.size()) < kMaxStripParcels) {
      const auto i = static_cast<std::size_t>(rng_.uniform() * static_cast<double>(sample.size()));
      widths.push_back(sample[std::min(i, sample.size() - 1)]);
      sum += widths.back();
    }
    if (widths.size() > 1 && sum - length > length - (sum - widths.back())) {
      sum -= widths.back();
      widths.pop_back();
    }
    std::vector<double> cuts;
    double at = 0;
    for (std::size_t k = 0; k + 1 < widths.size(); ++k) {
      at += widths[k];
      cuts.push_back(start + at * length / sum);
    }
    return cuts;
  }

  void slice(const Strip& s) {
    const std::vector<double> cuts = cutPositions(s.start, s.end);
    std::vector<Region> pieces(cuts.size() + 1);
    double at = 0;
    std::size_t before = 0;  // cuts before the current edge
    for (int g : s.edges) {
      const Edge& e = edges_[g];
      Region rest = regions_[g];
      std::size_t k = before;
      const K::Point_2 a = exact(e.a), b = exact(e.b);
      const K::Vector_2 inward(a.y() - b.y(), b.x() - a.x());
      for (; k < cuts.size() && cuts[k] < at + e.length; ++k) {
        if (rest.empty()) continue;
        const K::Point_2 o = a + (b - a) * K::FT(std::clamp((cuts[k] - at) / e.length, 0.0, 1.0));
        Region head = detail::clipLeft(rest, o, inward, reach_);
        rest = detail::clipLeft(rest, o, -inward, reach_);
        for (PWH& h : head) pieces[k].push_back(std::move(h));
      }
      for (PWH& r : rest) pieces[k].push_back(std::move(r));
      before = k;
      at += e.length;
    }
    for (const Region& r : pieces) addCandidates(detail::join(r));
  }

  // ---- 4 and 5 in floating point ----------------------------------------------
  // The floating-point route cuts and joins the regions rounded to doubles
  // (splitByLineFast, joinRingsFast): every cut point is computed once and
  // shared by the pieces on both sides, so the pieces still tile, and each
  // step is certified (a piece strictly simple, splitPieceIsSimple; a union
  // made of rings whose area is the parts'); a step that cannot be certified
  // throws NeedExact. Its parcels differ from the exact route's by the
  // rounding of the cut points (some 1e-16 of the coordinates).

  // The strips' regions rounded to doubles; null when the route does not
  // apply: the block has patios (joined exactly, step 1), or a region part has
  // holes, vanishes, or is not strictly simple once rounded.
  static std::shared_ptr<const std::vector<std::vector<Ring>>> roundedRegions(const StripStage& stage) {
    if (!stage.patios.empty()) return nullptr;
    auto out = std::make_shared<std::vector<std::vector<Ring>>>(stage.regions.size());
    for (std::size_t g = 0; g < stage.regions.size(); ++g) {
      for (const PWH& part : stage.regions[g]) {
        Polygon q;
        if (part.has_holes() || !detail::toDouble(part, q) || !detail::isStrictlySimple(q.outer)) return nullptr;
        (*out)[g].push_back(std::move(q.outer));
      }
    }
    return out;
  }

  // splitByLineFast of a ring, its pieces certified strictly simple.
  static void splitFast(const Polygon& ring, const Point& through, const Point& dir, detail::SplitPieces& split) {
    if (!detail::splitByLineFast(ring, through, dir, split) || split.pinched) throw NeedExact{};
    for (const auto* side : {&split.left, &split.right}) {
      for (const Polygon& q : *side) {
        if (!q.holes.empty() || !detail::splitPieceIsSimple(q.outer, bounds(q.outer), through, dir)) throw NeedExact{};
      }
    }
  }

  std::vector<Ring> joinFast(const std::vector<const Ring*>& parts) const {
    if (parts.size() == 1) return {*parts[0]};
    std::vector<Ring> out;
    if (parts.empty()) return out;
    if (!detail::joinRingsFast(parts, 1e-9 * size_, out)) throw NeedExact{};
    return out;
  }

  // slice() on the floating-point route.
  void sliceFast(const Strip& s) {
    const std::vector<double> cuts = cutPositions(s.start, s.end);
    // The pieces between cuts: a region's part a cut misses is used where it
    // is (and copied once, if it is a piece on its own); the cuts' pieces are
    // held in `made` (a deque: they stay in place).
    struct Part {
      const Ring* ring;
      Ring* made;  // ring, when it is one of the cuts' pieces
    };
    std::vector<std::vector<Part>> pieces(cuts.size() + 1);
    std::deque<Ring> made;
    const auto keep = [&](Ring&& r) {
      made.push_back(std::move(r));
      return Part{&made.back(), &made.back()};
    };
    double at = 0;
    std::size_t before = 0;  // cuts before the current edge
    std::vector<Part> rest, next;
    for (int g : s.edges) {
      const Edge& e = edges_[g];
      rest.clear();
      for (const Ring& r : (*fastRegions_)[g]) rest.push_back({&r, nullptr});
      std::size_t k = before;
      const Point inward{e.a.y - e.b.y, e.b.x - e.a.x};
      for (; k < cuts.size() && cuts[k] < at + e.length; ++k) {
        if (rest.empty()) continue;
        const double t = std::clamp((cuts[k] - at) / e.length, 0.0, 1.0);
        const Point o{e.a.x + (e.b.x - e.a.x) * t, e.a.y + (e.b.y - e.a.y) * t};
        next.clear();
        for (const Part& r : rest) {
          detail::SplitPieces split;
          splitFast(r.made ? Polygon{std::move(*r.made), {}} : Polygon{*r.ring, {}}, o, inward, split);
          for (Polygon& q : split.left) pieces[k].push_back(keep(std::move(q.outer)));
          for (Polygon& q : split.right) next.push_back(keep(std::move(q.outer)));
        }
        rest.swap(next);
      }
      pieces[k].insert(pieces[k].end(), rest.begin(), rest.end());
      before = k;
      at += e.length;
    }
    std::vector<const Ring*> parts;
    for (const std::vector<Part>& r : pieces) {
      if (r.size() == 1) {
        addFastCandidate(r[0].made ? std::move(*r[0].made) : *r[0].ring);
        continue;
      }
      parts.clear();
      for (const Part& q : r) parts.push_back(q.ring);
      for (Ring& u : joinFast(parts)) addFastCandidate(std::move(u));
    }
  }

  // singleRow() on the floating-point route, for a block without holes.
  void singleRowFast() {
    const OrientedBox box = minimumAreaBox(block_.outer);
    const Point u = box.u, across{-u.y, u.x};
    std::vector<Polygon> rest{Polygon{block_.outer, {}}}, next;
    const double start = -0.5 * box.length;
    for (double c : cutPositions(start, -start)) {
      const Point o{box.center.x + u.x * c, box.center.y + u.y * c};
      next.clear();
      for (const Polygon& r : rest) {
        detail::SplitPieces split;
        splitFast(r, o, across, split);
        for (Polygon& q : split.left) addFastCandidate(std::move(q.outer));
        for (Polygon& q : split.right) next.push_back(std::move(q));
      }
      rest.swap(next);
    }
    for (Polygon& r : rest) addFastCandidate(std::move(r.outer));
  }

  void backRegionsFast() {
    for (std::size_t g = static_cast<std::size_t>(ringStart_[1]); g < edges_.size(); ++g) {
      for (const Ring& r : (*fastRegions_)[g]) addFastCandidate(r);
    }
  }

  bool makeFastCandidate(Ring shape, Candidate& c) const {
    c.fast = Polygon{std::move(shape), {}};
    c.rounded = c.fast;
    dropMicroFeatures(c.rounded, 1e-9 * size_);
    if (!normalise(c.rounded)) return false;
    c.area = area(c.rounded);
    c.access = hasAccess(c.rounded);
    c.triangular = triangular(c.rounded);
    return true;
  }

  void addFastCandidate(Ring shape) {
    Candidate c;
    if (makeFastCandidate(std::move(shape), c)) parcels_.push_back(std::move(c));
  }

  // Faces along holes: no street, merged into their neighbours afterwards.
  // Face by face, so that each merges into the parcel behind it rather than
  // one ring of back land wrapping the hole.
  void backRegions() {
    for (std::size_t g = static_cast<std::size_t>(ringStart_[1]); g < edges_.size(); ++g) addCandidates(regions_[g]);
  }

  void singleRow() {
    const OrientedBox box = minimumAreaBox(block_.outer);
    const Point u = box.u;
    const K::Vector_2 across(-u.y, u.x);
    Region rest{detail::toExact(block_)};
    const double start = -0.5 * box.length;
    for (double c : cutPositions(start, -start)) {
      const K::Point_2 o(box.center.x + u.x * c, box.center.y + u.y * c);
      addCandidates(detail::clipLeft(rest, o, across, reach_));
      rest = detail::clipLeft(rest, o, -across, reach_);
    }
    addCandidates(rest);
  }

  // ---- 5. post-processing -----------------------------------------------------
  bool hasAccess(const Polygon& piece) const {
    return outlineEdges_->edges->sharesAtLeast(piece, p_.bounds.minFrontage);
  }

  bool rounded(const PWH& exactShape, Polygon& out) const {
    if (!detail::toDouble(exactShape, out)) return false;
    dropMicroFeatures(out, 1e-9 * size_);
    return normalise(out);
  }

  bool makeCandidate(PWH shape, Candidate& c) const {
    c.shape = std::make_unique<PWH>(std::move(shape));
    if (!rounded(*c.shape, c.rounded)) return false;
    c.area = area(c.rounded);
    c.access = hasAccess(c.rounded);
    c.triangular = triangular(c.rounded);
    return true;
  }

  void addCandidates(const Region& parts) {
    for (const PWH& part : parts) {
      Candidate c;
      if (makeCandidate(part, c)) parcels_.push_back(std::move(c));
    }
  }

  // The longest edge of the parcel lying on the block's outer contour.
  bool longestFrontage(const Polygon& parcel, Point& from, Point& to) const {
    double best = 0;
    const double tol = 1e-6 * size_;
    const Ring& r = parcel.outer;
    for (std::size_t i = 0, n = r.size(); i < n; ++i) {
      const Point &x = r[i], &y = r[(i + 1) % n];
      const double len = norm(y.x - x.x, y.y - x.y);
      if (len <= best) continue;
      for (std::size_t j = 0, m = block_.outer.size(); j < m; ++j) {
        const Point &a = block_.outer[j], &b = block_.outer[(j + 1) % m];
        if (pointSegmentDistance(x, a, b) <= tol && pointSegmentDistance(y, a, b) <= tol) {
          best = len;
          from = x;
          to = y;
          break;
        }
      }
    }
    return best > 0;
  }

  void splitLarge() {
    for (std::size_t i = 0; i < parcels_.size(); ++i) {
      for (int attempt = 0; attempt < 8 && parcels_[i].area > p_.bounds.aMax; ++attempt) {
        Point x, y;
        if (!parcels_[i].access || !longestFrontage(parcels_[i].rounded, x, y)) break;
        Candidate l, r;
        if (fast_) {
          const Point mid{0.5 * (x.x + y.x), 0.5 * (x.y + y.y)}, inward{x.y - y.y, y.x - x.x};
          detail::SplitPieces split;
          splitFast(parcels_[i].fast, mid, inward, split);
          if (split.left.size() != 1 || split.right.size() != 1) break;
          if (!makeFastCandidate(std::move(split.left[0].outer), l) ||
              !makeFastCandidate(std::move(split.right[0].outer), r)) {
            break;
          }
        } else {
          const K::Point_2 mid(0.5 * (x.x + y.x), 0.5 * (x.y + y.y));
          const K::Vector_2 inward(x.y - y.y, y.x - x.x);
          const Region left = detail::clipLeft(*parcels_[i].shape, mid, inward, reach_);
          const Region right = detail::clipLeft(*parcels_[i].shape, mid, -inward, reach_);
          if (left.size() != 1 || right.size() != 1) break;
          if (!makeCandidate(left[0], l) || !makeCandidate(right[0], r)) break;
        }
        auto fine = [&](const Candidate& c) {
          return c.access && c.area >= p_.bounds.aMin && minimumAreaBox(c.rounded.outer).width >= p_.bounds.wMin;
        };
        if (!fine(l) || !fine(r)) break;
        parcels_[i] = std::move(l);
        parcels_.push_back(std::move(r));
      }
    }
  }

  bool holesAreTheBlocks(const Polygon& p) const {
    for (const Ring& h : p.holes) {
      const double a = std::fabs(signedArea(h));
      bool found = false;
      for (const Ring& b : block_.holes) found = found || std::fabs(std::fabs(signedArea(b)) - a) <= 1e-9 * a;
      if (!found) return false;
    }
    return true;
  }

  // Whether the turn whose cross and dot products are `cross` and `dot`
  // exceeds 10 degrees: |atan2(cross, dot)| > 10 degrees, decided without
  // atan2 unless the ratio is within 1e-9 of the limit's tangent (atan2 is
  // then asked, so the answer is always atan2's).
  static bool sharpTurn(double cross, double dot) {
    constexpr double kLimit = 10.0 * kPi / 180.0;
    constexpr double kTangent = 0.17632698070846498;  // tan(kLimit)
    // More than 90 degrees.
    if (dot < 0) return true;
    if (dot > 0) {
      const double across = std::fabs(cross);
      if (across > kTangent * (1 + 1e-9) * dot) return true;
      if (across < kTangent * (1 - 1e-9) * dot) return false;
    }
    return std::fabs(std::atan2(cross, dot)) > kLimit;
  }

  static bool triangular(const Polygon& p) {
    if (!p.holes.empty()) return false;
    int corners = 0;
    const Ring& r = p.outer;
    for (std::size_t i = 0, n = r.size(); i < n; ++i) {
      const Point &a = r[(i + n - 1) % n], &b = r[i], &c = r[(i + 1) % n];
      corners += sharpTurn((b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x),
                           (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y));
    }
    return corners <= 3;
  }

  void mergeSmall() {
    for (;;) {
      if (parcels_.size() <= 1) return;
      int worst = -1;
      for (std::size_t i = 0; i < parcels_.size(); ++i) {
        const Candidate& c = parcels_[i];
        if (c.stuck || !(c.area < p_.bounds.aMin || !c.access || c.triangular)) continue;
        if (worst < 0 || c.area < parcels_[worst].area) worst = static_cast<int>(i);
      }
      if (worst < 0) return;
      const Box wb = bounds(parcels_[worst].rounded).expanded(accessTolerance_);
      std::vector<std::pair<double, std::size_t>> neighbours;
      for (std::size_t j = 0; j < parcels_.size(); ++j) {
        if (static_cast<int>(j) == worst || !bounds(parcels_[j].rounded).intersects(wb)) continue;
        const double shared =
            analysis::sharedBoundaryLength(parcels_[worst].rounded, parcels_[j].rounded, accessTolerance_);
        if (shared > 0) neighbours.push_back({-shared, j});
      }
      std::sort(neighbours.begin(), neighbours.end());
      bool merged = false;
      for (const auto& [negShared, j] : neighbours) {
        Candidate c;
        if (fast_) {
          // A union with a hole (around a third parcel or the block's hole)
          // is left to the exact route.
          std::vector<Ring> u = joinFast({&parcels_[worst].fast.outer, &parcels_[j].fast.outer});
          if (u.size() != 1 || !makeFastCandidate(std::move(u[0]), c)) continue;
        } else {
          const Region u = detail::join({*parcels_[worst].shape, *parcels_[j].shape});
          // One piece, whose holes are the block's (not two parcels closing around a third).
          if (u.size() != 1 || !makeCandidate(u[0], c) || !holesAreTheBlocks(c.rounded)) continue;
        }
        parcels_[j] = std::move(c);
        parcels_.erase(parcels_.begin() + worst);
        merged = true;
        break;
      }
      if (!merged) parcels_[worst].stuck = true;
    }
  }

  // Land along holes that no strip parcel borders lies behind a patio (a
  // finite offset cut it off from the streets): it joins that patio.
  void joinBackLandToPatios() {
    for (std::size_t i = 0; i < parcels_.size();) {
      bool joined = false;
      if (!parcels_[i].access) {
        for (PWH& patio : patios_) {
          Polygon shape;
          if (!rounded(patio, shape) ||
              analysis::sharedBoundaryLength(parcels_[i].rounded, shape, accessTolerance_) <= 0) {
            continue;
          }
          const Region u = detail::join({patio, *parcels_[i].shape});
          if (u.size() != 1) continue;
          patio = u[0];
          joined = true;
          break;
        }
      }
      if (joined) {
        parcels_.erase(parcels_.begin() + static_cast<long>(i));
      } else {
        ++i;
      }
    }
  }

  void emit(Subdivision& out) {
    for (Candidate& c : parcels_) {
      out.parcels.push_back(std::move(c.rounded));  // the last use of the candidates
      if (!c.access) ++out.withoutAccess;
      if (c.area > p_.bounds.aMax) ++out.oversize;
    }
    for (const PWH& patio : patios_) {
      Polygon shape;
      if (!rounded(patio, shape)) continue;
      // A patio can pinch to a corridor of no width where a ridge runs at the
      // offset depth: once rounded, its lobes are separate patios.
      for (Polygon& part : geos::validParts(shape)) {
        if (!p_.subdividePatios) {
          out.parcels.push_back(std::move(part));
          ++out.patioParcels;
          continue;
        }
        Subdivision inner = subdivideObb(part, p_.bounds, rng_.next());
        if (inner.failed) throw Fallback("a patio could not be subdivided: " + inner.failure);
        out.oversize += inner.oversize;
        for (Polygon& q : inner.parcels) {
          out.parcels.push_back(std::move(q));
          ++out.patioParcels;
        }
      }
    }
  }

  const Polygon& block_;
  Polygon outline_;
  SkeletonParameters p_;
  detail::Rng rng_;
  const detail::Rng rngStart_;  // rng_ before step 4, for the exact route after a failed certificate
  const StreetWidths& widths_;
  double chordTolerance_ = 0;
  bool exactOnly_ = false;
  bool fast_ = false;  // steps 4 and 5 on the floating-point route
  const std::vector<std::vector<Ring>>* fastRegions_ = nullptr;
  double size_ = 0, reach_ = 0, accessTolerance_ = 0, target_ = 0, maxTime_ = 0;
  std::shared_ptr<const PreparedOutline> outlineEdges_;  // outline_, for the access test
  std::vector<Edge> edges_;
  std::vector<int> ringStart_;
  std::vector<SkVertex> vertices_;
  std::vector<Face> faces_;
  std::map<std::pair<int, int>, Point> crossings_;
  std::vector<Region> regions_;  // per contour edge: its face's part of the strips
  Region patios_;
  std::vector<Strip> strips_;
  std::vector<Candidate> parcels_;
};

// Back to the block's coordinates, where rounding can close what were
// separate points locally: cleaned there; a parcel pinched into a corridor of
// no width becomes its parts (street access counted again). Returns, per
// parcel, whether it was proved valid here (checkTiling need not test it again).
std::vector<char> finish(const Polygon& block, const Point& o, Subdivision& out, double minFrontage) {
  const Box b = bounds(block);
  const std::size_t streetParcels = out.parcels.size() - static_cast<std::size_t>(out.patioParcels);
  std::vector<Polygon> parcels;
  std::vector<char> valid;
  std::size_t street = 0;
  bool split = false;
  for (std::size_t i = 0; i < out.parcels.size(); ++i) {
    Polygon parcel = detail::translated(out.parcels[i], o.x, o.y);
    dropMicroFeatures(parcel, 1e-9 * (b.width() + b.height()));
    // A parcel of no width (all corridor) vanishes; the area check below
    // catches anything of substance lost.
    if (!normalise(parcel)) continue;
    // A ring clearly simple (floating-point test with a margin) is valid as it is.
    const bool simple = parcel.holes.empty() && isClearlySimple(parcel.outer);
    std::vector<Polygon> parts = simple ? std::vector<Polygon>{parcel} : geos::validParts(parcel);
    double partsArea = 0;
    for (const Polygon& q : parts) partsArea += area(q);
    if (std::fabs(partsArea - area(parcel)) > 1e-9 * area(parcel)) throw Fallback("a parcel is not valid once rounded");
    split = split || parts.size() != 1;
    if (i < streetParcels) street += parts.size();
    valid.insert(valid.end(), parts.size(), simple);
    for (Polygon& q : parts) parcels.push_back(std::move(q));
  }
  out.parcels = std::move(parcels);
  out.patioParcels = static_cast<int>(out.parcels.size() - street);
  if (split) {
    const Polygon outline{block.outer, {}};
    const double tolerance = std::max(1e-6, 1e-9 * (b.width() + b.height()));
    out.withoutAccess = 0;
    for (std::size_t i = 0; i < street; ++i) {
      out.withoutAccess += analysis::sharedBoundaryLength(out.parcels[i], outline, tolerance) < minFrontage;
    }
  }
  return valid;
}

}  // namespace

namespace detail {

InnerSkeleton innerSkeleton(const Ring& ring, std::size_t maxEvents) {
  std::vector<Kc::Point_2> outer;
  outer.reserve(ring.size());
  for (const Point& p : ring) outer.emplace_back(p.x, p.y);
  GuardVisitor guard(maxEvents);
  SkeletonMaker maker(boost::none, SkeletonTraits(), guard);
  maker.enter_contour(outer.begin(), outer.end());
  const auto ss = maker.construct_skeleton();
  if (guard.overBudget)
    throw OverBudget("the straight skeleton made more than " + std::to_string(maxEvents) + " events");
  if (!ss)
    throw Fallback(guard.broken ? "the straight skeleton came out broken" : "no straight skeleton could be built");
  InnerSkeleton out;
  std::unordered_map<const void*, int> index;
  auto nodeOf = [&](auto v) {
    auto [it, added] = index.emplace(&*v, static_cast<int>(out.nodes.size()));
    if (added) {
      out.nodes.push_back({v->point().x(), v->point().y()});
      out.time.push_back(v->time());
    }
    return it->second;
  };
  for (auto h = ss->halfedges_begin(); h != ss->halfedges_end(); ++h) {
    // Each edge once (from its halfedge of lower address), skeleton nodes only.
    if (!h->is_bisector() || &*h > &*h->opposite()) continue;
    const auto a = h->opposite()->vertex(), b = h->vertex();
    if (a->is_contour() || b->is_contour()) continue;
    out.edges.emplace_back(nodeOf(a), nodeOf(b));
  }
  return out;
}

}  // namespace detail

struct SkeletonLayout {
  Polygon block;  // as given to subdivideSkeleton
  StreetWidths widths;
  SkeletonParameters parameters;
  std::array<LayoutAttempt, std::size(kChordTolerances)> attempts;  // by try
  bool blockValid = false;  // the block passed the validity check (not made again for it)
  // The block's outline (in the coordinates the builder works in) prepared
  // for the access test, kept for the next run on the same block.
  std::shared_ptr<const PreparedOutline> outlineEdges;
};

namespace {
bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool sameRingBits(const Ring& a, const Ring& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](const Point& p, const Point& q) { return sameBits(p.x, q.x) && sameBits(p.y, q.y); });
}

bool sameBlock(const Polygon& a, const Polygon& b) {
  return sameRingBits(a.outer, b.outer) &&
         std::equal(a.holes.begin(), a.holes.end(), b.holes.begin(), b.holes.end(), sameRingBits);
}

}  // namespace

bool sameStreetWidths(const StreetWidths& a, const StreetWidths& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& x, const auto& y) {
    return std::equal(x.begin(), x.end(), y.begin(), y.end(), sameBits);
  });
}

bool skeletonLayoutReusable(const SkeletonParameters& recorded, const SkeletonParameters& wanted) {
  return sameBits(recorded.offset, wanted.offset) && sameBits(recorded.streetAngle, wanted.streetAngle) &&
         recorded.corner == wanted.corner;
}

Subdivision subdivideSkeleton(const Polygon& block, const SkeletonParameters& parameters, std::uint64_t seed,
                              const StreetWidths& streetWidths, const SkeletonReuse& reuse) {
  SkeletonParameters p = parameters;
  p.bounds.aMax = std::max(p.bounds.aMax, p.bounds.aMin);
  p.bounds.wMax = std::max(p.bounds.wMax, p.bounds.wMin);
  // Drawn widths: finite and positive, none narrower than W_min (a split may
  // not make a narrower parcel; sliver parcels in the sample would otherwise
  // cut a street into thousands of slices).
  std::vector<double> widths;
  for (double w : p.sliceWidths) {
    if (std::isfinite(w) && w > 0) widths.push_back(std::max(w, p.bounds.wMin));
  }
  p.sliceWidths = std::move(widths);
  auto layout = std::make_shared<SkeletonLayout>();
  const SkeletonLayout* previous = reuse.previous;
  const bool sameBlockAsBefore = previous && sameBlock(previous->block, block);
  if (sameBlockAsBefore) layout->outlineEdges = previous->outlineEdges;
  if (sameBlockAsBefore && sameStreetWidths(previous->widths, streetWidths)) {
    layout->attempts = previous->attempts;
    // The skeleton (step 1) depends on the block and widths alone; the strips
    // also on d_offset, the street angle and the corner rule.
    if (!skeletonLayoutReusable(previous->parameters, p)) {
      for (LayoutAttempt& a : layout->attempts) a.strips.reset();
    }
  }
  if (reuse.record) {
    layout->block = block;
    layout->widths = streetWidths;
    layout->parameters = p;
  }
  const Point o = detail::exactShiftOrigin(block);
  Polygon local = detail::translated(block, -o.x, -o.y);
  Subdivision out;
  std::string reason;
  try {
    const bool checked = sameBlockAsBefore && previous->blockValid;
    if (!normalise(local) || (!checked && !detail::isValidForSplit(local))) {
      throw Fallback("the block is not a valid polygon with holes");
    }
    layout->blockValid = true;
    for (std::size_t attempt = 0;; ++attempt) {
      try {
        out = Subdivision{};
        SkeletonBuilder(local, p, detail::Rng{detail::splitmix64(seed ^ 0x5EC0DE)}, streetWidths,
                        kChordTolerances[attempt], reuse.exactOnly, layout->outlineEdges)
            .run(out, layout->attempts[attempt], reuse.record);
        break;
      } catch (const SkeletonFolds&) {
        std::size_t vertices = local.outer.size();
        for (const Ring& h : local.holes) vertices += h.size();
        const bool last = attempt + 2 == std::size(kChordTolerances) ? vertices > kMaxFullVertices
                                                                     : attempt + 1 == std::size(kChordTolerances);
        if (last) throw;
      }
    }
    // Back to the block's coordinates, where rounding can close what were
    // separate points locally: clean and check there.
    const std::vector<char> valid = finish(block, o, out, p.bounds.minFrontage);
    detail::checkTiling(block, out, valid);
  } catch (const std::exception& e) {
    detail::rethrowUnlessBlockFailure();
    reason = e.what();
  }
  if (!reason.empty()) out = detail::fallBackToObb(block, p.bounds, seed, reason);
  if (reuse.record) out.skeletonLayout = std::move(layout);
  return out;
}

}  // namespace parcelscope::generation

namespace parcelscope::generation {

namespace {

// skeleton: straight-skeleton strips along the streets (Vanegas et al. 2012,
// section 4.2); offset: the same with a finite d_offset (unless given: the block's mean observed parcel length, else 30
// m) and the patios subdivided with obb.
class SkeletonStyle : public Style {
public:
  explicit SkeletonStyle(bool offset) : offset_(offset) {}
  std::string name() const override { return offset_ ? "offset" : "skeleton"; }
  std::string description() const override {
    return offset_ ? "skeleton with a finite offset (the block's mean observed parcel length, else 30 m, unless "
                     "--offset) and patios subdivided by OBB"
                   : "straight-skeleton strips along the streets (4.2); --offset M leaves patios";
  }
  const std::vector<ParameterDescription>& parameters() const override {
    static const std::vector<ParameterDescription> p = [] {
      std::vector<ParameterDescription> all = obbParameterDescriptions();
      appendParameters(all, skeletonParameterDescriptions());
      return all;
    }();
    return p;
  }
  bool usesStreetWidths() const override { return true; }
  Subdivision run(const StyleRun& r) const override {
    SkeletonParameters p = skeletonParametersFrom(r.values);
    if (offset_) {
      // d_offset not given: the parcel depth of the block, its observed
      // parcels' mean length (long side of their bounding rectangle).
      if (p.offset <= 0 && r.observed && !r.observed->widths.empty()) {
        double sum = 0;
        std::size_t n = 0;
        for (std::size_t i = 0; i < r.observed->widths.size() && i < r.observed->aspectRatios.size(); ++i) {
          const double length = r.observed->widths[i] * r.observed->aspectRatios[i];
          if (std::isfinite(length) && length > 0) {
            sum += length;
            ++n;
          }
        }
        if (n > 0) p.offset = sum / static_cast<double>(n);
      }
      if (p.offset <= 0) p.offset = kDefaultOffsetStyleDepth;
      p.subdividePatios = true;
    }
    // subdivideSkeleton keeps the finite, positive widths, each at least W_min.
    if (p.observedSliceWidths && r.observed) p.sliceWidths = r.observed->widths;
    // The layout checks for itself that it was made for this block and these parameters.
    const SkeletonLayout* layout = r.previous ? r.previous->skeletonLayout.get() : nullptr;
    return subdivideSkeleton(r.block, p, r.seed, r.streetWidths, {layout, r.record});
  }

private:
  static constexpr double kDefaultOffsetStyleDepth = 30.0;  // m, style offset without --offset or observed parcels
  bool offset_;
};

}  // namespace

const Style& skeletonStyle() {
  static const SkeletonStyle s(false);
  return s;
}

const Style& offsetStyle() {
  static const SkeletonStyle s(true);
  return s;
}

}  // namespace parcelscope::generation
