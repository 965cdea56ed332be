#pragma once
// The `generate` job: blocks in (a block layer, or observed parcels grouped into
// blocks exactly as `stats` does), procedural parcels out, with the same
// metrics as observed parcels. The command line and the GUI both call this.
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/Json.h"
#include "parcelscope/generation/ObbSubdivision.h"
#include "parcelscope/generation/SkeletonSubdivision.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/io/ParcelReader.h"
#include "parcelscope/io/StreetReader.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/StatsJob.h"

namespace parcelscope::pipeline {

using generation::ObbParameters;
using generation::SkeletonParameters;
using generation::SkeletonReuse;
using generation::StreetWidths;
using generation::Subdivision;

/// One block's own style and parameters, set by the user over the run's.
struct BlockOverride {
  /// A style of generationStyles(); empty keeps the run's style.
  std::string style;
  /// Generator parameters (names of generationParameterDescriptions(), "seed"
  /// included). They win over the block's derived bounds and the run's values.
  ParameterValues parameters;
};
/// Overrides by block key (`block_key` of `stats` and `compare`; see Keys.h):
/// they stay on their block whatever the order of the input's features.
using BlockOverrides = std::map<Key, BlockOverride>;
/// Overrides by block id (ObservedAnalysis block ids, or the block_id field of
/// a block layer), as version 1 session files hold them: ids follow the order
/// of the input's features, so these are resolved against the blocks as read.
using BlockOverridesById = std::map<std::int64_t, BlockOverride>;

struct PremadeBlock;

struct OutcomeLibrary;  // below

struct GenerateRequest {
  io::ReadOptions input;
  /// The input holds observed parcels: build blocks and per-block A_min, A_max,
  /// W_min, W_max from them (as `stats`). Otherwise it holds block polygons, and
  /// numeric fields a_min, a_max, w_min, w_max (as in `stats`' blocks.gpkg) are
  /// used per block when present.
  bool fromParcels = false;
  std::string style = "obb";
  /// Values of analysis::analysisParameters() and obbParameterDescriptions().
  ParameterValues parameters;
  /// Names the user set explicitly: these override per-block values.
  std::set<std::string> explicitParameters;
  /// With fromParcels: the input already read and analysed with `parameters`
  /// (as `compare` does before generating); used instead of reading it again.
  const pipeline::ObservedData* observed = nullptr;
  /// Per-block style and parameters; a block key or id no block has is
  /// Error(Usage). A block named both ways takes the override by key.
  BlockOverrides overrides;
  BlockOverridesById overridesById;
  /// Street centre lines: the blocks are the street network's (StreetsJob.h),
  /// with the street parameters read from `parameters`. With fromParcels, the
  /// observed parcels of `input` are assigned to them for per-block bounds;
  /// without, `input.path` may be empty and every block takes the run's values.
  std::optional<io::StreetReadOptions> streets;
  /// Outcomes of earlier runs on the same blocks (a leaderboard's styles
  /// before `auto` and `access`): an entry whose plan is among its block's
  /// there takes a copy of that outcome instead of being subdivided. Null: none.
  const OutcomeLibrary* reusable = nullptr;
  /// Where the run leaves its outcomes, by plan, for later runs (null: nowhere).
  OutcomeLibrary* keep = nullptr;
  /// Outcomes made elsewhere (by the shards of the run: pipeline/Shards.h),
  /// one per block entry: an entry whose premade plan equals its own takes
  /// that outcome (moved out) instead of being subdivided here. Null: none.
  std::vector<PremadeBlock>* premade = nullptr;
};

struct GeneratedParcels {
  /// The input as read (frame, CRS, cleaning report), shared with the BlockInputs it came from.
  std::shared_ptr<const io::ParcelLayer> source;
  /// The street network the blocks come from (--streets); null otherwise.
  std::shared_ptr<const StreetNetwork> streets;
  std::vector<Block> blocks;           ///< block outlines; `parcels` index `parcels` below
  std::vector<std::int64_t> blockIds;  ///< id of each entry of `blocks` (ids repeat for multipart blocks)
  std::vector<Key> blockKeys;          ///< stable key of each entry of `blocks` (repeats as ids do)
  std::vector<Polygon> parcels;        ///< generated parcels, local metres
  std::vector<analysis::ParcelMetrics> metrics;
  /// Entries of `blocks` whose outcome was measured by shape only (see
  /// BlockReuse::shapesOnly): neighbours, frontage and street access of their
  /// parcels are not known yet (left at 0). Empty: every parcel fully measured.
  std::vector<std::size_t> contextPending;
  std::int64_t failedBlocks = 0, oversize = 0, withoutAccess = 0;
  std::int64_t clampedBounds = 0;   ///< per-block bounds moved into the parameter ranges
  std::int64_t fallbackBlocks = 0;  ///< skeleton blocks subdivided with OBB instead
  std::int64_t premadeBlocks = 0;   ///< entries whose outcome was made elsewhere (GenerateRequest::premade)
  std::int64_t reusedBlocks = 0;    ///< entries whose outcome an earlier run had made (GenerateRequest::reusable)
  std::int64_t patioParcels = 0;    ///< parcels that are (parts of) patios
  /// Per parcel, 1 where it is land the style left unassigned (see
  /// Subdivision::unassignedParcels): written with role "unassigned", drawn
  /// in a neutral colour, left out of every comparison. Empty when none is.
  std::vector<char> unassigned;
  std::int64_t unassignedParcels = 0;
  /// Blocks subdivided towards a number of parcels (sexton), and of those the
  /// blocks that reached it exactly.
  std::int64_t blocksWithTarget = 0, blocksAtTarget = 0;
  double unassignedArea = 0;  ///< m²
  /// Per parcel, its geometry as a file holds it where it was made beside the
  /// parcels (BlockOutcome::written; an empty wkb elsewhere). Empty when none was.
  std::vector<io::FileGeometry> written;
  bool isUnassigned(std::size_t parcel) const { return !unassigned.empty() && unassigned[parcel]; }
  /// Indices of the parcels that are not unassigned land, of `parcels` (all
  /// parcels when empty).
  std::vector<int> assignedOf(const std::vector<int>& parcels) const;
  std::vector<std::string> blockStyles;  ///< style each entry of `blocks` was subdivided with
  /// Blocks by the variant their style chose (Subdivision::variant: template's templates).
  std::map<std::string, std::int64_t> blocksByVariant;
  std::vector<std::string> failures;  ///< one line per failed or fallen-back block
  std::uint64_t seed = 0;
  Timings timings;  ///< "subdivide" and "measure"
};

/// The blocks of a run before any style or parameter is chosen: each block
/// polygon with its id, its own bounds (NaN where it has none) and the share of
/// its observed parcels with street access (NaN when unknown). Multipart blocks
/// give one entry per part.
struct BlockInputs {
  struct Entry {
    std::int64_t blockId = -1;
    Polygon shape;
    double aMin = NAN, aMax = NAN, wMin = NAN, wMax = NAN;
    double accessShare = NAN;
    /// The block's stable key (observed blocks: Block::key; a block layer: its
    /// block_key field, else the feature's geometry).
    Key blockKey = 0;
    int part = 0;  ///< which part of a multipart block
    /// The block's observed parcels (shared by its parts), for styles that fit
    /// them; null without observed parcels.
    std::shared_ptr<const generation::ObservedSample> observed;
    double observedShare = 1.0;  ///< this part's share of its block's area
  };
  std::shared_ptr<const io::ParcelLayer> source;  ///< the input as read (frame, CRS, cleaning report)
  /// The street network the blocks come from (--streets); null otherwise.
  std::shared_ptr<const StreetNetwork> streets;
  std::vector<Entry> entries;
  /// Street widths per entry (see StreetWidths), measured on first need by streetWidthsOf().
  std::vector<StreetWidths> widths;
};

/// Reads (or takes request.observed) and lists the blocks, as generate() does.
BlockInputs prepareBlocks(const GenerateRequest& request, const ProgressFn& progress = {});

/// Street widths of every entry, measured once from the block layout and kept in `inputs`.
const std::vector<StreetWidths>& streetWidthsOf(BlockInputs& inputs);

/// How one block is subdivided: a concrete style, every parameter, its own seed.
/// Two equal plans give the same parcels.
struct BlockPlan {
  std::string style;  ///< a concrete style of the registry (generation::styles()), auto resolved
  /// The values the style reads (generation::styleValues), per-block bounds included.
  ParameterValues values;
  std::uint64_t seed = 0;  ///< the block's seed (blockSeed of the run seed and the key of the block's part)
  /// The OBB bounds of `values`.
  ObbParameters bounds() const { return generation::obbParametersFrom(values); }
  bool operator==(const BlockPlan& other) const;
  bool operator!=(const BlockPlan& other) const { return !(*this == other); }
};

/// Throws Error(Usage) naming the styles when `style` is not one (auto
/// included): said before any input is read.
void requireStyle(const std::string& style);

/// Throws Error(Usage) when a generator parameter of `values` is out of its
/// range or a bound pair is out of order (--a-min above --a-max): said before
/// any input is read. (Other names in `values` are not checked here.)
void requireGeneratorParameters(const ParameterValues& values);

/// The summary's line saying that `clamped` per-block bounds were moved into
/// their parameter's range (planBlocks).
std::string clampedBoundsNote(std::int64_t clamped);

/// The plan of every entry of `inputs` under `request`: auto resolved, per-block
/// bounds clamped into range (counted in `clampedBounds`), the user's explicit
/// values and the block overrides applied. Throws Error(Usage) on an unknown
/// style, a bound pair out of order or an override for a block that does not exist.
/// Entries `skip` marks (when given) are left unplanned (a default BlockPlan):
/// the caller has their plans already (and their clamped bounds are not counted).
std::vector<BlockPlan> planBlocks(const GenerateRequest& request, const BlockInputs& inputs,
                                  std::int64_t* clampedBounds = nullptr, const std::vector<char>* skip = nullptr);

/// One block subdivided and its parcels measured (shape metrics, neighbours
/// within the block, frontage on the block).
struct BlockOutcome {
  Subdivision subdivision;
  std::vector<analysis::ParcelMetrics> metrics;
  /// Whether neighbours, frontage and street access are in `metrics` (false
  /// after a shapes-only run, until measureOutcomeContext).
  bool contextMeasured = true;
  /// The parcels as a file holds them (io::fileGeometry), when made beside
  /// them (by a shard of the run); empty otherwise.
  std::vector<io::FileGeometry> written;
};
/// A digest of every field of `plan` (its style, each value by name, its seed):
/// plans with equal keys are taken as equal.
Key planKey(const BlockPlan& plan);

/// One block entry subdivided and measured elsewhere, and under what plan.
struct PremadeBlock {
  bool made = false;  ///< false: left to the run
  Key plan = 0;       ///< planKey of the plan it was made under
  BlockOutcome outcome;
};

/// Outcomes of runs on the same blocks, per block entry, by the planKey of
/// the plan each was made under (equal plans give equal outcomes).
struct OutcomeLibrary {
  std::vector<std::map<Key, BlockOutcome>> byEntry;
};

/// What runBlock may reuse from the block's last run.
struct BlockReuse {
  /// The entry's outcome under `previousPlan` (both null: nothing to reuse).
  const BlockOutcome* previous = nullptr;
  const BlockPlan* previousPlan = nullptr;
  /// Keep the OBB splits or the skeleton layout in the outcome for the next
  /// run (see ObbSplits and SkeletonReuse).
  bool record = false;
  /// Measure the new parcels' shapes only; their neighbours, frontage and
  /// street access are left for measureOutcomeContext (parcels equal to the
  /// previous ones keep whatever the previous outcome had measured).
  bool shapesOnly = false;
};
/// Runs `plan` on entry `entry` of `inputs` (street widths must have been measured
/// with streetWidthsOf when the style is not obb). `minFrontage` as the analysis's.
/// With `reuse`, an OBB plan differing from the previous one only in A_max or
/// W_max reuses its splits, a skeleton plan keeping d_offset, the street angle
/// and the corner rule reuses the skeleton and strips, and parcels equal to
/// the previous ones keep their metrics; the outcome is the same as without.
BlockOutcome runBlock(const BlockInputs& inputs, std::size_t entry, const BlockPlan& plan, double minFrontage,
                      const BlockReuse& reuse = {});

/// Fills in the neighbours, frontage and street access of an outcome of
/// entry `entry` measured by shape only; the metrics are then those runBlock
/// gives without shapesOnly.
void measureOutcomeContext(const BlockInputs& inputs, std::size_t entry, BlockOutcome& outcome, double minFrontage);

/// The run's result from one outcome per entry (in entry order).
GeneratedParcels assembleParcels(const BlockInputs& inputs, const std::vector<BlockPlan>& plans,
                                 const std::vector<const BlockOutcome*>& outcomes, std::uint64_t seed);

/// {variant: blocks} of GeneratedParcels::blocksByVariant (run.json's blocks_by_template).
Json variantCounts(const std::map<std::string, std::int64_t>& blocksByVariant);

/// Reads the input and subdivides every block (in parallel) with the request's
/// style: prepareBlocks, planBlocks, runBlock on every entry, assembleParcels. Throws Error on bad input or parameters
/// (A_min > A_max, W_min > W_max, unknown style).
GeneratedParcels generate(const GenerateRequest& request, const ProgressFn& progress = {});

/// The generated parcels as parcels.gpkg and parcels.csv hold them: one row per
/// parcel in block order (parcel_id, parcel_key, block_id, block_key and every
/// metric; parcel_key is the block's key and the parcel's index in its block,
/// "<block_key>-<index>") and, when
/// `geometries` is given, each row's geometry.
Table generatedParcelTable(const GeneratedParcels& g, std::vector<std::vector<Polygon>>* geometries = nullptr);
/// The same rows, made when read; `g` must outlive it. `parcelOfRow` receives
/// each row's parcel (an index of g.parcels), in row order.
RowSource generatedParcelRows(const GeneratedParcels& g, std::vector<int>* parcelOfRow = nullptr);

/// Runs `generate` and writes DIR/parcels.gpkg (layer `parcels`, input CRS, field
/// block_id and the metrics), DIR/parcels.csv and DIR/run.json, all at once when
/// complete.
pipeline::JobOutcome runGenerate(const GenerateRequest& request, const std::string& outDir,
                                 const ProgressFn& progress = {});

}  // namespace parcelscope::pipeline
