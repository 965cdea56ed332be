#pragma once
// `compare --style all`: every subdivision style on the same blocks of the same
// observed parcels, measured alike, ranked side by side (a leaderboard), with
// the style that fits each block's observed parcels best.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "parcelscope/core/Table.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/LayoutMeasures.h"

namespace parcelscope::pipeline {

/// The styles a leaderboard runs: every registered style (auto included), in
/// the registry's order.
std::vector<std::string> leaderboardStyles();

struct LeaderboardEntry {
  std::string style;
  CompareResult result;
  double seconds = 0;  ///< generate and compare, the observed data read once for all
};

struct Leaderboard {
  std::shared_ptr<const ObservedData> observed;
  std::vector<LeaderboardEntry> entries;  ///< one per style of leaderboardStyles()
  /// Per observed block: the fit of each entry (KS area + KS width + KS aspect
  /// ratio, each 1 where a side has no parcels), and the index of the entry of
  /// least fit (ties: the earlier style).
  std::vector<std::vector<double>> blockFit;  ///< [block][entry]
  std::vector<int> bestEntry;
};

/// The fit of one comparison: KS of area, width and aspect ratio summed (0 to
/// 3, lower is closer); a KS that cannot be measured (a side without parcels) counts 1.
double fitScore(const analysis::Comparison& c);

/// Reads and analyses `request`'s input once, then compares every style of
/// leaderboardStyles() on its blocks (request.style is ignored). Throws as compare().
Leaderboard leaderboard(const CompareRequest& request, const ProgressFn& progress = {});

/// leaderboard.csv: one row per style: style, parcels (generated), count_ratio
/// (generated / observed parcels), ks_*, w1_* and hi_* of area, width and
/// aspect_ratio, street_access_share, undesirable_share, fit (fitScore of the
/// city), blocks_best (blocks where it fits best), seconds.
Table leaderboardTable(const Leaderboard& board);
/// leaderboard_blocks.csv: one row per observed block: block_id, block_key,
/// observed_parcels, fit_<style> for each style, best_style.
Table leaderboardBlockTable(const Leaderboard& board);

/// layout.csv's rows: the observed layout, then each style's (Yang et al.
/// 2013's section 7 measures, LayoutMeasures.h).
std::vector<LayoutMeasures> layoutRows(const Leaderboard& board);

/// What draws the leaderboard's figure (viz supplies it): small multiples of
/// the aspect-ratio maps, observed first, then each style; `stage` turns a
/// name relative to the output folder into the path to write; returns the
/// names written. Null or figures = 0: none.
using LeaderboardRenderer =
    std::function<std::vector<std::string>(const Leaderboard& board, const CompareRequest& request,
                                           const std::function<std::string(const std::string&)>& stage)>;

/// Runs leaderboard() and writes into `outDir`, all at once when complete:
/// leaderboard.csv, leaderboard_blocks.csv, run.json and the figures `draw`
/// makes. Throws as compare(); the output directory is then left as it was.
JobOutcome runLeaderboard(const CompareRequest& request, const std::string& outDir, const ProgressFn& progress = {},
                          const LeaderboardRenderer& draw = {});

/// Writes a leaderboard already made (the application's) into `outDir` as
/// runLeaderboard does; run.json's total time is the styles' time.
JobOutcome saveLeaderboard(const Leaderboard& board, const CompareRequest& request, const std::string& outDir,
                           const LeaderboardRenderer& draw = {});

}  // namespace parcelscope::pipeline
