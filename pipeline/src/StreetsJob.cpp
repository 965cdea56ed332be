#include "parcelscope/pipeline/StreetsJob.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "parcelscope/core/BoxIndex.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/GeosOps.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/CompareSession.h"

namespace parcelscope::pipeline {

namespace {
namespace bgi = boost::geometry::index;

double value(const ParameterValues& v, const std::string& name) {
  const auto it = v.find(name);
  if (it != v.end()) return it->second;
  for (const auto& d : streetParameters()) {
    if (d.name == name) return d.defaultValue;
  }
  throw usageError("no street parameter " + name);
}

IndexBox boxOf(const Polygon& p) { return indexBox(bounds(p)); }
}  // namespace

const std::vector<ParameterDescription>& streetParameters() {
  static const std::vector<ParameterDescription> d = {
      realParameter("street-snap",
                    "Street line ends closer than this are one intersection; a line ending this close to another "
                    "meets it (a T-junction)",
                    "m", 0.0, 50.0, 1.0, "Streets"),
      realParameter("default-width",
                    "Width of a street whose line gives none and whose width cannot be measured from observed "
                    "parcels (kerb to kerb, or the right of way between parcel blocks)",
                    "m", 0.0, 200.0, 12.0, "Streets"),
      realParameter("max-block-area",
                    "Faces of the street network larger than this are not blocks (open country, the land "
                    "around a network)",
                    "m2", 1.0, 1e9, 2e6, "Streets"),
  };
  return d;
}

namespace {
StreetNetwork buildNetwork(const io::StreetReadOptions& streets, const ParameterValues& parameters,
                           const ObservedData* observed, const ProgressFn& progress) {
  StreetNetwork n;
  n.timings.start("read streets");
  n.layer =
      observed ? io::readStreets(streets, &observed->layer.frame, &observed->layer.crs) : io::readStreets(streets);
  reportProgress(progress, 0.2, "reading streets");
  n.timings.start("graph");
  std::vector<analysis::StreetLine> lines;
  lines.reserve(n.layer.streets.size());
  for (const io::StreetFeature& f : n.layer.streets) lines.push_back({f.line, f.width, f.name, f.noNode, f.key});
  analysis::RoadGraphOptions options;
  options.snap = value(parameters, "street-snap");
  // Keys from the input's own coordinates: the frame's origin follows the
  // parcels (or streets) read, and moves when some are added.
  options.keyPlace = [frame = n.layer.frame](const Point& p) { return frame.keyPlace(p); };
  if (observed && !observed->analysis.blocks.empty()) {
    // The study area's edge: where the parcels end (a city limit) closes the
    // faces the network leaves open there. The outline of every parcel block
    // (gaps narrower than two default widths, the streets between blocks,
    // closed), where it lies outside every face of the streets alone.
    std::vector<const Polygon*> all;
    for (const Block& b : observed->analysis.blocks) {
      for (const Polygon& part : b.parts) all.push_back(&part);
    }
    std::vector<geos::Polyline> outline;
    for (const Polygon& part : geos::unionAndClose(all, 2 * value(parameters, "default-width"))) {
      outline.push_back(part.outer);
      outline.back().push_back(part.outer.front());
    }
    const analysis::RoadGraph streetsOnly = analysis::buildRoadGraph(lines, options);
    std::vector<geos::Polyline> edges;
    for (const analysis::RoadEdge& e : streetsOnly.edges) edges.push_back(e.line);
    for (geos::Polyline& piece : geos::linesOutside(outline, geos::polygonizeLines(edges).faces)) {
      analysis::StreetLine edge;
      edge.line = std::move(piece);
      edge.boundary = true;
      edge.width = 0;
      edge.key = hashBytes("boundary");
      lines.push_back(std::move(edge));
      ++n.boundaryLines;
    }
  }
  n.graph = analysis::buildRoadGraph(lines, options);
  reportProgress(progress, 0.4, "road graph");
  n.timings.start("widths");
  for (const analysis::RoadEdge& e : n.graph.edges) n.widthsGiven += !std::isnan(e.width) && !e.boundary;
  std::vector<const Polygon*> parcelBlocks;
  if (observed) {
    for (const Block& b : observed->analysis.blocks) {
      for (const Polygon& part : b.parts) parcelBlocks.push_back(&part);
    }
  }
  const std::int64_t unknown =
      std::count_if(n.graph.edges.begin(), n.graph.edges.end(),
                    [](const analysis::RoadEdge& e) { return std::isnan(e.width) && !e.boundary; });
  n.widthsMeasured = analysis::fillStreetWidths(n.graph, parcelBlocks, value(parameters, "default-width"));
  n.widthsDefault = unknown - n.widthsMeasured;
  n.timings.start("street blocks");
  analysis::StreetBlockOptions blockOptions;
  blockOptions.maxArea = value(parameters, "max-block-area");
  n.blocks = analysis::streetBlocks(n.graph, blockOptions, scaledProgress(progress, 0.5, 1.0));
  n.timings.stop();
  return n;
}

}  // namespace

StreetNetwork buildStreetNetwork(const io::StreetReadOptions& streets, const ParameterValues& parameters,
                                 const ObservedData* observed, const ProgressFn& progress) {
  try {
    return buildNetwork(streets, parameters, observed, progress);
  } catch (const Error& e) {
    // A geometric failure of the graph or the blocks names the street file.
    if (e.kind() != Error::Kind::Geometry) throw;
    throw geometryError(streets.path + ": " + e.what());
  }
}

std::int64_t assignToStreetBlocks(ObservedData& observed, std::shared_ptr<const StreetNetwork> network,
                                  const analysis::BoundsRule& rule) {
  analysis::ObservedAnalysis& a = observed.analysis;
  const auto& blocks = network->blocks.blocks;
  std::vector<std::pair<IndexBox, int>> boxes;
  for (std::size_t b = 0; b < blocks.size(); ++b) boxes.push_back({boxOf(blocks[b].shape), static_cast<int>(b)});
  const BoxTree<int> tree(boxes.begin(), boxes.end());
  const std::size_t n = observed.layer.parcels.size();
  std::vector<int> to(n, -1);
  parallelFor(n, [&](std::size_t p) {
    if (a.blockOf[p] < 0) return;  // right of way
    const Polygon& shape = observed.layer.parcels[p].shape;
    std::vector<int> candidates;
    for (auto it = tree.qbegin(bgi::intersects(boxOf(shape))); it != tree.qend(); ++it) {
      candidates.push_back(it->second);
    }
    std::sort(candidates.begin(), candidates.end());
    // Most parcels lie inside one block: the overlap is then the whole parcel.
    const Point inside = interiorPoint(shape);
    int containing = -1, hits = 0;
    for (int b : candidates) {
      if (pointInPolygon(inside, blocks[static_cast<std::size_t>(b)].shape)) {
        containing = b;
        ++hits;
      }
    }
    // A parcel none of whose vertices lies in another block than the one
    // holding its interior point overlaps that one most (it may reach into
    // the street, not across it), but for a corner of another block cut by
    // one of its edges.
    if (hits == 1) {
      bool elsewhere = false;
      for (int b : candidates) {
        if (b == containing) continue;
        for (std::size_t i = 0; i < shape.outer.size() && !elsewhere; ++i) {
          elsewhere = pointInPolygon(shape.outer[i], blocks[static_cast<std::size_t>(b)].shape);
        }
      }
      if (!elsewhere) {
        to[p] = containing;
        return;
      }
    }
    double best = 0;
    for (int b : candidates) {
      const double overlap = geos::intersectionArea(shape, blocks[static_cast<std::size_t>(b)].shape);
      if (overlap > best) {
        best = overlap;
        to[p] = b;
      }
    }
  });
  std::vector<Block> regrouped(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    regrouped[b].id = static_cast<int>(b);
    regrouped[b].parts = {blocks[b].shape};
    regrouped[b].key = blocks[b].key;
  }
  std::int64_t outside = 0;
  for (std::size_t p = 0; p < n; ++p) {
    if (a.blockOf[p] < 0) continue;
    if (to[p] < 0) ++outside;
    a.blockOf[p] = to[p];
    if (to[p] >= 0) regrouped[static_cast<std::size_t>(to[p])].parcels.push_back(static_cast<int>(p));
  }
  a.blocks = std::move(regrouped);
  a.statistics.assign(a.blocks.size(), {});
  a.multipartBlocks = a.clampedAMin = a.clampedWMin = 0;
  for (std::size_t b = 0; b < a.blocks.size(); ++b) {
    const Block& block = a.blocks[b];
    std::vector<double> areas, widths;
    int withAccess = 0;
    for (int p : block.parcels) {
      areas.push_back(a.metrics[static_cast<std::size_t>(p)].area);
      widths.push_back(a.metrics[static_cast<std::size_t>(p)].width);
      withAccess += a.metrics[static_cast<std::size_t>(p)].streetAccess;
    }
    analysis::BlockStatistics s;
    if (block.parcels.empty()) {
      s.meanArea = s.sdArea = s.meanWidth = s.sdWidth = NAN;
      s.aMin = s.aMax = s.wMin = s.wMax = NAN;
      s.streetAccessShare = NAN;
    } else {
      s = analysis::blockStatistics(areas, widths, rule);
      s.streetAccessShare = static_cast<double>(withAccess) / static_cast<double>(block.parcels.size());
    }
    s.blockId = block.id;
    s.blockArea = area(block.parts.front());
    a.clampedAMin += s.aMinClamped;
    a.clampedWMin += s.wMinClamped;
    a.statistics[b] = s;
  }
  observed.streets = std::move(network);
  return outside;
}

ObservedData loadObservedInStreetBlocks(const io::ReadOptions& input, const io::StreetReadOptions* streets,
                                        const ParameterValues& parameters, const ProgressFn& progress) {
  if (!streets) return loadObserved(input, parameters, progress);
  ObservedData data = loadObserved(input, parameters, scaledProgress(progress, 0.0, 0.6));
  auto network = std::make_shared<StreetNetwork>(
      buildStreetNetwork(*streets, parameters, &data, scaledProgress(progress, 0.6, 0.95)));
  StreetNetwork* timed = network.get();
  timed->timings.start("assign parcels");
  data.outsideStreetBlocks = assignToStreetBlocks(data, network, analysis::analysisOptionsFrom(parameters).bounds());
  timed->timings.stop();
  reportProgress(progress, 1.0, "street blocks");
  return data;
}

Table streetBlockTable(const StreetNetwork& network, const ObservedData* observed) {
  Table t;
  t.columns = {{"block_key", Column::Type::String, ""},
               {"area", Column::Type::Real, "m2"},
               {"streets", Column::Type::String, ""},
               {"edge_keys", Column::Type::String, ""},
               {"parcel_count", Column::Type::Integer, ""}};
  for (std::size_t b = 0; b < network.blocks.blocks.size(); ++b) {
    const analysis::StreetBlock& block = network.blocks.blocks[b];
    std::set<std::string> names;
    std::set<Key> edges;
    for (const auto& ring : block.faced) {
      for (int e : ring) {
        if (e < 0) continue;
        const analysis::RoadEdge& edge = network.graph.edges[static_cast<std::size_t>(e)];
        edges.insert(edge.key);
        if (!edge.name.empty()) names.insert(edge.name);
      }
    }
    std::string nameList, keyList;
    for (const auto& s : names) nameList += (nameList.empty() ? "" : "; ") + s;
    for (Key k : edges) keyList += (keyList.empty() ? "" : ",") + keyText(k);
    const std::int64_t count = observed && b < observed->analysis.blocks.size()
                                   ? static_cast<std::int64_t>(observed->analysis.blocks[b].parcels.size())
                                   : -1;
    t.rows.push_back({keyText(block.key), area(block.shape), nameList, keyList, count});
  }
  return t;
}

Table streetNodeTable(const StreetNetwork& network) {
  Table t;
  t.columns = {{"node_key", Column::Type::String, ""}, {"degree", Column::Type::Integer, ""}};
  for (const analysis::RoadNode& n : network.graph.nodes) {
    t.rows.push_back({keyText(n.key), static_cast<std::int64_t>(n.degree)});
  }
  return t;
}

Table streetEdgeTable(const StreetNetwork& network) {
  Table t;
  t.columns = {{"edge_key", Column::Type::String, ""},     {"width", Column::Type::Real, "m"},
               {"width_source", Column::Type::String, ""}, {"kind", Column::Type::String, ""},
               {"name", Column::Type::String, ""},         {"from_node_key", Column::Type::String, ""},
               {"to_node_key", Column::Type::String, ""},  {"length", Column::Type::Real, "m"}};
  for (const analysis::RoadEdge& e : network.graph.edges) {
    const bool given = !e.boundary && !std::isnan(network.layer.streets[static_cast<std::size_t>(e.source)].width);
    const std::string widthSource = e.boundary ? "none" : given ? "given" : "measured or default";
    double length = 0;
    for (std::size_t i = 0; i + 1 < e.line.size(); ++i) {
      length += std::hypot(e.line[i + 1].x - e.line[i].x, e.line[i + 1].y - e.line[i].y);
    }
    t.rows.push_back({keyText(e.key), e.width, widthSource, std::string(e.boundary ? "boundary" : "street"), e.name,
                      keyText(network.graph.nodes[static_cast<std::size_t>(e.from)].key),
                      keyText(network.graph.nodes[static_cast<std::size_t>(e.to)].key), length});
  }
  return t;
}

Json streetRecord(const StreetNetwork& network) {
  const io::StreetReport& r = network.layer.report;
  const analysis::RoadGraphReport& g = network.graph.report;
  Json seconds = Json::object();
  for (const auto& [stage, s] : network.timings.stages()) seconds.set(stage, s);
  return Json::object()
      .set("path", network.layer.path)
      .set("layer", network.layer.layerName)
      .set("crs", network.layer.crs.name)
      .set("frame", network.layer.frame.describe())
      .set("features", r.features)
      .set("null_or_empty", r.nullOrEmpty)
      .set("not_lines", r.nonLinear)
      .set("non_finite_skipped", r.nonFiniteSkipped)
      .set("lines", r.lines)
      .set("lines_with_width", r.withWidth)
      .set("lines_not_noded", r.noNode)
      .set("nodes", static_cast<std::int64_t>(network.graph.nodes.size()))
      .set("edges", static_cast<std::int64_t>(network.graph.edges.size()))
      .set("dead_ends", g.deadEnds)
      .set("endpoints_joined", g.endpointsJoined)
      .set("ends_moved_onto_lines", g.endpointsOnLines)
      .set("duplicate_edges_merged", g.duplicateEdges)
      .set("lines_skipped", g.skipped)
      .set("widths_given", network.widthsGiven)
      .set("widths_measured", network.widthsMeasured)
      .set("widths_default", network.widthsDefault)
      .set("boundary_lines", network.boundaryLines)
      .set("faces", network.blocks.faces)
      .set("faces_above_max_block_area", network.blocks.facesTooLarge)
      .set("pieces_dropped", network.blocks.partsTooSmall)
      .set("blocks", static_cast<std::int64_t>(network.blocks.blocks.size()))
      .set("seconds", seconds);
}

std::vector<std::pair<std::string, io::LayerWrite>> writeStreetLayers(io::OutputDirectory& out,
                                                                      const StreetNetwork& network,
                                                                      const ObservedData* observed) {
  const io::LocalFrame& frame = network.layer.frame;
  const io::CrsInfo& crs = network.layer.crs;
  std::vector<std::vector<Polygon>> outlines;
  for (const analysis::StreetBlock& b : network.blocks.blocks) outlines.push_back({b.shape});
  const io::LayerWrite blocksWritten = io::writePolygonLayer(out.stage("blocks.gpkg"), "blocks", outlines,
                                                             streetBlockTable(network, observed), frame, crs);
  std::vector<Point> nodes;
  for (const analysis::RoadNode& n : network.graph.nodes) nodes.push_back(n.at);
  std::vector<std::vector<Point>> edges;
  for (const analysis::RoadEdge& e : network.graph.edges) edges.push_back(e.line);
  io::writeNetworkLayers(out.stage("streets.gpkg"), nodes, streetNodeTable(network), edges, streetEdgeTable(network),
                         frame, crs);
  std::vector<std::vector<Polygon>> surface;
  for (Polygon& p : analysis::streetSurface(network.graph)) surface.push_back({std::move(p)});
  Table surfaceTable;
  surfaceTable.columns = {{"part", Column::Type::Integer, ""}};
  for (std::size_t i = 0; i < surface.size(); ++i) surfaceTable.rows.push_back({static_cast<std::int64_t>(i)});
  const io::LayerWrite surfaceWritten =
      io::writePolygonLayer(out.stage("street_surface.gpkg"), "surface", surface, surfaceTable, frame, crs);
  return {{"blocks.gpkg", blocksWritten}, {"street_surface.gpkg", surfaceWritten}};
}

namespace {

JobOutcome writeBlocks(io::OutputDirectory& out, const io::StreetReadOptions& streets,
                       const ParameterValues& parameters, const io::ReadOptions* parcels, const ProgressFn& progress) {
  ObservedData observed;
  if (parcels) observed = loadObserved(*parcels, parameters, scaledProgress(progress, 0.0, 0.4));
  const auto shared = std::make_shared<const StreetNetwork>(buildStreetNetwork(
      streets, parameters, parcels ? &observed : nullptr, scaledProgress(progress, parcels ? 0.4 : 0.0, 0.9)));
  const StreetNetwork& network = *shared;
  reportProgress(progress, 0.9, "writing");
  const ObservedData* withParcels = nullptr;
  if (parcels) {
    assignToStreetBlocks(observed, shared, analysis::analysisOptionsFrom(parameters).bounds());
    withParcels = &observed;
  }
  const auto written = writeStreetLayers(out, network, withParcels);
  Json run = runRecord("blocks", parameters);
  run.set("streets", streetRecord(network).set("options", streetOptionsJson(streets)));
  if (parcels) {
    addObservedRecord(run, observed);
  }
  run.set("written", writtenLayersJson(written));
  run.set("outputs",
          Json::array().push("blocks.gpkg").push("streets.gpkg").push("street_surface.gpkg").push("run.json"));
  io::writeJson(out.stage("run.json"), run);
  out.commit();
  reportProgress(progress, 1.0, "writing");
  const analysis::RoadGraphReport& g = network.graph.report;
  std::ostringstream s;
  s << "read " << network.layer.report.lines << " street lines of " << network.layer.path << " ("
    << network.layer.crs.name << ")\n"
    << "  road graph: " << network.graph.nodes.size() << " nodes, " << network.graph.edges.size() << " edges, "
    << g.deadEnds << " dead ends; " << g.endpointsJoined << " endpoints joined, " << g.endpointsOnLines
    << " ends moved onto a line, " << g.duplicateEdges << " duplicate edges merged, " << g.notNoded
    << " lines not noded\n"
    << "  widths: " << network.widthsGiven << " given, " << network.widthsMeasured << " measured from parcels, "
    << network.widthsDefault << " default\n"
    << "  " << network.blocks.blocks.size() << " blocks from " << network.blocks.faces << " faces ("
    << network.blocks.facesTooLarge << " above max-block-area)";
  return {run, s.str()};
}
}  // namespace

JobOutcome runBlocks(const io::StreetReadOptions& streets, const ParameterValues& parameters,
                     const io::ReadOptions* parcels, const std::string& outDir, const ProgressFn& progress) {
  std::vector<std::string> inputs = {streets.path};
  if (parcels) inputs.push_back(parcels->path);
  io::OutputDirectory out(outDir, inputs);
  try {
    return writeBlocks(out, streets, parameters, parcels, progress);
  } catch (const Error& e) {
    throw out.explain(e);
  }
}

}  // namespace parcelscope::pipeline
