#pragma once
// The style `auto` picks per block: the style a block's nearest neighbours
// got from calibration, each voting with 1 / its distance, in block features
// standardised over the training blocks (docs/algorithms/auto.md). The training blocks are rows of
// a table: the bundled one (datasets/auto_rule.csv, made by
// datasets/make_auto_rule.sh from the calibrations of the shared datasets) or
// any a caller builds, for example from its own calibration.csv files.
#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation {

struct ObservedSample;

/// What the rule knows of a block before any style runs.
constexpr std::size_t kAutoFeatures = 7;
using AutoFeatures = std::array<double, kAutoFeatures>;

/// Feature names, in order (the table's columns and calibration.csv's).
const std::array<const char*, kAutoFeatures>& autoFeatureNames();

/// The features of a block part `shape` (local metres) whose block's observed
/// parcels are `observed`, of which a share `accessShare` has street access,
/// the part holding `observedShare` of the block's area: log10 area, width /
/// length of its minimum-area box, convexity (area over convex hull area),
/// street access share, log10 observed mean parcel area, log10 observed
/// parcels in the part, log10 observed median aspect ratio. Needs at least one
/// observed parcel.
AutoFeatures autoFeatures(const Polygon& shape, const ObservedSample& observed, double accessShare,
                          double observedShare = 1.0);

class AutoRule {
public:
  struct Row {
    AutoFeatures features{};
    std::string style;
  };

  AutoRule() = default;
  /// A rule over `rows`; `neighbours` votes per prediction; `weights` scale
  /// each standardised feature in the distance (0 leaves it out).
  explicit AutoRule(std::vector<Row> rows, std::size_t neighbours = kNeighbours,
                    const AutoFeatures& weights = kWeights);

  /// Reads a table: a header naming at least the feature columns and `style`
  /// (other columns, such as `city`, are kept apart), one row per block,
  /// comma-separated. `source` names it in errors. Rows whose `city` is in
  /// `leaveOut` are skipped (leave-one-city-out evaluation). Throws
  /// Error(Input) with the line and the problem.
  static AutoRule fromCsv(const std::string& text, const std::string& source,
                          const std::vector<std::string>& leaveOut = {}, std::size_t neighbours = kNeighbours,
                          const AutoFeatures& weights = kWeights);

  /// The rule trained on the shared datasets (datasets/auto_rule.csv).
  static const AutoRule& bundled();
  /// The bundled table's text.
  static const std::string& bundledTable();

  /// The style with the most votes of the nearest rows, each voting with 1 /
  /// its standardised distance (ties: the nearest's style). A block whose
  /// features are a row's takes that row's style. A block farther than kFar
  /// from every row takes kFarStyle: no calibrated block is like it, and
  /// sexton takes the block's own observed count, areas, street access and
  /// aspect ratios.
  const std::string& predict(const AutoFeatures& x) const;
  /// The `k` rows nearest `x`, nearest first: (squared standardised distance, row).
  std::vector<std::pair<double, std::size_t>> nearest(const AutoFeatures& x, std::size_t k) const;

  const std::vector<Row>& rows() const { return rows_; }
  static constexpr std::size_t kNeighbours = 3;
  static constexpr AutoFeatures kWeights = {1, 1, 1, 1, 1, 1, 1};
  /// Added to each distance before its vote is taken (standardised units).
  static constexpr double kVoteFloor = 1e-9;
  /// Standardised distance beyond which a block is unlike every row.
  static constexpr double kFar = 3.0;
  static constexpr const char* kFarStyle = "sexton";

private:
  std::vector<Row> rows_;
  AutoFeatures mean_{}, scale_{};  // scale_: standard deviation over weight
  std::size_t neighbours_ = kNeighbours;
};

}  // namespace parcelscope::generation
