#pragma once
// A planar road graph built from street centre lines, and city blocks as its
// faces (Vanegas et al. 2012, section 3.1: nodes are intersections, edges are
// street segments with a width; a block is a face of the graph, its contour
// moved inward by the half width of each street it faces).
//
// Real centre lines are not a clean graph: lines cross without a shared
// vertex, stop short of the street they meet, run twice over the same segment,
// and pass over each other on bridges. buildRoadGraph nodes crossings (except
// for lines marked as not noded: bridges and tunnels), joins endpoints within a
// snap distance, merges duplicate segments and keeps dead ends. Keys of nodes,
// edges and blocks depend on geometry only, never on the order of the input.
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "parcelscope/core/GeosOps.h"
#include "parcelscope/core/Keys.h"
#include "parcelscope/core/Progress.h"

namespace parcelscope::analysis {

using geos::Polyline;

/// One street centre line as read, local metres.
struct StreetLine {
  Polyline line;
  double width = NAN;  ///< street width in m (kerb to kerb); NaN when unknown
  std::string name;
  bool noNode = false;  ///< a bridge or tunnel: meets other lines only at its ends
  Key key = 0;          ///< the feature's key (hash of its geometry)
  /// Not a street: the edge of the study area (where the data ends, a city
  /// limit), which closes the faces at the edge of the network. It has no
  /// width and no block faces it as a street.
  bool boundary = false;
};

/// Where keys drawn from positions see a local point, in steps of a key cell
/// (about a centimetre; see io::LocalFrame::keyPlace): the input's own
/// coordinates, so that keys do not move with the local frame, whose origin
/// follows the data. Null: local metres, in centimetres.
using KeyPlace = std::function<Point(const Point&)>;

struct RoadGraphOptions {
  /// Endpoints closer than this (m) become one node; a free end this close to
  /// another line meets it there (a T-junction).
  double snap = 1.0;
  KeyPlace keyPlace;
};

struct RoadNode {
  Key key = 0;  ///< from its place (the key place of its cell of the 1 mm noding grid)
  Point at;
  int degree = 0;  ///< edges ending here (a loop counts twice); 1: a dead end
};

struct RoadEdge {
  Key key = 0;  ///< from its end nodes' keys and its middle point's key place
  int from = -1, to = -1;
  /// From node `from` to node `to`: the edge's geometry, or, for a curved
  /// edge, its cubic Bezier flattened (see setCurve).
  Polyline line;
  /// A curved edge's two control points (a cubic Bezier from node `from` to
  /// node `to`, Vanegas et al. 2012, section 3.1); none for a polyline edge.
  std::optional<std::array<Point, 2>> controls;
  double width = NAN;
  std::string name;
  bool noNode = false;
  bool boundary = false;  ///< the study area's edge, not a street (see StreetLine::boundary)
  int source = -1;        ///< index of the StreetLine it comes from
};

struct RoadGraphReport {
  std::int64_t lines = 0;             ///< lines given
  std::int64_t skipped = 0;           ///< fewer than two distinct points
  std::int64_t endpointsJoined = 0;   ///< endpoints moved onto another endpoint within the snap distance
  std::int64_t endpointsOnLines = 0;  ///< free ends moved onto another line within the snap distance
  std::int64_t duplicateEdges = 0;    ///< edges that more than one line ran along (merged)
  std::int64_t deadEnds = 0;          ///< nodes of degree 1
  std::int64_t notNoded = 0;          ///< lines kept apart from what they cross (bridges, tunnels)
};

struct RoadGraph {
  std::vector<RoadNode> nodes;
  std::vector<RoadEdge> edges;
  RoadGraphReport report;
  KeyPlace keyPlace;  ///< the options' (block keys are drawn from it too)
};

/// The graph of `lines`. Deterministic, and independent of the order of
/// `lines`: nodes and edges come sorted by key. Throws Error(Geometry) if GEOS
/// fails to node the lines.
RoadGraph buildRoadGraph(const std::vector<StreetLine>& lines, const RoadGraphOptions& options = {});

/// Makes edge `edge` the cubic Bezier from its `from` node through control
/// points `c1`, `c2` to its `to` node (none: a straight segment between its
/// nodes), flattened into `line` so that no point of the curve lies farther
/// than `tolerance` (m) from it. Keys do not change: an edge keeps its identity
/// when its curvature is edited. Throws Error(Usage) for an edge out of range.
void setCurve(RoadGraph& graph, std::size_t edge, std::optional<std::array<Point, 2>> controls,
              double tolerance = 0.05);

/// Fills the unknown widths of `graph`'s edges: measured from the blocks of
/// observed parcels (`parcelBlocks`, the outlines `stats` builds) as the gap
/// between the blocks on either side of the centre line (the median, over
/// points every 5 m along the edge's middle 80 %, of the distances straight
/// out to the nearest block outline on the left plus on the right; twice the
/// one side where only one side has a block within `maxWidth` / 2), else
/// `defaultWidth`. Returns how many edges were measured.
std::int64_t fillStreetWidths(RoadGraph& graph, const std::vector<const Polygon*>& parcelBlocks, double defaultWidth,
                              double maxWidth = 60.0);

/// Segments per quarter circle of a street surface's round ends and joins:
/// a turning circle of 8 segments (2 per quarter) is within 8 % of the
/// circle's area, and each segment costs every overlay that cuts a block.
inline constexpr int kStreetQuadrantSegments = 2;

/// One block: a face of the graph minus the street surface.
struct StreetBlock {
  Key key = 0;  ///< setKey of the keys of the edges it faces (mixed with its part number when a face gives several)
  Polygon shape;
  /// For ring r (0 the outer ring, then the holes) and its edge from vertex i
  /// to i+1: the index of the graph edge it faces (the nearest centre line),
  /// or -1 when no centre line lies within its half width plus 1 m (the edge
  /// lies along the study area's boundary, say).
  std::vector<std::vector<int>> faced;
};

struct StreetBlockOptions {
  /// Faces larger than this (m²) are not blocks (the land around a network
  /// that encloses it, open country); pieces smaller than `minArea` or
  /// narrower than `minWidth` (twice the area over the perimeter) left after
  /// the streets are removed are dropped too (slivers between a street and
  /// the boundary).
  double maxArea = 2e6;
  double minArea = 1.0;
  double minWidth = 1.0;
  /// Segments per quarter circle of the street surface's round ends and
  /// joins (streetSurface must be given the same to match the blocks).
  int quadrantSegments = kStreetQuadrantSegments;
};

struct StreetBlocks {
  std::vector<StreetBlock> blocks;  ///< sorted by key
  std::int64_t faces = 0;           ///< faces of the graph
  std::int64_t facesTooLarge = 0;   ///< faces above maxArea (dropped)
  std::int64_t partsTooSmall = 0;   ///< pieces under minArea or minWidth (dropped)
};

/// What streetBlocks may reuse from its earlier calls on graphs that differ
/// by edits: each edge's street surface, by its line and width; each face's
/// blocks, by the face and the edges near it (their indices, keys, lines and
/// widths). A face an edit did not reach is not overlaid again: an interactive
/// editor rebuilds only the faces around what it changed. The blocks are
/// those of a call without the cache.
struct StreetBlockCache {
  struct Face {
    Polygon face;  ///< the face, compared vertex for vertex on a hit
    std::vector<StreetBlock> blocks;
    bool tooLarge = false;
    int tooSmall = 0;
  };
  std::unordered_map<Key, Face> faces;
  std::unordered_map<Key, std::vector<Polygon>> surfaces;
  /// The lines the last call polygonised (kept apart or not) and its faces:
  /// an edit that moves no line (a width) polygonises nothing again.
  std::vector<Polyline> lines;
  bool linesApart = false;
  std::optional<geos::LineFaces> lineFaces;
  /// Calls whose faces were the last call's with moved points (lines moved
  /// without a change of topology: a node dragged), not polygonised again:
  /// the faces GEOS would give, bit for bit (its dangles, unused, may then be
  /// listed in another order).
  std::int64_t facesMoved = 0;
};

/// The blocks of `graph` (every edge width must be known: see
/// fillStreetWidths). Faces come from the lines noded in full (a bridge's
/// crossings included, so that the land under it is street); each face minus
/// the surface of the streets near it (each centre line buffered by its half
/// width, round ends) gives its blocks: widths differ edge by edge, a dead end
/// cuts a slot into its block, an enclosed face is a hole of the block around
/// it. Throws Error(Geometry) if GEOS fails, Error(Cancelled) when `progress`
/// asks to stop.
StreetBlocks streetBlocks(const RoadGraph& graph, const StreetBlockOptions& options = {},
                          const ProgressFn& progress = {}, StreetBlockCache* cache = nullptr);

/// The street surface: every edge buffered by its half width, unioned.
std::vector<Polygon> streetSurface(const RoadGraph& graph, int quadrantSegments = kStreetQuadrantSegments);

/// The street widths of a block for the skeleton style (generation::StreetWidths):
/// per ring and contour edge, the width of the street it faces, NaN where none.
std::vector<std::vector<double>> facedWidths(const RoadGraph& graph, const StreetBlock& block);

}  // namespace parcelscope::analysis
