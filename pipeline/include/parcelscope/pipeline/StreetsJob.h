#pragma once
// Blocks from a street network (`parcelscope blocks`, and `generate` and
// `compare` with --streets): centre lines read, a planar road graph built,
// unknown widths measured from observed parcels or set to a default, blocks as
// the graph's faces minus the street surface (analysis/RoadGraph.h). Observed
// parcels, when given, are assigned to the street block they overlap most, so
// that per-block statistics and comparisons are those of street blocks.
#include <memory>
#include <string>
#include <vector>

#include "parcelscope/analysis/RoadGraph.h"
#include "parcelscope/core/Parameter.h"
#include "parcelscope/core/Table.h"
#include "parcelscope/core/Timings.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/StreetReader.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/StatsJob.h"

namespace parcelscope::pipeline {

/// The street network's parameters (group "Streets"): street-snap, default-width,
/// max-block-area.
const std::vector<ParameterDescription>& streetParameters();

// (StreetEditor::apply copies every member but `blocks` one by one: a new
// member is to be copied there too.)
struct StreetNetwork {
  io::StreetLayer layer;
  analysis::RoadGraph graph;
  analysis::StreetBlocks blocks;
  std::int64_t widthsGiven = 0;     ///< edges whose line had a width (width or class field)
  std::int64_t widthsMeasured = 0;  ///< measured from the observed parcels' blocks
  std::int64_t widthsDefault = 0;   ///< default-width
  /// Rings of the study area's boundary added to the graph: with observed
  /// parcels, the outline of all their blocks (gaps narrower than two default
  /// widths closed), which closes the faces where the network is cut off.
  std::int64_t boundaryLines = 0;
  Timings timings;  ///< "read streets", "graph", "widths", "street blocks"
};

/// Reads `streets` (into the frame and CRS of `observed` when given), builds
/// the graph (closed by the outline of `observed`'s blocks, see
/// boundaryLines), fills unknown widths (measured from `observed`'s blocks
/// when given, else `default-width`) and builds the blocks. Throws Error(Input) on
/// unreadable streets, Error(Geometry) if GEOS fails.
StreetNetwork buildStreetNetwork(const io::StreetReadOptions& streets, const ParameterValues& parameters,
                                 const ObservedData* observed = nullptr, const ProgressFn& progress = {});

/// Regroups `observed` into the blocks of `network`: each lot (right-of-way
/// parcels stay out) goes to the street block it overlaps most, or to none
/// when it overlaps none (then it is left out of blocks, as right-of-way is);
/// each street block's statistics and bounds come from its parcels with `k`
/// (NaN, so that the run's values apply, for a block without parcels). The
/// blocks' keys are the street blocks' keys; `observed.streets` keeps `network`.
/// Returns the number of lots left outside every street block.
std::int64_t assignToStreetBlocks(ObservedData& observed, std::shared_ptr<const StreetNetwork> network,
                                  const analysis::BoundsRule& rule);

/// Reads observed parcels as loadObserved does and, with `streets`, regroups
/// them into street blocks (assignToStreetBlocks) built with `parameters`.
ObservedData loadObservedInStreetBlocks(const io::ReadOptions& input, const io::StreetReadOptions* streets,
                                        const ParameterValues& parameters, const ProgressFn& progress = {});

/// blocks.gpkg's attributes: block_key, area, streets (the names faced, '; '
/// between), edge_keys (the edges faced, ',' between), parcel_count (-1 without
/// observed parcels).
Table streetBlockTable(const StreetNetwork& network, const ObservedData* observed = nullptr);
/// streets.gpkg's layers: nodes (node_key, degree) and edges (edge_key, width,
/// width_source, kind (street or boundary), name, from_node_key, to_node_key, length).
Table streetNodeTable(const StreetNetwork& network);
Table streetEdgeTable(const StreetNetwork& network);

/// The run record's "streets" section: the layer read, the graph's counts and
/// the blocks'.
Json streetRecord(const StreetNetwork& network);

/// Writes `network` into `out`'s staging folder: blocks.gpkg (layer `blocks`,
/// streetBlockTable with `observed`), streets.gpkg (layers `nodes` and `edges`)
/// and street_surface.gpkg (layer `surface`), in the network's frame and CRS.
/// Returns the polygon layers written, for the run record.
std::vector<std::pair<std::string, io::LayerWrite>> writeStreetLayers(io::OutputDirectory& out,
                                                                      const StreetNetwork& network,
                                                                      const ObservedData* observed = nullptr);

/// `parcelscope blocks`: builds the network (widths measured from `parcels`
/// when given) and writes, all at once when complete, DIR/blocks.gpkg (layer
/// `blocks`), DIR/streets.gpkg (layers `nodes` and `edges`),
/// DIR/street_surface.gpkg (layer `surface`) and DIR/run.json.
JobOutcome runBlocks(const io::StreetReadOptions& streets, const ParameterValues& parameters,
                     const io::ReadOptions* parcels, const std::string& outDir, const ProgressFn& progress = {});

}  // namespace parcelscope::pipeline
