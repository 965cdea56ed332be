// template: the template-based splitting of Yang et al. 2013 (section 4 and
// 4.1): parcel-level templates of their Figure 4 (a row of parcels, a grid of
// two rows back to back, the spike of parcels around a dead end) are matched
// to a block by its corners, ranked by the distortion of boundary lengths and
// by how well their parcels fit the block's bounds and observed parcels,
// warped onto the block (TemplateWarp.h), and their interior lines used as
// split lines on the block itself, coarse level first. docs/algorithms/
// template.md gives the choices the paper leaves open.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "LotSplit.h"
#include "PostProcess.h"
#include "Random.h"
#include "TemplateWarp.h"
#include "parcelscope/analysis/Metrics.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/generation/Styles.h"

namespace parcelscope::generation {

namespace {

using detail::Corner;
using detail::PartClass;
using detail::Template;
using detail::TemplatePart;

const std::vector<ParameterDescription>& templateParameterDescriptions() {
  static const std::vector<ParameterDescription> d = [] {
    std::vector<ParameterDescription> all;
    for (const ParameterDescription& p : obbParameterDescriptions()) {
      if (p.name == "a-min" || p.name == "a-max" || p.name == "w-min" || p.name == "w-max" ||
          p.name == "min-frontage" || p.name == "seed") {
        all.push_back(p);
      }
    }
    all.push_back(realParameter("template-distortion",
                                "template: largest boundary-length distortion at which a template fits a block region "
                                "(RMS log ratio of arc lengths, plus over 180 degrees each arc's net turn at corners "
                                "left unmatched and a tenth of their turns); regions none fits are split at a concave "
                                "corner or left to obb",
                                "", 0.0, 10.0, 2.0, "Subdivision"));
    all.push_back(integerParameter("warp-iterations",
                                   "template: rounds of registration and regression warping a template to a block", "",
                                   0.0, 1000.0, 30.0, "Subdivision"));
    return all;
  }();
  return d;
}

struct TemplateParameters {
  double aMin = 200, aMax = 800, wMin = 8, wMax = 30, minFrontage = 1;
  double maxDistortion = 2.0;
  int iterations = 30;
};

TemplateParameters templateParametersFrom(const ParameterValues& v) {
  TemplateParameters p;
  for (const auto& [name, target] :
       {std::pair{"a-min", &p.aMin}, std::pair{"a-max", &p.aMax}, std::pair{"w-min", &p.wMin},
        std::pair{"w-max", &p.wMax}, std::pair{"min-frontage", &p.minFrontage},
        std::pair{"template-distortion", &p.maxDistortion}}) {
    readValue(v, name, *target);
  }
  readValue(v, "warp-iterations", p.iterations);
  p.aMax = std::max(p.aMax, p.aMin);
  p.wMax = std::max(p.wMax, p.wMin);
  return p;
}

constexpr double kCornerTurn = 30.0 * kPi / 180.0;  // sides turning by less meet at a regular boundary vertex
constexpr std::size_t kMaxCorners = 12;
// Two corners joined by a side shorter than this share of both sides around
// them are one (a jog in a street, a cut-off corner).
constexpr double kShortSide = 0.3;
// An arc with at least this share of its length on the block's outer ring is
// a street (edges semantics of section 4.1's initialisation).
constexpr double kStreetShare = 0.5;
constexpr double kChordSag = 0.05;                // the sharpest, for the matching's enumeration
constexpr std::size_t kMaxCoarseVertices = 5000;  // blocks with more sides get no template
constexpr int kMaxPerRow = 2000;
constexpr std::size_t kMaxLots = 200000;
// Parcels looked at, summed over the merges of parcels without street access
// in one block (mergeWithoutAccess): about 2 s.
constexpr std::size_t kMaxMergeWork = 20000000;
constexpr double kNearBest = 0.05;   // candidates this close to the best score are drawn at random
constexpr double kOutOfBounds = 10;  // weight of a parcel's squared log excess beyond a bound
constexpr int kMaxWarps = 3;         // candidates warped before the block falls back
// A warp whose registration residual (RMS, m) exceeds this share of the
// template's parcel size (square root of its mean parcel area) breaks the
// parts' tolerances: the next candidate is tried.
constexpr double kMaxResidualShare = 0.35;
// Regions no template fits are subdivided by obb inside the block; when they
// are more than this share of it, the whole block falls back to obb.
constexpr double kMaxObbShare = 0.5;

// The parcel sizes a template aims at: the block's bounds, and within them the
// medians of its observed parcels (without: the bounds' geometric means).
struct Sizes {
  double aMin, aMax, wMin, wMax, width, area;
  double aspect = 0;  // median observed aspect ratio (length / width); 0: none
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Sizes sizesFrom(const TemplateParameters& p, const ObservedSample* observed) {
  // A lower bound of 0 (no smallest parcel) counts as a millionth of the upper
  // one here, so that the aim stays positive (a zero aim split nothing).
  auto mean = [](double lo, double hi) { return std::sqrt(std::max(lo, 1e-6 * hi) * hi); };
  Sizes s{p.aMin, p.aMax, p.wMin, p.wMax, mean(p.wMin, p.wMax), mean(p.aMin, p.aMax)};
  if (observed && !observed->widths.empty()) s.width = median(observed->widths);
  if (observed && !observed->areas.empty()) s.area = median(observed->areas);
  if (observed) {
    std::vector<double> ratios;
    for (double r : observed->aspectRatios) {
      if (std::isfinite(r) && r >= 1) ratios.push_back(r);
    }
    if (!ratios.empty()) s.aspect = median(ratios);
  }
  s.width = std::clamp(s.width, s.wMin, s.wMax);
  s.area = std::clamp(s.area, s.aMin, s.aMax);
  return s;
}

struct Count {
  int n = 1;
  double cost = 0;
};

double excess(double v, double lo, double hi) { return v < lo ? std::log(lo / v) : v > hi ? std::log(v / hi) : 0.0; }

// How many parcels a row `length` long and `depth` deep holds: the count whose
// parcels' frontage and area are closest (log ratio) to the targets, parcels
// outside the bounds (width: the smaller of frontage and depth) penalised.
Count parcelsAlong(double length, double depth, const Sizes& s) {
  Count best{1, std::numeric_limits<double>::infinity()};
  if (!(length > 0) || !(depth > 0)) return {1, 0};
  const double a = length * depth;
  const double lo = std::max(1.0, std::floor(std::min(length / s.wMax, a / s.aMax)));
  const double hi = std::min(static_cast<double>(kMaxPerRow), std::ceil(std::max(length / s.wMin, a / s.aMin)));
  for (double n = std::min(lo, hi); n <= std::max(lo, hi); n += 1) {
    const double f = length / n, parcel = a / n, w = std::min(f, depth);
    const double ew = excess(w, s.wMin, s.wMax), ea = excess(parcel, s.aMin, s.aMax);
    const double lf = std::log(f / s.width), la = std::log(parcel / s.area);
    // The parcel's shape too: a deep row of narrow parcels matches width and
    // area and still makes strips the observed parcels are not.
    const double lr = s.aspect > 0 ? std::log(std::max(f, depth) / w / s.aspect) : 0.0;
    const double cost = 0.5 * (lf * lf + la * la + lr * lr) + kOutOfBounds * (ew * ew + ea * ea);
    if (cost < best.cost) best = {static_cast<int>(n), cost};
  }
  return best;
}

// The parts' deformation classes (docs/algorithms/template.md): a parcel of a
// row stretches along the row more than across it; rows of the first level
// more; fan parcels of the spike in both directions.
TemplatePart affinePart(double alongLo, double alongHi, double acrossLo, double acrossHi, double tolerance) {
  return {{}, PartClass::Affine, alongLo, alongHi, acrossLo, acrossHi, tolerance};
}
const TemplatePart kRowParcel = affinePart(0.6, 1.6, 0.8, 1.25, 0.2);
const TemplatePart kWholeRow = affinePart(0.5, 2.0, 0.75, 1.33, 0.3);
const TemplatePart kArmParcel = affinePart(0.8, 1.25, 0.6, 1.6, 0.2);  // arms run along y
const TemplatePart kFanParcel = affinePart(0.5, 2.0, 0.5, 2.0, 0.4);

// Vertices on horizontal lines of a template, found again by position.
class Builder {
public:
  explicit Builder(Template& t, double scale) : t_(t), tolerance_(1e-9 * scale) {}
  int at(double x, double y) {
    for (std::size_t i = 0; i < t_.vertices.size(); ++i) {
      if (std::fabs(t_.vertices[i].x - x) <= tolerance_ && std::fabs(t_.vertices[i].y - y) <= tolerance_)
        return static_cast<int>(i);
    }
    t_.vertices.push_back({x, y});
    return static_cast<int>(t_.vertices.size()) - 1;
  }
  void boundary(int v, signed char corner = 0) {
    if (!t_.boundary.empty() && t_.boundary.back() == v) return;
    t_.boundary.push_back(v);
    t_.corners.push_back(corner);
  }
  void part(std::vector<int> ring, const TemplatePart& kind) {
    TemplatePart p = kind;
    p.ring = std::move(ring);
    p.ring.erase(std::unique(p.ring.begin(), p.ring.end()), p.ring.end());
    while (p.ring.size() > 1 && p.ring.front() == p.ring.back()) p.ring.pop_back();
    t_.parts.push_back(std::move(p));
  }

private:
  Template& t_;
  double tolerance_;
};

// A row (one entry in `counts`) or a grid of two rows back to back: the
// rectangle [0, L] x [0, D], rows along x, counts[r] parcels in row r; its
// corners (0, 0), (L, 0), (L, D), (0, D). The lines between rows split first.
Template gridTemplate(double L, double D, const std::vector<int>& counts, const TemplatePart& parcel) {
  Template t;
  const std::size_t m = counts.size();
  t.name = m == 1 ? "row" : "grid";
  Builder b(t, L + D);
  auto y = [&](std::size_t j) { return D * static_cast<double>(j) / static_cast<double>(m); };
  auto xs = [&](std::size_t r) {  // the cross lines of row r, ends included
    std::vector<double> v;
    for (int i = 0; i <= counts[r]; ++i) v.push_back(L * i / counts[r]);
    return v;
  };
  // The vertices of line j (between rows j - 1 and j), left to right.
  std::vector<std::vector<int>> line(m + 1);
  for (std::size_t j = 0; j <= m; ++j) {
    std::vector<double> x;
    for (std::size_t r : {j - 1, j}) {
      if (r < m) {
        const std::vector<double> v = xs(r);
        x.insert(x.end(), v.begin(), v.end());
      }
    }
    std::sort(x.begin(), x.end());
    for (double v : x) {
      const int k = b.at(v, y(j));
      if (line[j].empty() || line[j].back() != k) line[j].push_back(k);
    }
  }
  for (std::size_t k = 0; k < line[0].size(); ++k) b.boundary(line[0][k], k == 0 || k + 1 == line[0].size());
  for (std::size_t j = 1; j < m; ++j) b.boundary(line[j].back());
  for (std::size_t k = line[m].size(); k-- > 0;) b.boundary(line[m][k], k == 0 || k + 1 == line[m].size());
  for (std::size_t j = m - 1; j >= 1; --j) b.boundary(line[j].front());
  for (std::size_t j = 1; j < m; ++j) t.splits.push_back(line[j]);
  for (std::size_t r = 0; r < m; ++r) {
    const std::vector<double> x = xs(r);
    for (int i = 0; i < counts[r]; ++i) {
      std::vector<int> ring;
      for (int v : line[r]) {
        if (t.vertices[v].x >= x[i] - 1e-9 * L && t.vertices[v].x <= x[i + 1] + 1e-9 * L) ring.push_back(v);
      }
      std::vector<int> top;
      for (int v : line[r + 1]) {
        if (t.vertices[v].x >= x[i] - 1e-9 * L && t.vertices[v].x <= x[i + 1] + 1e-9 * L) top.push_back(v);
      }
      ring.insert(ring.end(), top.rbegin(), top.rend());
      b.part(ring, parcel);
      if (i > 0) t.splits.push_back({b.at(x[i], y(r)), b.at(x[i], y(r + 1))});
    }
  }
  return t;
}

// The spike around a dead end: the rectangle [0, W] x [0, H] with a notch
// [x1, x1 + wn] x [0, dn] from its bottom side (the dead-end street); its
// corners, counter-clockwise from (0, 0): convex, the notch's mouth (convex),
// its end (two concave), its mouth (convex), then the rectangle's three other
// corners. Level 2: the lines from the notch's end to both sides; then rows of
// parcels along both of the notch's walls (left, right counts) and a fan of
// `fan` parcels radiating from the notch's end.
Template spikeTemplate(double W, double H, double x1, double wn, double dn, int left, int right, int fan) {
  Template t;
  t.name = "spike";
  Builder b(t, W + H);
  const double x2 = x1 + wn, headPath = 2 * (H - dn) + W;
  const int c0 = b.at(0, 0), e1 = b.at(x1, 0), t1 = b.at(x1, dn), t2 = b.at(x2, dn), e2 = b.at(x2, 0), c5 = b.at(W, 0),
            c6 = b.at(W, H), c7 = b.at(0, H), l1 = b.at(0, dn), r1 = b.at(W, dn);
  auto armY = [&](int j, int n) { return dn * j / n; };
  // The head's outer path from l1 (s = 0) up, along the top and down to r1 (s = headPath).
  auto onPath = [&](double s) {
    if (s <= H - dn) return b.at(0, dn + s);
    if (s <= H - dn + W) return b.at(s - (H - dn), H);
    return b.at(W, H - (s - (H - dn) - W));
  };
  std::vector<int> p(fan + 1), q(fan + 1);
  for (int i = 0; i <= fan; ++i) {
    p[i] = i == 0 ? t1 : i == fan ? t2 : b.at(x1 + wn * i / fan, dn);
    q[i] = i == 0 ? l1 : i == fan ? r1 : onPath(headPath * i / fan);
  }
  // The boundary, counter-clockwise.
  b.boundary(c0, 1);
  b.boundary(e1, 1);
  for (int j = 1; j < left; ++j) b.boundary(b.at(x1, armY(j, left)));
  b.boundary(t1, -1);
  for (int i = 1; i < fan; ++i) b.boundary(p[i]);
  b.boundary(t2, -1);
  for (int j = right - 1; j >= 1; --j) b.boundary(b.at(x2, armY(j, right)));
  b.boundary(e2, 1);
  b.boundary(c5, 1);
  for (int j = 1; j < right; ++j) b.boundary(b.at(W, armY(j, right)));
  b.boundary(r1);
  std::vector<std::pair<double, int>> path{{0.0, l1}, {H - dn, c7}, {H - dn + W, c6}, {headPath, r1}};
  for (int i = 1; i < fan; ++i) path.emplace_back(headPath * i / fan, q[i]);
  std::stable_sort(path.begin(), path.end());
  for (auto it = path.rbegin(); it != path.rend(); ++it) b.boundary(it->second, it->second == c6 || it->second == c7);
  for (int j = left - 1; j >= 1; --j) b.boundary(b.at(0, armY(j, left)));
  if (t.boundary.back() == c0) {
    t.boundary.pop_back();
    t.corners.pop_back();
  }
  // Parts and split lines.
  t.splits.push_back({l1, t1});
  t.splits.push_back({t2, r1});
  for (int j = 0; j < left; ++j) {
    const double y0 = armY(j, left), y1 = armY(j + 1, left);
    b.part({b.at(0, y0), b.at(x1, y0), b.at(x1, y1), b.at(0, y1)}, kArmParcel);
    if (j > 0) t.splits.push_back({b.at(0, y0), b.at(x1, y0)});
  }
  for (int j = 0; j < right; ++j) {
    const double y0 = armY(j, right), y1 = armY(j + 1, right);
    b.part({b.at(x2, y0), b.at(W, y0), b.at(W, y1), b.at(x2, y1)}, kArmParcel);
    if (j > 0) t.splits.push_back({b.at(x2, y0), b.at(W, y0)});
  }
  for (int i = 0; i < fan; ++i) {
    std::vector<int> ring{p[i], p[i + 1]};
    const double s0 = headPath * i / fan, s1 = headPath * (i + 1) / fan;
    for (auto it = path.rbegin(); it != path.rend(); ++it) {
      if (it->first >= s0 - 1e-9 * headPath && it->first <= s1 + 1e-9 * headPath) ring.push_back(it->second);
    }
    b.part(ring, kFanParcel);
    if (i > 0) t.splits.push_back({p[i], q[i]});
  }
  return t;
}

// A template matched to a block: which one, its dimensions, its corners on
// the block and its score.
struct Candidate {
  enum Kind { Row, Grid, Spike } kind = Row;
  std::vector<std::size_t> matched;  // ring vertices of the template's corners
  double distortion = 0, score = 0;
  double L = 0, D = 0;                          // row, grid: the rectangle
  double W = 0, H = 0, x1 = 0, wn = 0, dn = 0;  // spike
  int left = 1, right = 1, fan = 2;
};

// What the corners a matching leaves out cost, over pi: on each arc between
// two matched corners (`used`, in ring order), the net turn of the corners
// left out (the arc's bend the template's straight side does not have), and
// kSkippedTurn of their summed turns (a jog or a notch whose turns cancel).
constexpr double kSkippedTurn = 0.1;
double skippedTurns(const std::vector<Corner>& corners, const std::vector<std::size_t>& used) {
  const std::size_t c = corners.size();
  double s = 0;
  for (std::size_t k = 0; k < used.size(); ++k) {
    double net = 0, total = 0;
    for (std::size_t i = (used[k] + 1) % c; i != used[(k + 1) % used.size()]; i = (i + 1) % c) {
      net += corners[i].type * corners[i].turn;
      total += corners[i].turn;
    }
    s += (std::fabs(net) + kSkippedTurn * total) / kPi;
  }
  return s;
}

class Matcher {
public:
  /// street[i]: edge i of `ring` lies on a street (the block's outer ring).
  Matcher(const Ring& ring, const std::vector<char>& street, const std::vector<Corner>& corners, const Sizes& sizes,
          double maxDistortion)
      : ring_(ring), corners_(corners), sizes_(sizes), maxDistortion_(maxDistortion) {
    cumulative_.push_back(0);
    streetCumulative_.push_back(0);
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Point &a = ring[i], &b = ring[(i + 1) % ring.size()];
      const double l = norm(b.x - a.x, b.y - a.y);
      cumulative_.push_back(cumulative_.back() + l);
      streetCumulative_.push_back(streetCumulative_.back() + (street[i] ? l : 0.0));
    }
  }

  std::vector<Candidate> candidates() {
    std::vector<Candidate> out;
    quads(out);
    spikes(out);
    std::stable_sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
    return out;
  }

private:
  double arc(std::size_t from, std::size_t to) const {
    const double d = cumulative_[to] - cumulative_[from];
    return to > from ? d : cumulative_.back() + d;
  }
  // The share of the arc from corner `from` to corner `to` (of corners_) on a street.
  bool onStreet(std::size_t from, std::size_t to) const {
    const std::size_t a = corners_[from].index, b = corners_[to].index;
    const double d = streetCumulative_[b] - streetCumulative_[a];
    const double s = b > a ? d : streetCumulative_.back() + d;
    return s >= kStreetShare * arc(a, b);
  }
  std::vector<double> arcs(const std::vector<std::size_t>& corner) const {
    std::vector<double> a;
    for (std::size_t k = 0; k < corner.size(); ++k) {
      a.push_back(arc(corners_[corner[k]].index, corners_[corner[(k + 1) % corner.size()]].index));
    }
    return a;
  }
  std::vector<std::size_t> ringIndices(const std::vector<std::size_t>& corner, std::size_t rotation) const {
    std::vector<std::size_t> m;
    for (std::size_t k = 0; k < corner.size(); ++k) m.push_back(corners_[corner[(k + rotation) % corner.size()]].index);
    return m;
  }

  // Row and grid: four convex corners; rows along arcs 0 and 2 or along 1 and 3.
  void quads(std::vector<Candidate>& out) const {
    std::vector<std::size_t> convex;
    for (std::size_t k = 0; k < corners_.size(); ++k) {
      if (corners_[k].type > 0) convex.push_back(k);
    }
    const std::size_t c = convex.size();
    for (std::size_t i = 0; i < c; ++i)
      for (std::size_t j = i + 1; j < c; ++j)
        for (std::size_t k = j + 1; k < c; ++k)
          for (std::size_t l = k + 1; l < c; ++l) {
            const std::vector<std::size_t> used{convex[i], convex[j], convex[k], convex[l]};
            const std::vector<double> a = arcs(used);
            const double skipped = skippedTurns(corners_, used);
            for (std::size_t rotation : {0u, 1u}) {
              const double L = 0.5 * (a[rotation] + a[rotation + 2]),
                           D = 0.5 * (a[rotation + 1] + a[(rotation + 3) % 4]);
              const double distortion =
                  detail::boundaryDistortion(
                      {L, D, L, D}, {a[rotation], a[rotation + 1], a[(rotation + 2) % 4], a[(rotation + 3) % 4]}) +
                  skipped;
              if (!(distortion <= maxDistortion_)) continue;
              // The paper's edge semantics: every row fronts a street (a row
              // spans the depth: one of its long sides will do).
              const bool front = onStreet(used[rotation], used[rotation + 1]);
              const bool back = onStreet(used[(rotation + 2) % 4], used[(rotation + 3) % 4]);
              for (int rows : {1, 2}) {
                if (rows == 1 ? !(front || back) : !(front && back)) continue;
                Candidate cand;
                cand.kind = rows == 1 ? Candidate::Row : Candidate::Grid;
                cand.matched = ringIndices(used, rotation);
                cand.L = L;
                cand.D = D;
                cand.distortion = distortion;
                cand.score = distortion + parcelsAlong(L, D / rows, sizes_).cost;
                out.push_back(cand);
              }
            }
          }
  }

  // Spike: two consecutive concave corners (the dead end's end) between two
  // convex ones (its mouth), and four more convex corners.
  void spikes(std::vector<Candidate>& out) const {
    const std::size_t c = corners_.size();
    if (c < 8) return;
    for (std::size_t k = 0; k < c; ++k) {
      const std::size_t e1 = k, t1 = (k + 1) % c, t2 = (k + 2) % c, e2 = (k + 3) % c;
      if (corners_[e1].type < 0 || corners_[t1].type > 0 || corners_[t2].type > 0 || corners_[e2].type < 0) continue;
      std::vector<std::size_t> rest;  // convex corners after the mouth, in order
      for (std::size_t s = 4; s < c; ++s) {
        if (corners_[(k + s) % c].type > 0) rest.push_back((k + s) % c);
      }
      const std::size_t r = rest.size();
      for (std::size_t a = 0; a < r; ++a)
        for (std::size_t b = a + 1; b < r; ++b)
          for (std::size_t d = b + 1; d < r; ++d)
            for (std::size_t e = d + 1; e < r; ++e) {
              // Template order from its corner (0, 0): c0, e1, t1, t2, e2, c5, c6, c7.
              const std::vector<std::size_t> used{rest[e], e1, t1, t2, e2, rest[a], rest[b], rest[d]};
              const std::vector<double> x = arcs(used);
              Candidate cand;
              cand.kind = Candidate::Spike;
              cand.H = 0.5 * (x[5] + x[7]);
              cand.dn = std::min(0.5 * (x[1] + x[3]), 0.8 * cand.H);
              cand.wn = x[2];
              cand.W = 0.5 * (x[0] + x[2] + x[4] + x[6]);
              if (!(cand.W > cand.wn) || !(x[0] > 0) || !(x[4] > 0)) continue;
              cand.x1 = (cand.W - cand.wn) * x[0] / (x[0] + x[4]);
              const double x2 = cand.x1 + cand.wn;
              cand.distortion = detail::boundaryDistortion(
                                    {cand.x1, cand.dn, cand.wn, cand.dn, cand.W - x2, cand.H, cand.W, cand.H}, x) +
                                skippedTurns(corners_, used);
              if (!(cand.distortion <= maxDistortion_)) continue;
              const Count left = parcelsAlong(cand.dn, cand.x1, sizes_);
              const Count right = parcelsAlong(cand.dn, cand.W - x2, sizes_);
              const Count fan = parcelsAlong(cand.W, cand.H - cand.dn, sizes_);
              cand.left = left.n;
              cand.right = right.n;
              cand.fan = std::max(2, fan.n);
              if (!onStreet(e1, t1) || !onStreet(t2, e2)) continue;  // the dead end is a street
              cand.matched = ringIndices(used, 0);
              cand.score = cand.distortion + (left.cost + right.cost + fan.cost) / 3;
              out.push_back(cand);
            }
    }
  }

  const Ring& ring_;
  const std::vector<Corner>& corners_;
  Sizes sizes_;
  double maxDistortion_;
  std::vector<double> cumulative_;        // arc length from vertex 0 to vertex i
  std::vector<double> streetCumulative_;  // the same, of street edges only
};

// The template of a candidate, hierarchically for rows and grids (the paper's
// Figure 5): the rows are warped first, and the length each takes on the block
// sets its number of parcels.
Template instantiate(const Candidate& c, const Ring& ring, const Sizes& sizes, int iterations) {
  if (c.kind == Candidate::Spike) return spikeTemplate(c.W, c.H, c.x1, c.wn, c.dn, c.left, c.right, c.fan);
  const std::size_t m = c.kind == Candidate::Row ? 1 : 2;
  const Template rows = gridTemplate(c.L, c.D, std::vector<int>(m, 1), kWholeRow);
  const detail::Warp w = detail::warpTemplate(rows, ring, c.matched, iterations);
  std::vector<int> counts;
  for (std::size_t r = 0; r < m; ++r) {
    // Row r lies between the template's lines r and r + 1; with one parcel a
    // row, each line is its two ends.
    const TemplatePart& part = rows.parts[r];
    const Point &a = w.positions[part.ring[0]], &b = w.positions[part.ring[1]];
    const Point &c2 = w.positions[part.ring[2]], &d = w.positions[part.ring[3]];
    const double length = 0.5 * (norm(b.x - a.x, b.y - a.y) + norm(c2.x - d.x, c2.y - d.y));
    const double depth = 0.5 * (norm(d.x - a.x, d.y - a.y) + norm(c2.x - b.x, c2.y - b.y));
    counts.push_back(parcelsAlong(length, depth, sizes).n);
  }
  return gridTemplate(c.L, c.D, counts, kRowParcel);
}

// Whether `p` (near the origin) is still a valid polygon once moved back by
// `origin`, its vertices rounded, as checkTiling will test it. A ring clearly
// simple here stays so (its margin, 1e-9 of its size, is far above the
// rounding); others are tested moved back, by GEOS up to kMaxTestedVertices
// (beyond, refused: GEOS on every split of a large piece costs minutes on
// malibu_ca's hillside blocks).
constexpr std::size_t kMaxTestedVertices = 256;
bool validAt(const Polygon& p, const Point& origin) {
  if (p.holes.empty() && isClearlySimple(p.outer)) return true;
  std::size_t vertices = p.outer.size();
  for (const Ring& h : p.holes) vertices += h.size();
  if (vertices > kMaxTestedVertices) return false;
  const Polygon back = detail::translated(p, origin.x, origin.y);
  return (back.holes.empty() && isClearlySimple(back.outer)) || geos::isValid(back);
}

// The vertex of `piece` within `tolerance` of `p`, if any.
const Point* vertexNear(const Polygon& piece, const Point& p, double tolerance) {
  auto in = [&](const Ring& r) -> const Point* {
    for (const Point& v : r) {
      if (norm(v.x - p.x, v.y - p.y) <= tolerance) return &v;
    }
    return nullptr;
  };
  if (const Point* v = in(piece.outer)) return v;
  for (const Ring& h : piece.holes) {
    if (const Point* v = in(h)) return v;
  }
  return nullptr;
}

// The block split along the warped template's interior lines, each the
// straight line through its warped ends, applied to the piece that holds the
// line's middle (the block's own geometry: the parcels tile it exactly).
std::vector<Polygon> applySplits(const Polygon& block, const Template& t, const std::vector<Point>& at,
                                 const Point& origin) {
  std::vector<Polygon> pieces{block};
  std::vector<double> areas{area(block)};
  std::vector<Box> boxes{bounds(block)};
  for (const std::vector<int>& chain : t.splits) {
    const Point &p = at[chain.front()], &q = at[chain.back()];
    const double length = norm(q.x - p.x, q.y - p.y);
    const Point middle = chain.size() > 2 ? at[chain[chain.size() / 2]] : Point{0.5 * (p.x + q.x), 0.5 * (p.y + q.y)};
    std::size_t holder = pieces.size();
    for (std::size_t k = 0; k < pieces.size() && holder == pieces.size(); ++k) {
      const Box& b = boxes[k];
      if (middle.x >= b.minX && middle.x <= b.maxX && middle.y >= b.minY && middle.y <= b.maxY &&
          pointInPolygon(middle, pieces[k]))
        holder = k;
    }
    if (holder == pieces.size() || !(length > 0)) continue;  // a line the warp folded away
    // An end on a vertex of the piece (a corner of the block) is where the
    // line passes exactly: a line passing a rounding error beside a vertex
    // leaves an edge of 1e-14 m that rounding back to the block's frame folds.
    Point through = p, towards = q;
    if (const Point* v = vertexNear(pieces[holder], q, 1e-9 * length);
        v && !vertexNear(pieces[holder], p, 1e-9 * length)) {
      through = *v;
      towards = p;
    } else if (const Point* w = vertexNear(pieces[holder], p, 1e-9 * length)) {
      through = *w;
    }
    const double d = norm(towards.x - through.x, towards.y - through.y);
    if (!(d > 0)) continue;
    const double whole = areas[holder];
    std::vector<Polygon> split =
        detail::splitLot(pieces[holder], whole, {through, {(towards.x - through.x) / d, (towards.y - through.y) / d}},
                         true, [&](const std::vector<Polygon>& made) {
                           for (const Polygon& m : made) {
                             if (area(m) < 1e-3 * whole) return false;
                             // nearly pinched (valid only by 1e-15 m): not this line
                             if (!validAt(m, origin)) return false;
                           }
                           return true;
                         });
    if (split.size() < 2) continue;
    for (std::size_t k = 0; k < split.size(); ++k) {
      const std::size_t to = k == 0 ? holder : pieces.size();
      if (k > 0) {
        pieces.emplace_back();
        areas.push_back(0);
        boxes.emplace_back();
      }
      areas[to] = area(split[k]);
      boxes[to] = bounds(split[k]);
      pieces[to] = std::move(split[k]);
    }
    if (pieces.size() > kMaxLots) throw detail::WorkBudgetExceeded("work budget: more than 200000 parcels");
  }
  return pieces;
}

// The block's ring with one vertex per side (LotSplit.h's sidesOf) where that
// is a simple ring: the template is warped onto it (projection costs grow
// with the vertices; sides are what a template's boundary follows).
Ring coarseRing(const Ring& ring) {
  Ring coarse;
  for (const detail::Side& s : detail::sidesOf(ring)) coarse.push_back(s.a);
  if (coarse.size() < 3 || signedArea(coarse) <= 0 || !isClearlySimple(coarse)) return ring;
  return coarse;
}

// The block's regions subdivided one by one: a region some template fits is
// split along its warped interior lines; one none fits is first split in two
// (the paper's streamline-based splitting, which this style replaces by its
// simplest case, docs/algorithms/template.md): along a side ending at its
// sharpest concave corner, or through a hole along the hole's longest side.
class RegionSubdivider {
public:
  RegionSubdivider(const Ring& outline, const Point& origin, const TemplateParameters& p, const ObbParameters& bounds,
                   const Sizes& sizes, std::uint64_t seed)
      : outline_(outline),
        origin_(origin),
        p_(p),
        bounds_(bounds),
        sizes_(sizes),
        rng_{detail::splitmix64(seed ^ 0x7E3A1A7EULL)} {
    const Box b = parcelscope::bounds(outline);
    tolerance_ = std::max(1e-6, 1e-9 * (b.width() + b.height()));
  }

  void subdivide(const Polygon& region, int depth) {
    if (!region.holes.empty()) {
      splitThenSubdivide(region, holeLines(region), depth, "no template fits: a hole no line opens");
      return;
    }
    const Ring ring = coarseRing(region.outer);
    if (ring.size() > kMaxCoarseVertices) {
      byObb(region, "no template fits: too many sides");
      return;
    }
    if (fit(region, ring)) return;

    splitThenSubdivide(region, concaveLines(ring), depth, "no template fits the block's corners");
  }

  std::vector<Polygon> parcels;
  std::map<std::string, double> areaByTemplate;
  double obbArea = 0;       // of the regions no template fits
  std::string lastFailure;  // why the last of them got none

private:
  static constexpr int kMaxDepth = 6;
  static constexpr double kMinShare = 0.02;     // of the region, the least piece of a split without template
  static constexpr std::size_t kMaxLines = 64;  // lines tried to split a region no template fits

  bool fit(const Polygon& region, Ring ring) {
    std::vector<Corner> corners = detail::cornersOf(ring, kCornerTurn, kMaxCorners, kShortSide);
    std::vector<Candidate> candidates = Matcher(ring, streets(ring), corners, sizes_, p_.maxDistortion).candidates();
    if (candidates.empty() && addVirtualCorner(ring, corners)) {
      candidates = Matcher(ring, streets(ring), corners, sizes_, p_.maxDistortion).candidates();
    }
    if (candidates.empty()) return false;
    // The paper picks at random among the best ranked: here among those within
    // kNearBest of the best score; then the others by score.
    std::size_t near = 1;
    while (near < candidates.size() && candidates[near].score <= candidates[0].score + kNearBest) ++near;
    const auto pick = static_cast<std::size_t>(rng_.uniform() * static_cast<double>(near));
    std::rotate(candidates.begin(), candidates.begin() + static_cast<long>(pick),
                candidates.begin() + static_cast<long>(pick) + 1);
    for (int tried = 0; tried < kMaxWarps && tried < static_cast<int>(candidates.size()); ++tried) {
      const Candidate& c = candidates[static_cast<std::size_t>(tried)];
      const Template t = instantiate(c, ring, sizes_, p_.iterations);
      const detail::Warp w = detail::warpTemplate(t, ring, c.matched, p_.iterations);
      double templateArea = 0;
      for (const TemplatePart& part : t.parts) {
        Ring r;
        for (int v : part.ring) r.push_back(t.vertices[v]);
        templateArea += std::fabs(signedArea(r));
      }
      const double size = std::sqrt(templateArea / static_cast<double>(std::max<std::size_t>(1, t.parts.size())));
      if (!(w.residual <= kMaxResidualShare * size)) continue;
      std::vector<Polygon> made = applySplits(region, t, w.positions, origin_);
      parcels.insert(parcels.end(), std::make_move_iterator(made.begin()), std::make_move_iterator(made.end()));
      if (parcels.size() > kMaxLots) throw detail::WorkBudgetExceeded("work budget: more than 200000 parcels");
      areaByTemplate[t.name] += area(region);
      return true;
    }
    return false;
  }

  // Per edge of `ring`: whether its middle lies on the block's outer ring
  // (within 5 % of its length: an edge of the coarse ring is the chord of a
  // side that may bend by up to 10 degrees).
  std::vector<char> streets(const Ring& ring) const {
    std::vector<char> on(ring.size(), 0);
    const std::size_t m = outline_.size();
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Point &a = ring[i], &b = ring[(i + 1) % ring.size()];
      const Point mid{0.5 * (a.x + b.x), 0.5 * (a.y + b.y)};
      for (std::size_t j = 0; j < m && !on[i]; ++j) {
        on[i] = pointSegmentDistance(mid, outline_[j], outline_[(j + 1) % m]) <=
                tolerance_ + kChordSag * norm(b.x - a.x, b.y - a.y);
      }
    }
    return on;
  }

  // A region of two or three corners gets virtual ones (the paper lets a
  // template's corner classification be overridden) up to four, each in the
  // middle of the longest arc, a vertex added to `ring` there: rows and grids
  // fit it.
  static bool addVirtualCorner(Ring& ring, std::vector<Corner>& corners) {
    if (corners.size() < 2 || corners.size() > 3) return false;
    while (corners.size() < 4) {
      const std::size_t n = ring.size(), c = corners.size();
      std::vector<double> cumulative{0};
      for (std::size_t i = 0; i < n; ++i) {
        const Point &a = ring[i], &b = ring[(i + 1) % n];
        cumulative.push_back(cumulative.back() + norm(b.x - a.x, b.y - a.y));
      }
      auto arc = [&](std::size_t k) {
        const double d = cumulative[corners[(k + 1) % c].index] - cumulative[corners[k].index];
        return d > 0 ? d : d + cumulative.back();
      };
      std::size_t longest = 0;
      for (std::size_t k = 1; k < c; ++k) {
        if (arc(k) > arc(longest)) longest = k;
      }
      double left = 0.5 * arc(longest);
      for (std::size_t i = corners[longest].index;; i = (i + 1) % n) {
        const Point &a = ring[i], &b = ring[(i + 1) % n];
        const double l = norm(b.x - a.x, b.y - a.y);
        if (left >= l) {
          left -= l;
          continue;
        }
        const double f = left / l;
        std::size_t at = i + 1;
        if (f > 1e-6 && f < 1 - 1e-6) {
          ring.insert(ring.begin() + static_cast<long>(at), Point{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y)});
          for (Corner& k : corners) k.index += k.index >= at;
        } else {
          at = f < 0.5 ? i : (i + 1) % n;
        }
        corners.push_back({at % ring.size(), 1, 0.0});
        std::sort(corners.begin(), corners.end(), [](const Corner& x, const Corner& y) { return x.index < y.index; });
        break;
      }
    }
    return true;
  }

  // Lines along the sides meeting at each concave corner, sharpest corner first.
  static std::vector<detail::SplitLine> concaveLines(const Ring& ring) {
    std::vector<Corner> concave;
    for (const Corner& c : detail::cornersOf(ring, kCornerTurn, ring.size(), kShortSide)) {
      if (c.type < 0) concave.push_back(c);
    }
    std::stable_sort(concave.begin(), concave.end(), [](const Corner& a, const Corner& b) { return a.turn > b.turn; });
    std::vector<detail::SplitLine> lines;
    const std::size_t n = ring.size();
    for (const Corner& c : concave) {
      const Point& at = ring[c.index];
      lines.push_back({at, detail::unitFrom(ring[(c.index + n - 1) % n], at)});
      lines.push_back({at, detail::unitFrom(at, ring[(c.index + 1) % n])});
    }
    return lines;
  }

  // Lines through each hole (largest first) along its sides (longest first):
  // they open the hole to the outer ring.
  static std::vector<detail::SplitLine> holeLines(const Polygon& region) {
    std::vector<std::pair<double, detail::SplitLine>> lines;
    for (const Ring& h : region.holes) {
      Polygon inside{h, {}};
      if (!normalise(inside)) continue;
      const Point through = interiorPoint(inside);
      const double holeArea = area(inside);
      for (const detail::Side& s : detail::sidesOf(inside.outer)) {
        lines.push_back({-holeArea - 1e-9 * s.length, {through, s.dir}});
      }
    }
    std::stable_sort(lines.begin(), lines.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<detail::SplitLine> out;
    for (const auto& l : lines) out.push_back(l.second);
    return out;
  }

  // The region cut along `line` (exactly): a line along a side passes next to
  // the side's other end, leaving a ring pinched there or a crumb: pinched
  // rings are taken apart, crumbs merged into a neighbouring piece. Nothing
  // unless two pieces of at least kMinShare of the region remain.
  std::vector<Polygon> cutAlong(const Polygon& region, double whole, const detail::SplitLine& line) const {
    detail::SplitPieces raw = detail::splitByLine(region, line.through, line.dir);
    std::vector<Polygon> pieces;
    double sum = 0;
    for (std::vector<Polygon>* side : {&raw.left, &raw.right}) {
      for (Polygon& q : *side) {
        std::vector<Polygon> parts;
        if ((q.holes.empty() && isClearlySimple(q.outer)) || geos::isValid(q)) {
          parts.push_back(std::move(q));
        } else {
          parts = geos::validParts(q);
        }
        for (Polygon& part : parts) {
          if (!validAt(part, origin_)) return {};  // nearly pinched: another line
          sum += area(part);
          pieces.push_back(std::move(part));
        }
      }
    }
    if (std::fabs(sum - whole) > 1e-9 * whole) return {};
    const auto large =
        std::count_if(pieces.begin(), pieces.end(), [&](const Polygon& m) { return area(m) >= kMinShare * whole; });
    if (large < 2) return {};
    for (std::size_t i = 0; i < pieces.size();) {
      if (area(pieces[i]) >= kMinShare * whole) {
        ++i;
      } else if (detail::mergeIntoNeighbour(pieces, i, {}, [&](const Polygon& u) { return validAt(u, origin_); }) < 0) {
        return {};
      }
    }
    return pieces;
  }

  // The first of `lines` that splits the region into pieces of at least
  // kMinShare of it, then each piece subdivided.
  void splitThenSubdivide(const Polygon& region, const std::vector<detail::SplitLine>& lines, int depth,
                          const char* failure) {
    if (depth >= kMaxDepth) {
      byObb(region, failure);
      return;
    }
    const double whole = area(region);
    // The first kMaxLines only: each is an exact cut of the whole region (a
    // block of 1,600 holes offered 6,400 lines, none usable, for five minutes).
    for (std::size_t k = 0; k < lines.size() && k < kMaxLines; ++k) {
      const detail::SplitLine& line = lines[k];
      std::vector<Polygon> pieces = cutAlong(region, whole, line);
      if (pieces.size() < 2) continue;
      for (const Polygon& piece : pieces) subdivide(piece, depth + 1);
      return;
    }
    byObb(region, failure);
  }

  // A region no template fits and no line splits: subdivided by obb (the
  // paper's rule-based assignment, section 3).
  void byObb(const Polygon& region, const char* failure) {
    Subdivision o = subdivideObb(region, bounds_, rng_.next());
    if (o.failed) throw detail::StyleFailure(failure);
    parcels.insert(parcels.end(), std::make_move_iterator(o.parcels.begin()), std::make_move_iterator(o.parcels.end()));
    obbArea += area(region);
    lastFailure = failure;
  }

  const Ring& outline_;  // the block's outer ring: its streets
  Point origin_;         // where the block was moved from (see validAt)
  double tolerance_ = 1e-6;
  const TemplateParameters& p_;
  ObbParameters bounds_;
  Sizes sizes_;
  detail::Rng rng_;
};

void subdivideWithTemplate(const Polygon& local, const Point& origin, const TemplateParameters& p,
                           const ObbParameters& bounds, const ObservedSample* observed, std::uint64_t seed,
                           Subdivision& out) {
  if (const double least = area(local) / p.aMax; least > kMaxLots) {
    out.failed = true;
    out.failure = "work budget: area / A_max = " + std::to_string(static_cast<long long>(std::min(least, 1e18))) +
                  " parcels, more than " + std::to_string(kMaxLots);
    return;
  }
  RegionSubdivider regions(local.outer, origin, p, bounds, sizesFrom(p, observed), seed);
  regions.subdivide(local, 0);
  if (regions.obbArea > kMaxObbShare * area(local)) throw detail::StyleFailure(regions.lastFailure);
  out.parcels = std::move(regions.parcels);
  // The template that made most of the block.
  double most = -1;
  for (const auto& [name, a] : regions.areaByTemplate) {
    if (a > most) {
      most = a;
      out.variant = name;
    }
  }
}

// Parcels without street access merged into a neighbour with it (the
// templates' parcels all front a street; a split line extended past its
// template segment can cut one off, and obb's parcels in a region front the
// region's sides, not all streets).
void mergeWithoutAccess(const Polygon& block, Subdivision& out, double minFrontage, const Point& origin) {
  const Polygon outline{block.outer, {}};
  const Box b = bounds(block);
  const analysis::PreparedBoundary edges(outline, std::max(1e-6, 1e-9 * (b.width() + b.height())));
  auto hasAccess = [&](const Polygon& q) { return edges.sharesAtLeast(q, minFrontage); };
  // Each merge looks at every parcel once; passes go on while any merges. With
  // thousands of parcels in a block (bounds of a few square metres) that grew
  // as the cube of their number (minutes on one block): bounded, the block
  // then falls back to obb.
  std::size_t looked = 0;
  auto merge = [&](std::size_t i, const std::function<bool(const Polygon&)>& eligible) {
    looked += out.parcels.size();
    if (looked > kMaxMergeWork) {
      throw detail::StyleFailure("work budget: merging the parcels without street access (" +
                                 std::to_string(out.parcels.size()) + " parcels)");
    }
    return detail::mergeIntoNeighbour(out.parcels, i, eligible, [&](const Polygon& u) { return validAt(u, origin); });
  };
  // Passes until none merges: a parcel merged may give the next its
  // neighbour. When none merges into a neighbour with access, parcels without
  // access merge together (a cluster of them in the middle of a region), and
  // the passes go on; every merge leaves one parcel fewer.
  for (bool merged = true, anyNeighbour = false; merged;) {
    merged = false;
    const std::function<bool(const Polygon&)> eligible =
        anyNeighbour ? std::function<bool(const Polygon&)>{} : std::function<bool(const Polygon&)>{hasAccess};
    for (std::size_t i = 0; i < out.parcels.size();) {
      if (hasAccess(out.parcels[i]) || merge(i, eligible) < 0) {
        ++i;
      } else {
        merged = true;
        if (anyNeighbour) break;  // one cluster merge, then neighbours with access again
      }
    }
    if (!merged && !anyNeighbour) {
      merged = anyNeighbour = true;
    } else if (anyNeighbour && merged) {
      anyNeighbour = false;
    }
  }
  for (const Polygon& q : out.parcels) out.withoutAccess += !hasAccess(q);
}

Subdivision subdivideTemplate(const StyleRun& r) {
  const TemplateParameters p = templateParametersFrom(r.values);
  const ObbParameters bounds = obbParametersFrom(r.values);
  // Where runNearOrigin moves the block (its parcels go back from there).
  const Point origin = detail::exactShiftOrigin(r.block);
  Subdivision s = detail::runNearOrigin(r.block, bounds, r.seed, [&](const Polygon& local, Subdivision& out) {
    subdivideWithTemplate(local, origin, p, bounds, r.observed, r.seed, out);
    if (!out.failed) mergeWithoutAccess(local, out, p.minFrontage, origin);
  });
  if (!s.fallback && !s.failed) {
    for (const Polygon& q : s.parcels) {
      const OrientedBox box = minimumAreaBox(q.outer);
      s.oversize += area(q) > p.aMax || box.width > p.wMax;
    }
  }
  return s;
}

class TemplateStyle : public Style {
public:
  std::string name() const override { return "template"; }
  std::string description() const override {
    return "pre-designed templates (row, grid, spike around a dead end) matched by corners and warped onto the "
           "block, their interior lines used as split lines (Yang et al. 2013)";
  }
  const std::vector<ParameterDescription>& parameters() const override { return templateParameterDescriptions(); }
  Subdivision run(const StyleRun& r) const override { return subdivideTemplate(r); }
};

}  // namespace

const Style& templateStyle() {
  static const TemplateStyle s;
  return s;
}

}  // namespace parcelscope::generation
