#include "parcelscope/pipeline/StatsJob.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <utility>

#include "parcelscope/core/Error.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"

#ifndef PARCELSCOPE_VERSION
#define PARCELSCOPE_VERSION "unknown"
#endif

namespace parcelscope::pipeline {

using namespace analysis;

std::string version() { return PARCELSCOPE_VERSION; }

ObservedData loadObserved(const io::ReadOptions& input, const ParameterValues& parameters, const ProgressFn& progress) {
  ObservedData data;
  data.layer = io::readParcels(input, scaledProgress(progress, 0.0, 0.4));
  data.analysis =
      analyseParcels(data.layer.parcels, analysisOptionsFrom(parameters), scaledProgress(progress, 0.4, 1.0));
  return data;
}

Json runRecord(const std::string& command, const ParameterValues& parameters) {
  Json params = Json::object();
  for (const auto& [name, value] : parameters) params.set(name, value);
  return Json::object()
      .set("tool", "parcelscope")
      .set("version", version())
      .set("command", command)
      .set("gdal", io::gdalVersion())
      .set("parameters", params);
}

void addObservedRecord(Json& record, const ObservedData& data) {
  const io::ParcelLayer& l = data.layer;
  const io::CleaningReport& r = l.report;
  Json input = Json::object()
                   .set("path", l.path)
                   .set("layer", l.layerName)
                   .set("crs", l.crs.name)
                   .set("crs_assumed", l.crs.assumedLonLat)
                   .set("crs_overridden", l.crs.overridden)
                   .set("local_frame", l.frame.describe());
  std::int64_t byHoles = 0, byShape = 0;
  for (auto w : data.analysis.rightOfWay) {
    byHoles += w == RightOfWay::HolesHoldParcels;
    byShape += w == RightOfWay::NetworkShape;
  }
  Json counts = Json::object()
                    .set("features", r.features)
                    .set("null_or_empty_skipped", r.nullOrEmpty)
                    .set("non_polygonal_skipped", r.nonPolygonal)
                    .set("non_polygonal_parts_dropped", r.nonPolygonalParts)
                    .set("non_finite_skipped", r.nonFiniteSkipped)
                    .set("multipart_features_split", r.multipartFeatures)
                    .set("parcels_from_multipart", r.partsFromMultipart)
                    .set("parcels_with_holes", r.withHoles)
                    .set("invalid_repaired", r.invalidRepaired)
                    .set("invalid_skipped", r.invalidSkipped)
                    .set("degenerate_parts_skipped", r.degenerateSkipped)
                    .set("duplicates_collapsed", r.duplicatesCollapsed)
                    .set("duplicate_stacks", r.duplicateStacks)
                    .set("parcels", r.parcels)
                    .set("right_of_way", data.analysis.rightOfWayCount)
                    .set("right_of_way_holes_hold_parcels", byHoles)
                    .set("right_of_way_network_shape", byShape)
                    .set("blocks", static_cast<std::int64_t>(data.analysis.blocks.size()))
                    .set("multipart_blocks", data.analysis.multipartBlocks)
                    .set("a_min_clamped", data.analysis.clampedAMin)
                    .set("w_min_clamped", data.analysis.clampedWMin);
  Json seconds = Json::object();
  for (const auto* t : {&data.layer.timings, &data.analysis.timings}) {
    for (const auto& [stage, s] : t->stages()) seconds.set(stage, s);
  }
  record.set("input", input).set("counts", counts).set("seconds", seconds);
}

namespace {
// Lon/lat input is measured in one transverse Mercator centred on the layer:
// its scale grows with the distance x from the central meridian, areas by
// about (x / R)^2. The largest such error over the parcels, and that x.
std::pair<double, double> frameAreaError(const io::ParcelLayer& layer) {
  if (!layer.frame.isGeographic()) return {0, 0};
  double farthest = 0;
  for (const Parcel& p : layer.parcels) {
    const Box b = bounds(p.shape.outer);
    farthest = std::max({farthest, std::fabs(b.minX), std::fabs(b.maxX)});
  }
  const double r = farthest / 6371008.8;
  return {r * r, farthest};
}
}  // namespace

std::string summarize(const ObservedData& data) {
  const io::CleaningReport& r = data.layer.report;
  const ObservedAnalysis& a = data.analysis;
  std::ostringstream s;
  s << "read " << r.features << " features of " << data.layer.path << " (" << data.layer.crs.name << ")\n"
    << "  " << r.parcels << " parcels: " << r.invalidRepaired << " repaired, " << r.multipartFeatures
    << " multipart features split into " << r.partsFromMultipart << " parcels, " << r.duplicatesCollapsed
    << " duplicates collapsed into " << r.duplicateStacks << " stacks\n"
    << "  skipped: " << r.nullOrEmpty << " null or empty, " << r.nonPolygonal << " not polygons, " << r.nonFiniteSkipped
    << " with non-finite coordinates, " << r.invalidSkipped << " beyond repair, " << r.degenerateSkipped
    << " degenerate parts\n"
    << "  " << a.rightOfWayCount << " right-of-way parcels kept out of blocks\n"
    << "  " << a.blocks.size() << " blocks (" << a.clampedAMin << " with A_min clamped, " << a.clampedWMin
    << " with W_min clamped)";
  if (const auto [error, x] = frameAreaError(data.layer); error > 0.001) {
    s << "\n  warning: lon/lat measured in one transverse Mercator centred on the layer: areas up to "
      << std::setprecision(2) << 100 * error << " % too large " << std::setprecision(6) << std::round(x / 1000)
      << " km from its centre line; reproject so wide a layer to an equal-area CRS, or split it";
  }
  if (data.streets) {
    s << "\n  " << data.outsideStreetBlocks << " of " << (r.parcels - a.rightOfWayCount)
      << " parcels lie in no street block (left out of the comparison)";
  }
  return s.str();
}

Json writtenLayersJson(const std::vector<std::pair<std::string, io::LayerWrite>>& layers) {
  Json written = Json::object();
  for (const auto& [file, w] : layers) {
    written.set(file, Json::object().set("features", w.features).set("repaired", w.repaired).set("emptied", w.emptied));
  }
  return written;
}

namespace {
JobOutcome writeStats(io::OutputDirectory& out, const io::ReadOptions& input, const ParameterValues& parameters,
                      const ProgressFn& progress) {
  ObservedData data = loadObserved(input, parameters, scaledProgress(progress, 0.0, 0.9));

  reportProgress(progress, 0.9, "writing");
  io::writeCsv(out.stage("parcels.csv"), parcelTable(data.layer.parcels, data.analysis));
  const Table blocks = blockTable(data.analysis);
  io::writeCsv(out.stage("blocks.csv"), blocks);
  std::vector<std::vector<Polygon>> outlines;
  for (const Block& b : data.analysis.blocks) outlines.push_back(b.parts);
  const io::LayerWrite written =
      io::writePolygonLayer(out.stage("blocks.gpkg"), "blocks", outlines, blocks, data.layer.frame, data.layer.crs);

  Json run = runRecord("stats", parameters);
  addObservedRecord(run, data);
  run.set("written", writtenLayersJson({{"blocks.gpkg", written}}));
  run.set("outputs", Json::array().push("parcels.csv").push("blocks.csv").push("blocks.gpkg").push("run.json"));
  io::writeJson(out.stage("run.json"), run);
  out.commit();
  reportProgress(progress, 1.0, "writing");
  return {run, summarize(data)};
}

}  // namespace

JobOutcome runStats(const io::ReadOptions& input, const ParameterValues& parameters, const std::string& outDir,
                    const ProgressFn& progress) {
  io::OutputDirectory out(outDir, {input.path});
  try {
    return writeStats(out, input, parameters, progress);
  } catch (const Error& e) {
    throw out.explain(e);  // a writer's error names --out, not the staging folder, with its cause
  }
}

}  // namespace parcelscope::pipeline
