#pragma once
// `parcelscope calibrate`: per block, the style whose parcels come closest to
// the block's observed parcels (issue "realism"), kept in a session file that
// `compare --session`, `generate` and the application read; and a
// cross-validated score, so that a choice that only memorises is seen: a rule
// fitted on half of the city's blocks (nearest neighbours in block features)
// measured on the other half, beside the paper's rule (style auto, k as given).
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "parcelscope/core/Table.h"
#include "parcelscope/generation/AutoRule.h"
#include "parcelscope/pipeline/Leaderboard.h"

namespace parcelscope::pipeline {

/// How close a set of generated parcels is to the observed ones, city-wide or
/// over some blocks: KS of area, width and aspect ratio over their parcels,
/// and the median over the blocks of |n_generated / n_observed - 1|.
struct FitMeasures {
  double ksArea = NAN, ksWidth = NAN, ksAspectRatio = NAN;
  double medianCountError = NAN;
  /// |generated / observed - 1| of the parcels of all the blocks with observed
  /// parcels together: a city of two thirds of its parcels does not measure
  /// like it, even where the pooled KS do.
  double totalCountError = NAN;
  std::int64_t blocks = 0;
};

/// One observed block's calibration.
struct BlockCalibration {
  std::int64_t blockId = -1;
  Key blockKey = 0;
  std::int64_t observedParcels = 0;
  std::string styleBefore;  ///< the paper's rule (the access style's choice)
  double distanceBefore = NAN;
  /// The calibrated style: from the style of least distance (or the paper's
  /// rule's, when that is better city-wide), changed where that lowers the
  /// city's calibrationObjective() (see calibrate()).
  std::string styleAfter;
  double distanceAfter = NAN;
  int half = 0;                ///< cross-validation half (0 or 1, from the block key)
  std::string stylePredicted;  ///< the fitted rule's style, fitted on the other half
  std::string styleHalf;       ///< the style its half calibrated alone gave it (the other half's labels)
  std::string styleAuto;       ///< the auto style's choice (the bundled rule)
  /// What the auto rule reads of the block (its largest part; see generation::autoFeatures).
  generation::AutoFeatures features{};
};

/// The measures over the observed blocks `blocks`, block b's parcels those
/// leaderboard entry `entryOf[b]` made.
FitMeasures fitMeasures(const Leaderboard& board, const std::vector<std::size_t>& blocks,
                        const std::vector<std::size_t>& entryOf);

struct Calibration {
  Leaderboard board;                     ///< every style on every block (the request's parameters)
  std::vector<BlockCalibration> blocks;  ///< per observed block
  CompareRequest session;                ///< the request with each block's style as an override
  FitMeasures before, after;             ///< every block: the paper's rule, the calibrated styles
  FitMeasures autoRule;                  ///< every block: the auto style (the bundled rule)
  /// Cross-validation: on each half, the rule fitted on the other half and the
  /// paper's rule; the two halves' measures, parcels pooled.
  FitMeasures crossFitted, crossPaper;
  std::map<std::string, std::int64_t> stylesChosen;  ///< blocks per calibrated style
  /// Per observed block, the leaderboard entry of its style: the paper's rule, calibrated.
  std::vector<std::size_t> entryBefore, entryAfter;
};

/// The generated parcels' metrics (unassigned land left out), each observed
/// block's from leaderboard entry `entryOf[block]`.
std::vector<analysis::ParcelMetrics> generatedMetrics(const Leaderboard& board,
                                                      const std::vector<std::size_t>& entryOf);

/// A block's distance to its observed parcels: KS area + KS width + KS aspect
/// ratio (a KS that cannot be measured counts 1) + |n_generated / n_observed - 1|.
double calibrationDistance(const analysis::Comparison& c);

/// KS area + KS width + KS aspect ratio + median count error + total count
/// error: what the calibration lowers city-wide.
double cityObjective(const FitMeasures& f);

/// Weight of a measure's excess over the paper's rule in calibrationObjective().
constexpr double kExcessWeight = 10;

/// What the calibration lowers: cityObjective(f), plus the largest of the
/// three KS and the median count error (so that no measure is left far behind
/// the others), plus kExcessWeight times each of those four measures' excess
/// over the paper's rule's `paper` on the same blocks, so that a calibration
/// that can be better than the paper's rule on every measure the issue bounds
/// is preferred to one better on the sum only. The total count error counts
/// once, in cityObjective().
double calibrationObjective(const FitMeasures& f, const FitMeasures& paper);

/// Runs every concrete style on `request`'s blocks (request.style is ignored)
/// and calibrates: from three starts (each block's style of least distance,
/// the paper's rule, each block's style of least count error), up to four
/// times over the blocks, a block's style is changed wherever that lowers
/// calibrationObjective(); the start that ends lowest wins. The searches (the
/// city's and the cross-validation halves') run in parallel. Throws as compare().
Calibration calibrate(const CompareRequest& request, const ProgressFn& progress = {});

/// The leaderboard entry of style `style`; throws std::logic_error when absent.
std::size_t entryOfStyle(const Calibration& c, const std::string& style);

/// Per observed block, the leaderboard entry of the style `rule` picks from
/// its features: how a rule trained elsewhere (another city) does here, with
/// fitMeasures().
std::vector<std::size_t> entriesOf(const Calibration& c, const generation::AutoRule& rule);

/// calibration.csv: one row per observed block.
Table calibrationTable(const Calibration& c);

/// What draws the calibration's figures (viz supplies it): `stage` turns a
/// name relative to the output folder into the path to write; returns the
/// names written.
using CalibrationRenderer =
    std::function<std::vector<std::string>(const Calibration& calibration, const CompareRequest& request,
                                           const std::function<std::string(const std::string&)>& stage)>;

/// calibrate() and its outputs in `outDir`, all at once: session.json,
/// calibration.csv, leaderboard.csv, run.json and the figures `draw` makes
/// (none when null or figures = 0).
JobOutcome runCalibrate(const CompareRequest& request, const std::string& outDir, const ProgressFn& progress = {},
                        const CalibrationRenderer& draw = {});

namespace detail {

/// The KS statistic (analysis::ksStatistic) between a fixed sample and a
/// pooled one with a few values swapped, without making the swapped sample:
/// what calibrate's search measures for each change of one block's style.
class SwappedKs {
public:
  SwappedKs() = default;
  /// Both sorted and finite.
  SwappedKs(const std::vector<double>& observed, const std::vector<double>& pooled);
  /// ksStatistic(observed, pooled without `out` and with `in`), the same
  /// number: `out` and `in` sorted and finite, `out` within the pooled
  /// sample. NaN when a side is empty.
  double operator()(const std::vector<double>& out, const std::vector<double>& in) const;

private:
  std::vector<double> value_;                            // the distinct values of both samples
  std::vector<std::int64_t> observedUpTo_, pooledUpTo_;  // each sample's count at or below each value
};

}  // namespace detail

}  // namespace parcelscope::pipeline
