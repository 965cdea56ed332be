#pragma once
// From observed parcels to blocks, per-parcel metrics and per-block statistics
// with the generator parameters of Vanegas et al. 2012, section 6.
#include <cstdint>
#include <vector>

#include "parcelscope/analysis/Metrics.h"
#include "parcelscope/core/Parameter.h"
#include "parcelscope/core/Parcel.h"
#include "parcelscope/core/Progress.h"
#include "parcelscope/core/Table.h"
#include "parcelscope/core/Timings.h"

namespace parcelscope::analysis {

/// How a block's bounds are derived from its observed parcels' areas and widths.
struct BoundsRule {
  double k = 2.0;
  /// false (`--derive paper`): the paper's A-bar -/+ k s_A, W-bar -/+ k s_W
  /// (mean and sample standard deviation); true (`--derive robust`): median
  /// -/+ k x 1.4826 MAD (the MAD scaled to s for normal data), which skewed
  /// areas and a few corner or through lots do not pull up.
  bool robust = false;
  BoundsRule(double kValue = 2.0, bool robustSpread = false) : k(kValue), robust(robustSpread) {}  // NOLINT
  bool operator==(const BoundsRule& o) const { return k == o.k && robust == o.robust; }
  bool operator!=(const BoundsRule& o) const { return !(*this == o); }
};

struct AnalysisOptions {
  /// Parcels whose boundaries come within this distance (m) belong to one block;
  /// the block outline is closed over gaps narrower than it.
  double blockTolerance = 1.0;
  /// k of A_min = A-bar - k s_A etc.
  double k = 2.0;
  /// Bounds from median and MAD instead of mean and standard deviation (BoundsRule::robust).
  bool robustBounds = false;
  BoundsRule bounds() const { return {k, robustBounds}; }
  /// Frontage (m) a parcel needs to count as having street access.
  double minFrontage = 1.0;
  /// Detect right-of-way parcels (streets stored as parcels) and keep them out of blocks.
  bool detectRightOfWay = true;
};

/// The descriptions of AnalysisOptions (CLI flags, GUI controls, run record).
const std::vector<ParameterDescription>& analysisParameters();
/// min-frontage, the street-access threshold of observed parcels (AnalysisOptions)
/// and of generated ones (generation::ObbParameters): described once, here, and
/// listed by analysisParameters() and generation::obbParameterDescriptions().
const ParameterDescription& minFrontageParameter();
/// Options from parameter values (names as in analysisParameters()).
AnalysisOptions analysisOptionsFrom(const ParameterValues& values);

struct ParcelMetrics : ShapeMetrics {
  int neighbours = 0;         ///< parcels sharing >= 1 m of boundary (edges within min(block tolerance, 1 m))
  double frontage = 0;        ///< m of boundary on the block's outer contour (within tolerance/2, 5 cm..0.5 m)
  bool streetAccess = false;  ///< frontage >= minFrontage
};

/// Why a parcel was judged to be a right-of-way (a street stored as a parcel).
enum class RightOfWay : std::uint8_t {
  No = 0,
  HolesHoldParcels,  ///< thin (MBR width >= 6 strip widths 2A/P) and its holes contain other parcels
  NetworkShape       ///< thin (as above) and at least 10 neighbours
};

/// Whether a parcel of these metrics has the shape of a right-of-way (thin:
/// MBR width at least 6 strip widths 2A/P); whether it is one depends on the
/// parcels around it (in its holes, or touching it).
bool hasRightOfWayShape(const ShapeMetrics& metrics);

struct BlockStatistics {
  int blockId = -1;
  int parcelCount = 0;
  double blockArea = 0;          ///< m², area of the block polygon
  double meanArea = 0;           ///< A-bar, m²
  double sdArea = 0;             ///< s_A, m² (sample standard deviation; 0 for one parcel)
  double meanWidth = 0;          ///< W-bar, m (MBR short side)
  double sdWidth = 0;            ///< s_W, m
  double aMin = 0, aMax = 0;     ///< A-bar -/+ k s_A, m² (aMin clamped, see aMinClamped)
  double wMin = 0, wMax = 0;     ///< W-bar -/+ k s_W, m (wMin clamped, see wMinClamped)
  bool aMinClamped = false;      ///< A-bar - k s_A was below max(0.1 A-bar, 1 m²) and was raised to it
  bool wMinClamped = false;      ///< W-bar - k s_W was below max(0.1 W-bar, 0.5 m) and was raised to it
  double streetAccessShare = 0;  ///< fraction of the block's parcels with street access
};

/// Per-block statistics and the derived generator bounds; `widths` and `areas`
/// are the block's parcels' values. Precondition: at least one value.
BlockStatistics blockStatistics(const std::vector<double>& areas, const std::vector<double>& widths,
                                const BoundsRule& rule);

struct ObservedAnalysis {
  std::vector<ParcelMetrics> metrics;       ///< one per parcel
  std::vector<RightOfWay> rightOfWay;       ///< one per parcel
  std::vector<int> blockOf;                 ///< block id per parcel; -1 for right-of-way parcels
  std::vector<Block> blocks;                ///< ids 0..n-1, in order of their first parcel
  std::vector<BlockStatistics> statistics;  ///< one per block
  std::int64_t rightOfWayCount = 0;
  std::int64_t multipartBlocks = 0;  ///< blocks whose closed union has several parts
  std::int64_t clampedAMin = 0, clampedWMin = 0;
  Timings timings;  ///< per analysis stage
};

/// Metrics, right-of-way detection, blocks and block statistics for `parcels`
/// (local metres, normalised). Reports progress; throws Error(Cancelled) if asked
/// to stop and Error(Geometry) if a block union fails.
ObservedAnalysis analyseParcels(const std::vector<Parcel>& parcels, const AnalysisOptions& options,
                                const ProgressFn& progress = {});

/// Derives every block's statistics and bounds again with another rule; the
/// blocks, metrics, block areas and street-access shares stay as they are.
void rederiveBlockBounds(ObservedAnalysis& analysis, const BoundsRule& rule);

/// Metrics of parcels whose blocks are already known (generated parcels):
/// shape metrics, neighbours (>= 1 m of shared boundary within `tolerance`) and
/// frontage on the outline of their block. `blocks[b].parcels` index `shapes`.
std::vector<ParcelMetrics> measureParcels(const std::vector<Polygon>& shapes, const std::vector<Block>& blocks,
                                          double tolerance, double minFrontage);
/// measureParcels in two steps: the shape metrics alone (neighbours, frontage
/// and street access left at 0), then measureContext, which fills those three
/// in. An interactive caller can show shapes, areas and widths before the
/// slower context is measured.
std::vector<ParcelMetrics> measureShapes(const std::vector<Polygon>& shapes);
void measureContext(const std::vector<Polygon>& shapes, const std::vector<Block>& blocks, double tolerance,
                    double minFrontage, std::vector<ParcelMetrics>& metrics);

/// The metric columns shared by observed and generated parcel tables, and one
/// parcel's values for them (same order).
std::vector<Column> metricColumns();
std::vector<Value> metricValues(const ParcelMetrics& m);

/// One row per parcel: ids, block, role and every metric (the parcels.csv columns).
Table parcelTable(const std::vector<Parcel>& parcels, const ObservedAnalysis& analysis);
/// The same rows, made when read; `parcels` and `analysis` must outlive it.
RowSource parcelRows(const std::vector<Parcel>& parcels, const ObservedAnalysis& analysis);
/// One row per block: statistics and derived parameters (the blocks.csv columns).
Table blockTable(const ObservedAnalysis& analysis);

}  // namespace parcelscope::analysis
