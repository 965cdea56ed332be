#include "parcelscope/pipeline/Calibrate.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <numeric>
#include <sstream>

#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Keys.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/BlockSource.h"
#include "parcelscope/pipeline/CompareSession.h"
#include "parcelscope/pipeline/StreetsJob.h"

namespace parcelscope::pipeline {

namespace {
// |n_generated / n_observed - 1| of a block; 0 without observed parcels.
double countError(const analysis::Comparison& c) {
  return c.observed.parcels > 0
             ? std::fabs(static_cast<double>(c.generated.parcels) / static_cast<double>(c.observed.parcels) - 1)
             : 0.0;
}
}  // namespace

double calibrationDistance(const analysis::Comparison& c) {
  double d = 0;
  for (analysis::ComparedMetric m : analysis::kComparedMetrics) {
    const double ks = c.distances(m).ks;
    d += std::isfinite(ks) ? ks : 1.0;
  }
  return d + countError(c);
}

namespace {

// The generated parcels (unassigned land left out) of each leaderboard entry
// in each observed block: [entry][block].
std::vector<std::vector<std::vector<int>>> parcelsByBlock(const Leaderboard& board) {
  const analysis::ObservedAnalysis& a = board.observed->analysis;
  std::map<Key, std::size_t> blockOf;
  for (std::size_t b = 0; b < a.blocks.size(); ++b) blockOf.emplace(a.blocks[b].key, b);
  std::vector<std::vector<std::vector<int>>> out(board.entries.size(), std::vector<std::vector<int>>(a.blocks.size()));
  for (std::size_t e = 0; e < board.entries.size(); ++e) {
    const GeneratedParcels& g = board.entries[e].result.generated;
    for (std::size_t k = 0; k < g.blocks.size(); ++k) {
      const auto it = blockOf.find(g.blockKeys[k]);
      if (it == blockOf.end()) continue;  // a street block without observed parcels
      const std::vector<int> assigned = g.assignedOf(g.blocks[k].parcels);
      auto& to = out[e][it->second];
      to.insert(to.end(), assigned.begin(), assigned.end());
    }
  }
  return out;
}

// The measures of a choice of entries over some blocks, for the many
// evaluations of the refinement: each sample sorted once (the observed
// parcels of the blocks, each entry's parcels in each block), and the pooled
// generated samples of the current choice kept sorted, so that measuring a
// change of one block's style is a merge rather than a sort.
class ChoiceMeasure {
public:
  ChoiceMeasure(const Leaderboard& board, const std::vector<std::vector<std::vector<int>>>& parcels,
                const std::vector<std::size_t>& blocks, const std::vector<std::size_t>& candidates,
                std::vector<std::size_t> choice)
      : board_(board), parcels_(parcels), blocks_(blocks), choice_(std::move(choice)) {
    const analysis::ObservedAnalysis& a = board.observed->analysis;
    position_.assign(a.blocks.size(), kNone);
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const std::size_t b = blocks[k];
      position_[b] = k;
      for (int i : a.blocks[b].parcels) add(observed_, a.metrics[static_cast<std::size_t>(i)]);
      countError_.push_back(countError(choice_[b], b));
      observedTotal_ += a.blocks[b].parcels.size();
      generatedTotal_ += counted(choice_[b], b);
    }
    for (auto& v : observed_) sortFinite(v);
    std::vector<std::size_t> entries = candidates;
    for (std::size_t b : blocks) entries.push_back(choice_[b]);
    std::sort(entries.begin(), entries.end());
    entries.erase(std::unique(entries.begin(), entries.end()), entries.end());
    values_.resize(board.entries.size());
    for (std::size_t e : entries) {
      values_[e].resize(a.blocks.size());
      const GeneratedParcels& g = board.entries[e].result.generated;
      for (std::size_t b : blocks) {
        for (int i : parcels[e][b]) add(values_[e][b], g.metrics[static_cast<std::size_t>(i)]);
        for (auto& v : values_[e][b]) sortFinite(v);
      }
    }
    for (std::size_t b : blocks) {
      for (std::size_t m = 0; m < 3; ++m) {
        const auto& v = values_[choice_[b]][b][m];
        pooled_[m].insert(pooled_[m].end(), v.begin(), v.end());
      }
    }
    for (auto& v : pooled_) std::sort(v.begin(), v.end());
    for (std::size_t m = 0; m < 3; ++m) swappedKs_[m] = detail::SwappedKs(observed_[m], pooled_[m]);
  }

  /// The measures of the current choice with block `b` made by entry `e`
  /// (the KS as fit() measures them, without making the changed samples).
  FitMeasures with(std::size_t b, std::size_t e) const {
    std::vector<double> errors = countError_;
    errors[position_[b]] = countError(e, b);
    FitMeasures f = fit(nullptr, std::move(errors), totalWith(b, e));
    double* ks[3] = {&f.ksArea, &f.ksWidth, &f.ksAspectRatio};
    for (std::size_t m = 0; m < 3; ++m) {
      *ks[m] = swappedKs_[m](values_[choice_[b]][b][m], values_[e][b][m]);
    }
    return f;
  }
  FitMeasures current() const { return fit(&pooled_, countError_, generatedTotal_); }

  /// Makes block `b`'s entry `e`.
  void set(std::size_t b, std::size_t e) {
    for (std::size_t m = 0; m < 3; ++m) {
      pooled_[m] = swapped(pooled_[m], values_[choice_[b]][b][m], values_[e][b][m]);
      swappedKs_[m] = detail::SwappedKs(observed_[m], pooled_[m]);
    }
    countError_[position_[b]] = countError(e, b);
    generatedTotal_ = totalWith(b, e);
    choice_[b] = e;
  }

private:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  using Samples = std::array<std::vector<double>, 3>;  // area, width, aspect ratio

  static void add(Samples& to, const analysis::ParcelMetrics& m) {
    to[0].push_back(m.area);
    to[1].push_back(m.width);
    to[2].push_back(m.aspectRatio);
  }
  static void sortFinite(std::vector<double>& v) {
    v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
    std::sort(v.begin(), v.end());
  }
  // `pooled` (sorted) without the values `out` and with the values `in` (both sorted, `out` within `pooled`).
  static std::vector<double> swapped(const std::vector<double>& pooled, const std::vector<double>& out,
                                     const std::vector<double>& in) {
    std::vector<double> r;
    r.reserve(pooled.size() - out.size() + in.size());
    std::size_t o = 0, n = 0;
    for (double x : pooled) {
      if (o < out.size() && out[o] == x) {
        ++o;
        continue;
      }
      while (n < in.size() && in[n] < x) r.push_back(in[n++]);
      r.push_back(x);
    }
    r.insert(r.end(), in.begin() + static_cast<long>(n), in.end());
    return r;
  }
  // NaN for a block without observed parcels (left out of the median, as in measure()).
  double countError(std::size_t e, std::size_t b) const {
    const std::size_t observed = board_.observed->analysis.blocks[b].parcels.size();
    if (observed == 0) return NAN;
    return std::fabs(static_cast<double>(parcels_[e][b].size()) / static_cast<double>(observed) - 1);
  }
  // Entry e's parcels in block b, where the block has observed parcels (else none: out of the totals).
  std::size_t counted(std::size_t e, std::size_t b) const {
    return board_.observed->analysis.blocks[b].parcels.empty() ? 0 : parcels_[e][b].size();
  }
  // The generated total with block b's parcels made by entry e.
  std::size_t totalWith(std::size_t b, std::size_t e) const {
    return generatedTotal_ - counted(choice_[b], b) + counted(e, b);
  }
  // The measures of `pooled` (null: the KS left NaN, for the caller), the
  // per-block count errors and the generated parcels of the blocks with observed ones.
  FitMeasures fit(const Samples* pooled, std::vector<double> errors, std::size_t generated) const {
    FitMeasures f;
    if (observedTotal_ > 0) {
      f.totalCountError = std::fabs(static_cast<double>(generated) / static_cast<double>(observedTotal_) - 1);
    }
    f.blocks = static_cast<std::int64_t>(blocks_.size());
    if (pooled) {
      f.ksArea = analysis::ksStatistic(observed_[0], (*pooled)[0]);
      f.ksWidth = analysis::ksStatistic(observed_[1], (*pooled)[1]);
      f.ksAspectRatio = analysis::ksStatistic(observed_[2], (*pooled)[2]);
    }
    errors.erase(std::remove_if(errors.begin(), errors.end(), [](double x) { return std::isnan(x); }), errors.end());
    if (!errors.empty()) {
      std::nth_element(errors.begin(), errors.begin() + static_cast<long>(errors.size() / 2), errors.end());
      f.medianCountError = errors[errors.size() / 2];
    }
    return f;
  }

  const Leaderboard& board_;
  const std::vector<std::vector<std::vector<int>>>& parcels_;
  std::vector<std::size_t> blocks_;
  std::vector<std::size_t> choice_;
  std::vector<std::size_t> position_;         // of each board block in blocks_ (kNone: not measured)
  std::vector<std::vector<Samples>> values_;  // [entry][block], sorted, finite
  Samples observed_, pooled_;
  std::array<detail::SwappedKs, 3> swappedKs_;          // of each measure's observed and pooled samples
  std::vector<double> countError_;                      // per position in blocks_
  std::size_t observedTotal_ = 0, generatedTotal_ = 0;  // parcels of the blocks with observed parcels
};

// The measures over the blocks `blocks`, block b's parcels made by entry `entryOf[b]`.
FitMeasures measure(const Leaderboard& board, const std::vector<std::vector<std::vector<int>>>& parcels,
                    const std::vector<std::size_t>& blocks, const std::vector<std::size_t>& entryOf) {
  return ChoiceMeasure(board, parcels, blocks, {}, entryOf).current();
}

// What the auto rule knows of observed block b: its largest part's shape and
// its observed parcels.
generation::AutoFeatures featuresOf(const ObservedData& d, std::size_t b) {
  const Block& block = d.analysis.blocks[b];
  const Polygon* largest = &block.parts.front();
  double total = 0;
  for (const Polygon& p : block.parts) {
    total += area(p);
    if (area(p) > area(*largest)) largest = &p;
  }
  return generation::autoFeatures(*largest, *observedSample(d.analysis, b), d.analysis.statistics[b].streetAccessShare,
                                  total > 0 ? area(*largest) / total : 1.0);
}

// Passes of the city-wide refinement (each visits every block once).
constexpr int kRefinePasses = 4;

// The calibration of the blocks `blocks` from the choice `choice` (other
// blocks' entries are left): passes over the blocks changing a block's style
// wherever that lowers calibrationObjective() over those blocks, against the
// measures there of the paper's rule, the leaderboard entries `paperEntries`
// (style access). calibrate() runs it from three starts (the per-block
// optimum, the styles the paper's rule picks, each block's least count error)
// and keeps the lowest: the per-block optimum need not add up to a city-wide
// one (a block's KS is measured on a few parcels), and one block's change
// barely moves the median count error, so that stays low only from a start
// where most blocks have their count. Returns early, empty, when `stop()`
// says so.
struct Refined {
  std::vector<std::size_t> choice;
  double objective = HUGE_VAL;
};

Refined refineChoice(const Leaderboard& board, const std::vector<std::vector<std::vector<int>>>& parcels,
                     const std::vector<std::size_t>& blocks, const std::vector<std::size_t>& candidates,
                     const std::vector<std::size_t>& paperEntries, std::vector<std::size_t> choice,
                     const std::function<bool()>& stop) {
  const FitMeasures paper = measure(board, parcels, blocks, paperEntries);
  auto objective = [&](const FitMeasures& f) { return calibrationObjective(f, paper); };
  ChoiceMeasure measured(board, parcels, blocks, candidates, choice);
  double current = objective(measured.current());
  for (int pass = 0; pass < kRefinePasses; ++pass) {
    bool changed = false;
    for (std::size_t b : blocks) {
      if (stop()) return {};
      const std::size_t kept = choice[b];
      std::size_t chosen = kept;
      for (std::size_t e : candidates) {
        if (e == kept) continue;
        const double o = objective(measured.with(b, e));
        if (o < current - 1e-12) {
          current = o;
          chosen = e;
        }
      }
      if (chosen != kept) {
        measured.set(b, chosen);
        choice[b] = chosen;
        changed = true;
      }
    }
    if (!changed) break;
  }
  return {std::move(choice), current};
}

}  // namespace

namespace detail {

// The two empirical distributions change only at the grid's values (the
// distinct values of both samples) and at the values of `in`; between the
// values of `out` and `in`, the swapped sample's count at a grid value is the
// pooled count plus a constant, so the walk goes over the grid in runs. The
// largest difference is found on exact integers, |A nb - J na| (A, J: the
// observed and the swapped sample's counts at or below a value), and reported
// as ksStatistic computes it, |A / na - J / nb|: distinct integers differ by
// at least 1 / (na nb) in the quotient, far above its rounding, and of equal
// ones the larger quotient is kept.
SwappedKs::SwappedKs(const std::vector<double>& observed, const std::vector<double>& pooled) {
  const std::vector<double>& a = observed;
  std::size_t i = 0, p = 0;
  while (i < a.size() || p < pooled.size()) {
    const double x = i == a.size() ? pooled[p] : p == pooled.size() ? a[i] : std::min(a[i], pooled[p]);
    while (i < a.size() && a[i] <= x) ++i;
    while (p < pooled.size() && pooled[p] <= x) ++p;
    value_.push_back(x);
    observedUpTo_.push_back(static_cast<std::int64_t>(i));
    pooledUpTo_.push_back(static_cast<std::int64_t>(p));
  }
}

double SwappedKs::operator()(const std::vector<double>& out, const std::vector<double>& in) const {
  const std::int64_t ina = observedUpTo_.empty() ? 0 : observedUpTo_.back();
  const std::int64_t inb = (pooledUpTo_.empty() ? 0 : pooledUpTo_.back()) - static_cast<std::int64_t>(out.size()) +
                           static_cast<std::int64_t>(in.size());
  if (ina == 0 || inb <= 0) return NAN;
  const double na = static_cast<double>(ina), nb = static_cast<double>(inb);
  std::int64_t most = -1;
  double ks = 0;
  auto consider = [&](std::int64_t a, std::int64_t j) {
    const std::int64_t d = std::llabs(a * inb - j * ina);
    if (d < most) return;
    const double q = std::fabs(static_cast<double>(a) / na - static_cast<double>(j) / nb);
    ks = d > most ? q : std::max(ks, q);
    most = d;
  };
  std::size_t k = 0, o = 0, n = 0;
  auto run = [&](std::size_t end) {
    const auto shift = static_cast<std::int64_t>(n) - static_cast<std::int64_t>(o);
    for (; k < end; ++k) consider(observedUpTo_[k], pooledUpTo_[k] + shift);
  };
  while (o < out.size() || n < in.size()) {
    const double x = o == out.size() ? in[n] : n == in.size() ? out[o] : std::min(out[o], in[n]);
    run(static_cast<std::size_t>(std::lower_bound(value_.begin() + static_cast<long>(k), value_.end(), x) -
                                 value_.begin()));
    while (o < out.size() && out[o] <= x) ++o;
    while (n < in.size() && in[n] <= x) ++n;
    if (k == value_.size() || value_[k] != x) {
      // A value of `in` alone: both samples' counts below it, and the swapped sample's at it.
      const std::int64_t a = k ? observedUpTo_[k - 1] : 0, p = k ? pooledUpTo_[k - 1] : 0;
      consider(a, p - static_cast<std::int64_t>(o) + static_cast<std::int64_t>(n));
    }
  }
  run(value_.size());
  return ks;
}

}  // namespace detail

std::vector<analysis::ParcelMetrics> generatedMetrics(const Leaderboard& board,
                                                      const std::vector<std::size_t>& entryOf) {
  const auto parcels = parcelsByBlock(board);
  std::vector<analysis::ParcelMetrics> out;
  for (std::size_t b = 0; b < entryOf.size(); ++b) {
    const GeneratedParcels& g = board.entries[entryOf[b]].result.generated;
    for (int i : parcels[entryOf[b]][b]) out.push_back(g.metrics[static_cast<std::size_t>(i)]);
  }
  return out;
}

double cityObjective(const FitMeasures& f) {
  return f.ksArea + f.ksWidth + f.ksAspectRatio + (std::isfinite(f.medianCountError) ? f.medianCountError : 0) +
         (std::isfinite(f.totalCountError) ? f.totalCountError : 0);
}

double calibrationObjective(const FitMeasures& f, const FitMeasures& paper) {
  auto excess = [](double m, double bound) {
    return std::isfinite(m) && std::isfinite(bound) ? std::max(0.0, m - bound) : 0.0;
  };
  const double worst =
      std::max({f.ksArea, f.ksWidth, f.ksAspectRatio, std::isfinite(f.medianCountError) ? f.medianCountError : 0.0});
  return cityObjective(f) + (std::isfinite(worst) ? worst : 0.0) +
         kExcessWeight *
             (excess(f.ksArea, paper.ksArea) + excess(f.ksWidth, paper.ksWidth) +
              excess(f.ksAspectRatio, paper.ksAspectRatio) + excess(f.medianCountError, paper.medianCountError));
}

FitMeasures fitMeasures(const Leaderboard& board, const std::vector<std::size_t>& blocks,
                        const std::vector<std::size_t>& entryOf) {
  return measure(board, parcelsByBlock(board), blocks, entryOf);
}

std::size_t entryOfStyle(const Calibration& c, const std::string& style) {
  for (std::size_t e = 0; e < c.board.entries.size(); ++e) {
    if (c.board.entries[e].style == style) return e;
  }
  throw std::logic_error("calibrate: no leaderboard entry of style " + style);
}

std::vector<std::size_t> entriesOf(const Calibration& c, const generation::AutoRule& rule) {
  std::vector<std::size_t> out;
  for (const BlockCalibration& b : c.blocks) out.push_back(entryOfStyle(c, rule.predict(b.features)));
  return out;
}

Calibration calibrate(const CompareRequest& request, const ProgressFn& progress) {
  Calibration c;
  c.board = leaderboard(request, scaledProgress(progress, 0.0, 0.95));
  reportProgress(progress, 0.95, "calibrating");
  const Leaderboard& board = c.board;
  const analysis::ObservedAnalysis& a = board.observed->analysis;
  std::size_t paper = board.entries.size();
  std::vector<std::size_t> candidates;
  for (std::size_t e = 0; e < board.entries.size(); ++e) {
    if (board.entries[e].style == generation::accessStyle().name()) paper = e;
    if (!generation::choosesPerBlock(generation::style(board.entries[e].style))) candidates.push_back(e);
  }
  if (paper == board.entries.size() || candidates.empty()) throw std::logic_error("calibrate: the styles are missing");

  const std::size_t n = a.blocks.size();
  std::map<Key, std::string> paperStyle;  // the style auto chose per block
  {
    const GeneratedParcels& g = board.entries[paper].result.generated;
    for (std::size_t k = 0; k < g.blocks.size(); ++k) paperStyle.emplace(g.blockKeys[k], g.blockStyles[k]);
  }
  std::vector<std::size_t> best(n), before(n, paper), all(n);
  std::iota(all.begin(), all.end(), 0);
  c.blocks.resize(n);
  for (std::size_t b = 0; b < n; ++b) {
    BlockCalibration& bc = c.blocks[b];
    bc.blockId = a.blocks[b].id;
    bc.blockKey = a.blocks[b].key;
    bc.observedParcels = static_cast<std::int64_t>(a.blocks[b].parcels.size());
    bc.half = static_cast<int>(bc.blockKey % 2);
    auto distance = [&](std::size_t e) { return calibrationDistance(board.entries[e].result.blocks[b].comparison); };
    const auto chosen = paperStyle.find(bc.blockKey);
    bc.styleBefore = chosen != paperStyle.end() ? chosen->second : board.entries[paper].style;
    bc.distanceBefore = distance(paper);
    best[b] = candidates.front();
    for (std::size_t e : candidates) {
      if (distance(e) < distance(best[b])) best[b] = e;  // ties: the earlier style
    }
    bc.styleAfter = board.entries[best[b]].style;
    bc.distanceAfter = distance(best[b]);
    ++c.stylesChosen[bc.styleAfter];
  }
  const auto parcels = parcelsByBlock(board);
  c.before = measure(board, parcels, all, before);
  const std::vector<std::size_t> perBlock = best;
  // The styles access picks, as candidates (their skeleton may slice otherwise).
  std::vector<std::size_t> paperChoice(n);
  for (std::size_t b = 0; b < n; ++b) {
    paperChoice[b] = best[b];
    for (std::size_t e : candidates) {
      if (board.entries[e].style == c.blocks[b].styleBefore) paperChoice[b] = e;
    }
  }
  // The third start: each block's style of least count error (then of least distance).
  std::vector<std::size_t> countFirst(n);
  for (std::size_t b = 0; b < n; ++b) {
    auto result = [&](std::size_t e) -> const analysis::Comparison& {
      return board.entries[e].result.blocks[b].comparison;
    };
    auto error = [&](std::size_t e) { return countError(result(e)); };
    countFirst[b] = perBlock[b];
    for (std::size_t e : candidates) {
      const double de = error(e), dk = error(countFirst[b]);
      if (de < dk || (de == dk && calibrationDistance(result(e)) < calibrationDistance(result(countFirst[b])))) {
        countFirst[b] = e;
      }
    }
  }
  // Every refinement at once, in parallel: the whole city and each half's
  // training blocks (the other half), each from the three starts.
  std::vector<std::vector<std::size_t>> blockSets = {all, {}, {}};
  for (std::size_t b = 0; b < n; ++b) blockSets[1 + (c.blocks[b].half == 0 ? 1 : 0)].push_back(b);
  const std::vector<std::vector<std::size_t>> starts = {perBlock, paperChoice, countFirst};
  std::vector<Refined> refined(blockSets.size() * starts.size());
  std::atomic<bool> stop{false};
  // Several threads: the calling thread reports progress (the tick below) and
  // sets `stop` when asked to; one thread: the searches report it themselves.
  const bool oneThread = workerCount() == 1;
  const std::function<bool()> poll = [&] {
    if (oneThread) reportProgress(progress, 0.95, "calibrating");
    return stop.load();
  };
  parallelFor(
      refined.size(),
      [&](std::size_t t) {
        const auto& blocks = blockSets[t / starts.size()];
        if (!blocks.empty()) {
          refined[t] = refineChoice(board, parcels, blocks, candidates, before, starts[t % starts.size()], poll);
        }
      },
      [&](std::size_t) {
        try {
          reportProgress(progress, 0.95, "calibrating");
        } catch (...) {
          stop = true;
          throw;
        }
      });
  // Per block set, the start that ended lowest (ties: the earlier start).
  auto refine = [&](std::size_t set) {
    std::size_t winner = set * starts.size();
    for (std::size_t t = winner; t < (set + 1) * starts.size(); ++t) {
      if (refined[t].objective < refined[winner].objective - 1e-12) winner = t;
    }
    return refined[winner].choice;
  };
  best = refine(0);
  for (std::size_t b = 0; b < n; ++b) {
    BlockCalibration& bc = c.blocks[b];
    --c.stylesChosen[bc.styleAfter];
    bc.styleAfter = board.entries[best[b]].style;
    bc.distanceAfter = calibrationDistance(board.entries[best[b]].result.blocks[b].comparison);
    ++c.stylesChosen[bc.styleAfter];
  }
  for (auto it = c.stylesChosen.begin(); it != c.stylesChosen.end();) {
    it = it->second == 0 ? c.stylesChosen.erase(it) : std::next(it);
  }
  c.after = measure(board, parcels, all, best);
  c.entryBefore = before;
  c.entryAfter = best;

  // Cross-validation: each half's styles predicted from the other half's calibrated styles.
  for (std::size_t b = 0; b < n; ++b) c.blocks[b].features = featuresOf(*board.observed, b);
  std::vector<std::size_t> predicted(n, candidates.front());
  for (int half = 0; half < 2; ++half) {
    // The other half's styles calibrated on that half alone: nothing of this
    // half's parcels goes into its labels.
    const std::vector<std::size_t>& trainBlocks = blockSets[1 + static_cast<std::size_t>(half)];
    if (trainBlocks.empty()) continue;
    const std::vector<std::size_t> trained = refine(1 + static_cast<std::size_t>(half));
    std::vector<generation::AutoRule::Row> rows;
    for (std::size_t b : trainBlocks) {
      c.blocks[b].styleHalf = board.entries[trained[b]].style;
      rows.push_back({c.blocks[b].features, c.blocks[b].styleHalf});
    }
    const generation::AutoRule rule(std::move(rows));
    for (std::size_t b = 0; b < n; ++b) {
      if (c.blocks[b].half == half) predicted[b] = entryOfStyle(c, rule.predict(c.blocks[b].features));
    }
  }
  for (std::size_t b = 0; b < n; ++b) c.blocks[b].stylePredicted = board.entries[predicted[b]].style;
  c.crossFitted = measure(board, parcels, all, predicted);
  c.crossPaper = c.before;
  std::size_t autoEntry = paper;
  for (std::size_t e = 0; e < board.entries.size(); ++e) {
    if (board.entries[e].style == generation::autoStyle().name()) autoEntry = e;
  }
  c.autoRule = measure(board, parcels, all, std::vector<std::size_t>(n, autoEntry));
  {
    const GeneratedParcels& g = board.entries[autoEntry].result.generated;
    std::map<Key, std::string> chosen;
    for (std::size_t k = 0; k < g.blocks.size(); ++k) chosen.emplace(g.blockKeys[k], g.blockStyles[k]);
    for (BlockCalibration& bc : c.blocks) {
      if (const auto it = chosen.find(bc.blockKey); it != chosen.end()) bc.styleAuto = it->second;
    }
  }

  c.session = request;
  if (c.session.style == "all") c.session.style = generation::autoStyle().name();
  // A session file takes relative paths from its own folder: these are absolute.
  c.session.input.path = std::filesystem::absolute(request.input.path).lexically_normal().string();
  if (c.session.streets) {
    c.session.streets->path = std::filesystem::absolute(request.streets->path).lexically_normal().string();
  }
  c.session.overridesById.clear();
  for (const BlockCalibration& bc : c.blocks) c.session.overrides[bc.blockKey].style = bc.styleAfter;
  return c;
}

Table calibrationTable(const Calibration& c) {
  Table t;
  using T = Column::Type;
  t.columns = {{"block_id", T::Integer, ""},   {"block_key", T::String, ""},    {"observed_parcels", T::Integer, ""},
               {"half", T::Integer, ""},       {"style_before", T::String, ""}, {"distance_before", T::Real, ""},
               {"style_after", T::String, ""}, {"distance_after", T::Real, ""}, {"style_predicted", T::String, ""},
               {"style_half", T::String, ""},  {"style_auto", T::String, ""}};
  for (const char* name : generation::autoFeatureNames()) t.columns.push_back({name, T::Real, ""});
  for (const BlockCalibration& b : c.blocks) {
    if (b.observedParcels == 0) continue;  // a street block without observed parcels: nothing calibrated
    t.rows.push_back({b.blockId, keyText(b.blockKey), b.observedParcels, std::int64_t(b.half), b.styleBefore,
                      b.distanceBefore, b.styleAfter, b.distanceAfter, b.stylePredicted, b.styleHalf, b.styleAuto});
    for (double f : b.features) t.rows.back().push_back(f);
  }
  return t;
}

namespace {

Json fitJson(const FitMeasures& f) {
  return Json::object()
      .set("blocks", f.blocks)
      .set("ks_area", f.ksArea)
      .set("ks_width", f.ksWidth)
      .set("ks_aspect_ratio", f.ksAspectRatio)
      .set("median_count_error", f.medianCountError)
      .set("total_count_error", f.totalCountError);
}

std::string fitText(const FitMeasures& f) {
  std::ostringstream s;
  s.precision(3);
  s << "KS area " << f.ksArea << ", width " << f.ksWidth << ", aspect ratio " << f.ksAspectRatio
    << ", median |n/n_obs - 1| " << f.medianCountError << ", total |N/N_obs - 1| " << f.totalCountError;
  return s.str();
}

}  // namespace

JobOutcome runCalibrate(const CompareRequest& request, const std::string& outDir, const ProgressFn& progress,
                        const CalibrationRenderer& draw) {
  io::OutputDirectory out(outDir, inputPaths(request));
  try {
    const Calibration c = calibrate(request, scaledProgress(progress, 0.0, 0.95));
    reportProgress(progress, 0.95, "writing");
    io::writeJson(out.stage("session.json"), sessionJson(c.session));
    io::writeCsv(out.stage("calibration.csv"), calibrationTable(c));
    io::writeCsv(out.stage("leaderboard.csv"), leaderboardTable(c.board));
    Json outputs = Json::array().push("session.json").push("calibration.csv").push("leaderboard.csv");
    if (draw && compareValue(request, "figures") != 0) {
      for (const std::string& name : draw(c, request, [&](const std::string& n) { return out.stage(n); })) {
        outputs.push(name);
      }
    }
    Json run = runRecord("calibrate", request.parameters);
    addObservedRecord(run, *c.board.observed);
    if (c.board.observed->streets) run.set("streets", streetRecord(*c.board.observed->streets));
    Json chosen = Json::object();
    for (const auto& [style, blocks] : c.stylesChosen) chosen.set(style, blocks);
    run.set(
        "calibration",
        Json::object()
            .set("distance", "per block: KS area + KS width + KS aspect ratio + |n_generated / n_observed - 1|")
            .set("before", fitJson(c.before).set("rule", "style access with the run's k (the paper's rule)"))
            .set("auto", fitJson(c.autoRule).set("rule", "style auto (the bundled rule) with the run's k"))
            .set("after",
                 fitJson(c.after).set(
                     "rule", "the calibrated styles: the city-wide objective lowered block by block from three starts"))
            .set("styles_chosen", chosen)
            .set("cross_validation",
                 Json::object()
                     .set("halves", "blocks split by block key parity")
                     .set("fitted_rule",
                          "the style the 3 nearest blocks of the other half got from that half's own "
                          "calibration, each voting with 1 / its distance in the auto rule's standardised "
                          "features (calibration.csv's f_ columns)")
                     .set("fitted", fitJson(c.crossFitted))
                     .set("paper", fitJson(c.crossPaper))));
    run.set("outputs", outputs.push("run.json"));
    io::writeJson(out.stage("run.json"), run);
    out.commit();
    reportProgress(progress, 1.0, "writing");
    std::ostringstream s;
    s << "calibrated " << c.blocks.size() << " blocks of " << c.board.observed->layer.path
      << "\n  before (access, the paper's rule): " << fitText(c.before) << "\n  auto: " << fitText(c.autoRule)
      << "\n  after: " << fitText(c.after)
      << "\n  cross-validated (fitted on one half, measured on the other): " << fitText(c.crossFitted)
      << "\n  styles chosen:";
    for (const auto& [style, blocks] : c.stylesChosen) s << " " << style << " " << blocks;
    return {run, s.str()};
  } catch (const Error& e) {
    throw out.explain(e);
  }
}

}  // namespace parcelscope::pipeline
