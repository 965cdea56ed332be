#pragma once
// Observed versus procedural parcels, number by number: distances between the
// two empirical distributions of a metric, and per-set summaries (Vanegas et
// al. 2012, section 6; parcel quality after Yang et al. 2013, section 6).
//
// Every function takes samples as they come (unsorted, any size). Non-finite
// values (the infinite aspect ratio of a zero-width sliver) are left out of the
// distances; an empty sample gives NaN, never a made-up 0.
#include <cstdint>
#include <iterator>
#include <string>
#include <vector>

#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/Table.h"

namespace parcelscope::analysis {

/// Two-sample Kolmogorov-Smirnov statistic D = sup_x |F_a(x) - F_b(x)|, with F
/// the empirical distribution functions (ties handled exactly). Dimensionless,
/// [0, 1]: 0 for identical samples, 1 when every value of one lies below every
/// value of the other. NaN when either sample is empty.
double ksStatistic(const std::vector<double>& a, const std::vector<double>& b);

/// Wasserstein-1 (earth mover's) distance between the empirical distributions,
/// W1 = integral over x of |F_a(x) - F_b(x)|: the mean distance values must move
/// to turn one distribution into the other. Same unit as the values, >= 0; 0 for
/// identical samples, |a - b| for two single values. NaN when either is empty.
double wasserstein1(const std::vector<double>& a, const std::vector<double>& b);

/// Histogram of two samples on the same bins.
struct SharedHistogram {
  std::vector<double> edges;         ///< bins + 1 increasing edges; bin i is [edges[i], edges[i+1])
  std::vector<int> a, b;             ///< counts per bin (not normalised)
  int aOverflow = 0, bOverflow = 0;  ///< values above the last edge, counted in the last bin too
};

/// `bins` equal-width bins from the smallest value of both samples to their
/// pooled `upperQuantile` quantile (1 = the largest value); larger values are
/// counted in the last bin, so long tails do not squeeze the rest into one bin.
/// When every value is equal, one unit-width bin holds them all. Throws
/// Error(Usage) unless bins >= 1 and 0 < upperQuantile <= 1. Empty samples give
/// empty edges.
SharedHistogram sharedHistogram(const std::vector<double>& a, const std::vector<double>& b, int bins,
                                double upperQuantile = 1.0);

/// Histogram intersection (Swain and Ballard 1991) of the relative frequencies
/// on shared bins, sum_i min(a_i / n_a, b_i / n_b). Dimensionless, [0, 1]: 1 for
/// identical histograms, 0 when no bin holds values of both. NaN when either
/// sample is empty.
double histogramIntersection(const SharedHistogram& histogram);

/// Yang et al. 2013 (Figure 12): a parcel is undesirable when p_angle > 15
/// degrees or p_area > 1.2.
bool isUndesirable(const ShapeMetrics& m);

/// What one set of parcels looks like, in the terms of the paper's per-block
/// table plus the quality measures.
struct SetSummary {
  std::int64_t parcels = 0;
  double meanArea = 0, sdArea = 0;    ///< A-bar and s_A, m² (sample SD, 0 for one parcel)
  double meanWidth = 0, sdWidth = 0;  ///< W-bar and s_W, m
  double meanAspectRatio = 0;         ///< mean of the finite aspect ratios
  double streetAccessShare = 0;       ///< fraction with street access, [0, 1]
  double meanPAngle = 0;              ///< degrees
  double meanPArea = 0;
  double undesirableShare = 0;  ///< fraction with p_angle > 15 or p_area > 1.2, [0, 1]
};
/// NaN in every mean and share when `metrics` is empty.
SetSummary summarizeSet(const std::vector<ParcelMetrics>& metrics);

/// The distances between two samples of one metric.
struct Distances {
  double ks = 0;            ///< ksStatistic
  double wasserstein = 0;   ///< wasserstein1, in the metric's unit
  double intersection = 0;  ///< histogramIntersection on shared bins
};

/// The compared metrics, in this order: area, width, aspect ratio.
enum class ComparedMetric { Area, Width, AspectRatio };
constexpr ComparedMetric kComparedMetrics[] = {ComparedMetric::Area, ComparedMetric::Width,
                                               ComparedMetric::AspectRatio};
/// "area", "width", "aspect_ratio" (column and JSON names).
const char* metricName(ComparedMetric m);
/// "m2", "m", "" (unit of the metric and of its Wasserstein distance).
const char* metricUnit(ComparedMetric m);
/// The finite values of metric `m` over `metrics`.
std::vector<double> metricSample(const std::vector<ParcelMetrics>& metrics, ComparedMetric m);

/// One per-parcel metric, described once: its column in every parcel table,
/// its colour scale and histogram (the GUI's "colour by", compare's --metric),
/// and its row in docs/user/metrics.md (`parcelscope metrics` prints that table).
struct ParcelQuantity {
  std::string name;   ///< column and JSON name, e.g. "aspect_ratio"
  std::string title;  ///< for people, with the unit, e.g. "area (m²)"
  double (*value)(const ParcelMetrics&);
  /// Measured from the parcel's surroundings (neighbours, block outline) rather
  /// than its own shape: see measureContext.
  bool context = false;
  std::string unit;      ///< "m", "m2", "deg" or "" (dimensionless)
  bool integer = false;  ///< a count or a flag, written as an integer
  std::string formula;   ///< how it is computed
  std::string range;     ///< values it takes, e.g. "[1, inf)"
  std::string source;    ///< the paper or tool it follows
};
/// Every parcel metric in the order of the parcel tables' columns: area,
/// perimeter, width, length, aspect_ratio, elongation, rectangularity,
/// p_angle, p_area, neighbours, frontage, street_access.
const std::vector<ParcelQuantity>& parcelMetrics();
/// The same metrics in the order offered to people: aspect_ratio (the paper's
/// colour map) first, then as parcelMetrics().
const std::vector<ParcelQuantity>& parcelQuantities();
/// The quantity called `name`; throws Error(Usage) listing the names otherwise.
const ParcelQuantity& parcelQuantity(const std::string& name);
/// The finite values of `q` over `metrics`.
std::vector<double> quantitySample(const std::vector<ParcelMetrics>& metrics, const ParcelQuantity& q);

struct Comparison {
  SetSummary observed, generated;
  Distances area, width, aspectRatio;
  const Distances& distances(ComparedMetric m) const;
  Distances& distances(ComparedMetric m);
};

/// Compares two sets of parcels. Histogram intersections use `bins` shared bins
/// up to the pooled `upperQuantile` (see sharedHistogram); with `histograms`,
/// those shared histograms are also returned, in the order of kComparedMetrics.
Comparison compareSets(const std::vector<ParcelMetrics>& observed, const std::vector<ParcelMetrics>& generated,
                       int bins, double upperQuantile, std::vector<SharedHistogram>* histograms = nullptr);

/// One set of parcels made ready to be compared: its summary and the sorted
/// finite values of each compared metric. A set compared many times (the
/// observed side of every update of an interactive session) is prepared once.
struct PreparedSet {
  SetSummary summary;
  std::vector<double> sorted[std::size(kComparedMetrics)];  ///< in the order of kComparedMetrics
};
PreparedSet prepareSet(const std::vector<ParcelMetrics>& metrics);
/// compareSets on prepared sets: the same numbers as on their metrics.
Comparison compareSets(const PreparedSet& observed, const PreparedSet& generated, int bins, double upperQuantile,
                       std::vector<SharedHistogram>* histograms = nullptr);

struct BlockComparison {
  std::int64_t blockId = -1;
  Key blockKey = 0;      ///< the observed block's stable key
  double blockArea = 0;  ///< m²
  Comparison comparison;
};

/// The per-block table (blocks.csv of `compare`): the paper's observed versus
/// procedural count, A-bar, s_A, W-bar, s_W, then the distances and quality
/// shares. Empty distances (a side without parcels) are written as NaN.
Table blockComparisonTable(const std::vector<BlockComparison>& blocks);
/// One row per quantity with its observed and procedural value (summary.csv).
Table summaryTable(const Comparison& city);
/// One row per compared metric: KS, Wasserstein-1, histogram intersection (distances.csv).
Table distanceTable(const Comparison& city);

}  // namespace parcelscope::analysis
