#pragma once
// Where a run's blocks come from. `generate`, `compare` and the session ask a
// BlockSource for their blocks (BlockInputs: each block part with its key, its
// own bounds and street-access share); each kind of input is one
// implementation: blocks grouped from observed parcels, a layer of block
// polygons, and a street network (blocks as the faces of a road graph, with
// observed parcels assigned to them when given; see StreetsJob.h).
#include <memory>
#include <string>

#include "parcelscope/core/Parameter.h"
#include "parcelscope/core/Progress.h"
#include "parcelscope/io/ParcelReader.h"
#include "parcelscope/pipeline/GenerateJob.h"

namespace parcelscope::pipeline {

class BlockSource {
public:
  virtual ~BlockSource() = default;
  /// Names the kind of source in run records: "observed-parcels", "block-layer",
  /// "street-network" or "street-network-with-parcels".
  virtual std::string kind() const = 0;
  /// The blocks, each multipart block as one entry per part. Throws Error(Input)
  /// on unreadable input, Error(Cancelled) when `progress` asks to stop.
  virtual BlockInputs blocks(const ProgressFn& progress = {}) const = 0;
};

/// The observed parcels of block `block` of `analysis`, as styles that fit them read them.
std::shared_ptr<generation::ObservedSample> observedSample(const analysis::ObservedAnalysis& analysis,
                                                           std::size_t block);
/// The same for a block whose parcels index `metrics`.
std::shared_ptr<generation::ObservedSample> observedSample(const std::vector<analysis::ParcelMetrics>& metrics,
                                                           const Block& block);

/// Appends to `inputs` one entry per part of each block (its bounds and
/// street access share from `statistics`, its observed parcels from
/// `metrics`), as the blocks of observed parcels are listed for generation.
void appendObservedEntries(BlockInputs& inputs, const std::vector<Block>& blocks,
                           const std::vector<analysis::BlockStatistics>& statistics,
                           const std::vector<analysis::ParcelMetrics>& metrics);

/// Blocks grouped from observed parcels exactly as `stats` groups them, with
/// bounds derived from their parcels (Vanegas et al. 2012, section 6); the
/// analysis parameters come from `parameters`. With `observed`, that data (read
/// and analysed with the same parameters) is used instead of reading `input`.
std::unique_ptr<BlockSource> observedParcelBlocks(const io::ReadOptions& input, const ParameterValues& parameters,
                                                  const ObservedData* observed = nullptr);

/// A layer of block polygons, as `stats` writes blocks.gpkg: numeric fields
/// block_id, a_min, a_max, w_min, w_max and street_access_share are used when
/// present (NaN otherwise), and block_key when present (the feature's geometry
/// gives the key otherwise).
std::unique_ptr<BlockSource> blockLayer(const io::ReadOptions& input);

/// The blocks of a street network without observed parcels: one entry per
/// street block (its index as id, its key, the run's values for its bounds)
/// with the widths of the streets it faces.
BlockInputs streetNetworkInputs(std::shared_ptr<const StreetNetwork> network);

/// The source a generate request names: the street network with `streets`
/// (its blocks, observed parcels of `input` assigned to them with fromParcels),
/// else observedParcelBlocks with fromParcels, else blockLayer.
std::unique_ptr<BlockSource> blockSourceOf(const GenerateRequest& request);

}  // namespace parcelscope::pipeline
