#pragma once
// One run split into spatial shards, by several processes (MPI ranks, or
// array jobs and `merge`), giving the outputs of a single process.
//
// The layer's extent is cut into `count` vertical strips. Shard i reads the
// features whose envelope meets its strip widened by a halo, and analyses them
// as one process would. A block (or a right-of-way parcel) is shard i's when
// the smallest x of its features' envelopes lies in strip i; it is kept only once
// it is whole: its box, grown by the contact distances, lies inside the window
// read, so every parcel that touches it, and so its grouping, right-of-way
// test, outline and metrics, are the single process's. A block of the strip
// that is not whole widens the window and the shard reads again; so does a
// block, not whole, that holds a parcel of right-of-way shape whose own
// surroundings are not all read (a right-of-way seen as a lot joins blocks).
// Parts end with a checksum of their bytes. The local
// frame is the single process's too: its sample (the features' centres) is
// exchanged between the shards, or, without exchange, read from every feature.
// The shard then subdivides and measures its blocks under the plan the whole
// run gives them (each block's plan depends on the block and the request
// only), except those whose style reads street widths (measured to the
// neighbouring blocks), and maps its parcels and outlines back as the writer
// would. mergeShards then orders the parcels by feature id and part, numbers
// the blocks by their first parcel, and gives the ObservedData one process
// reads, with the shards' outcomes in block-entry order for generate().
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/StatsJob.h"

namespace parcelscope::pipeline {

/// One shard's blocks and right-of-way parcels, whole.
struct ShardPart {
  int index = 0, count = 1;
  std::string path, layerName;
  std::vector<double> frame;  ///< io::LocalFrame::state()
  io::CrsInfo crs;
  io::CleaningReport report;  ///< the features of this shard's strip
  std::vector<Parcel> parcels;
  std::vector<std::vector<double>> fields;  ///< per parcel, as io::ParcelLayer::fields
  std::vector<analysis::ParcelMetrics> metrics;
  std::vector<analysis::RightOfWay> rightOfWay;
  std::vector<Block> blocks;  ///< `parcels` index this part's parcels
  std::vector<analysis::BlockStatistics> statistics;
  /// Per block, its outline as blocks.gpkg holds it (io::fileGeometry).
  std::vector<io::FileGeometry> blockOutlines;
  /// One per block entry (each block's parts in turn): the entry subdivided
  /// and measured here, under the plan the whole run gives it, or left to the
  /// merged run (`made` false: a style that reads street widths, which need
  /// the neighbouring blocks; or overrides by block id, which name the merged
  /// blocks). Empty: nothing generated here.
  std::vector<PremadeBlock> generated;
  std::int64_t blocksGenerated = 0;  ///< entries of `generated` made here
  double generateSeconds = 0;        ///< subdividing and measuring them
  std::vector<std::pair<std::string, double>> readTimings, analysisTimings;
  /// Shard 0: the layer's features as GDAL counts them (the merge checks that
  /// the shards counted each once). -1 in the other shards.
  std::int64_t layerFeatures = -1;
  int reads = 0;                 ///< windows read (1 when no block crossed the first one's edge)
  std::int64_t parcelsRead = 0;  ///< parcels cleaned over the reads
  double seconds = 0;            ///< reading and analysis
};

/// How a shard reads: through its window (io::ShardRead) and an exchange of the frame
/// sample with the other shards (MPI), or reading every feature for the
/// frame (one shard alone, as an array job does).
struct ShardReading {
  bool spatialFilter = false;
  /// With spatialFilter: called once by every shard, in step (a collective).
  std::function<void(io::FrameSample&)> exchange;
};

/// Shard `index` of `count` of request.input, analysed with request.parameters.
/// Only blocks from the parcels (no --streets). Throws Error as loadObserved.
ShardPart analyseShard(const CompareRequest& request, int index, int count, const ShardReading& reading,
                       const ProgressFn& progress = {});

/// The ObservedData a single process reads, from every shard's part (any
/// order). Throws Error(Input) when the parts are not one run's `count` shards
/// or overlap. With `generated`, the parts' premade entries in the order of
/// the merged data's block entries (ShardPart::generated).
ObservedData mergeShards(std::vector<ShardPart> parts, std::vector<PremadeBlock>* generated = nullptr);

/// A part as bytes and back (files of `compare --shard`, messages between ranks).
std::string encodeShard(const ShardPart& part);
/// Throws Error(Input) naming `what` when `bytes` is not an encoded part.
ShardPart decodeShard(std::string_view bytes, const std::string& what);

/// Runs shard `index` of `count` (reading every feature for the frame, as an
/// array job does) and writes into `outDir`, all at once: shard.bin (the part),
/// session.json (the request, input path made absolute) and shard.json (what
/// it holds, and the input path as given).
JobOutcome runShard(const CompareRequest& request, int index, int count, const std::string& outDir,
                    const ProgressFn& progress = {});

/// The request and the merged observed data of the folders runShard wrote
/// (one per shard, any order). Throws Error(Input) when a folder is no shard,
/// or the shards are not of one request and input.
std::pair<CompareRequest, PreparedObserved> readShards(const std::vector<std::string>& folders);

/// The merged data of `parts` with run.json's record of them ("ranks",
/// "shards": each one's blocks, parcels, windows read and seconds). When the
/// shards hold no parcel at all, `input` is read in one process for the error
/// one process gives (no usable polygon, and why).
PreparedObserved prepareMerged(std::vector<ShardPart> parts, int ranks, const io::ReadOptions& input);

/// Parses "I/N" (0 <= I < N) of --shard; throws Error(Usage).
std::pair<int, int> parseShard(const std::string& text);

}  // namespace parcelscope::pipeline
