#include "parcelscope/pipeline/CompareJob.h"

#include "parcelscope/pipeline/StreetsJob.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <future>
#include <iterator>
#include <limits>
#include <map>
#include <numeric>
#include <optional>

#include "CompareStages.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/io/FileHash.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/CompareSession.h"

namespace parcelscope::pipeline {

using analysis::ComparedMetric;
using analysis::ParcelMetrics;

const std::vector<ParameterDescription>& comparisonParameters() {
  static const std::vector<ParameterDescription> d = {
      integerParameter("bins", "Shared bins of the histograms, in the figures and in the histogram intersection", "", 2,
                       500, 30, "Comparison"),
      realParameter("histogram-quantile",
                    "The bins run from the smallest value to this quantile of both sets pooled; larger values "
                    "count in the last bin",
                    "", 0.5, 1.0, 0.99, "Comparison"),
      realParameter("map-aspect-ratio-max", "Aspect ratio drawn fully green in map_aspect_ratio (1:1 is red)", "", 1.5,
                    100, 5, "Figures"),
      outputOnly(booleanParameter("figures", "Render the figures (needs an X server); no: tables and layers only", true,
                                  "Figures")),
      outputOnly(booleanParameter("spatial-index",
                                  "Give the GeoPackage layers an R-tree spatial index (GIS tools draw large layers "
                                  "faster); no: written faster without one",
                                  true, "Output")),
      outputOnly(integerParameter("figure-width", "Width of every figure", "px", 200, 10000, 1800, "Figures")),
      outputOnly(integerParameter("figure-height", "Height of every figure", "px", 150, 10000, 900, "Figures")),
  };
  return d;
}

std::vector<ParameterDescription> compareParameters() {
  std::vector<ParameterDescription> all = analysis::analysisParameters();
  appendParameters(all, generation::generationParameterDescriptions());
  appendParameters(all, comparisonParameters());
  return all;
}

double compareValue(const CompareRequest& request, const std::string& name) {
  const auto it = request.parameters.find(name);
  if (it != request.parameters.end()) return it->second;
  for (const auto& d : compareParameters()) {
    if (d.name == name) return d.defaultValue;
  }
  for (const auto& d : streetParameters()) {
    if (d.name == name) return d.defaultValue;
  }
  throw std::logic_error("compare: no parameter named " + name);
}

namespace {

double value(const CompareRequest& request, const std::string& name) { return compareValue(request, name); }

double secondsIn(const Timings& t) {
  double s = 0;
  for (const auto& stage : t.stages()) s += stage.second;
  return s;
}

using detail::secondsSince;

std::vector<ParcelMetrics> pick(const std::vector<ParcelMetrics>& all, const std::vector<int>& indices) {
  std::vector<ParcelMetrics> out;
  out.reserve(indices.size());
  for (int i : indices) out.push_back(all[i]);
  return out;
}

}  // namespace

namespace detail {

pipeline::GenerateRequest generateRequest(const CompareRequest& request, const pipeline::ObservedData* observed) {
  pipeline::GenerateRequest g;
  g.input = request.input;
  g.fromParcels = true;
  g.style = request.style;
  g.parameters = request.parameters;
  g.explicitParameters = request.explicitParameters;
  g.observed = observed;
  g.overrides = request.overrides;
  g.overridesById = request.overridesById;
  return g;
}

void requireBlocks(const CompareRequest& request, const pipeline::ObservedData& observed) {
  if (observed.analysis.blocks.empty()) {
    throw inputError(request.input.path +
                     ": no block to compare (no parcel is left once right-of-way parcels "
                     "are set aside)");
  }
}

void checkRequest(const CompareRequest& request) {
  if (request.style != "all") requireStyle(request.style);  // before the input is read
  requireGeneratorParameters(request.parameters);
  for (const auto& d : compareParameters()) {
    const auto it = request.parameters.find(d.name);
    if (it != request.parameters.end()) checkValue(d, it->second);
  }
  for (const auto& d : streetParameters()) {
    const auto it = request.parameters.find(d.name);
    if (it != request.parameters.end()) checkValue(d, it->second);
  }
  // Each side within its range, the two together at most 16 million pixels
  // (4000 x 4000 took 1.6 GB to draw; 10000 x 10000, 8.9 GB and 6 minutes).
  constexpr double kMaxFigurePixels = 16e6;
  const double width = value(request, "figure-width"), height = value(request, "figure-height");
  if (width * height > kMaxFigurePixels) {
    throw usageError("--figure-width " + std::to_string(static_cast<long long>(width)) + " and --figure-height " +
                     std::to_string(static_cast<long long>(height)) +
                     ": a figure of at most 16 million pixels (4000 x 4000) is drawn");
  }
  analysis::parcelQuantity(request.metric);
  if (request.vectorFormat != "svg" && request.vectorFormat != "pdf") {
    throw usageError("--vector " + request.vectorFormat + ": the histograms' vector copy is svg or pdf");
  }
  if (request.parcelsFormat != "gpkg" && request.parcelsFormat != "geojson") {
    throw usageError("--parcels-format " + request.parcelsFormat +
                     ": generated parcels are written as gpkg or geojson");
  }
}

void compareStage(CompareResult& r, const CompareRequest& request, const std::vector<char>* keep) {
  const analysis::ObservedAnalysis& a = r.observed->analysis;
  const int bins = static_cast<int>(value(request, "bins"));
  const double quantile = value(request, "histogram-quantile");
  if (r.observedLots.empty()) {
    std::vector<int> lots;
    for (std::size_t i = 0; i < a.blockOf.size(); ++i) {
      if (a.blockOf[i] >= 0) lots.push_back(static_cast<int>(i));
    }
    r.observedLots = pick(a.metrics, lots);
  }
  // Generated entries go to the observed block of their key; a block of the
  // source that no observed block matches (no observed parcels) is compared
  // as such, after the observed ones, with an empty observed side.
  std::map<Key, std::size_t> observedBlock;  // made on first need: blocks from the observed parcels match by id
  std::vector<std::vector<int>> generatedIn(a.blocks.size());
  std::vector<std::size_t> blockOfEntry(r.generated.blocks.size());
  struct Unmatched {
    std::int64_t id;
    Key key;
    double area = 0;
    std::vector<int> parcels;
  };
  std::vector<Unmatched> unmatched;
  std::map<Key, std::size_t> unmatchedOf;
  for (std::size_t k = 0; k < r.generated.blocks.size(); ++k) {
    const Key key = k < r.generated.blockKeys.size() ? r.generated.blockKeys[k] : 0;
    const std::int64_t id = r.generated.blockIds[k];
    std::size_t b = a.blocks.size();
    if (id >= 0 && id < static_cast<std::int64_t>(a.blocks.size()) && a.blocks[id].key == key) {
      b = static_cast<std::size_t>(id);  // blocks made from the observed parcels themselves
    } else {
      if (observedBlock.empty()) {
        for (std::size_t o = 0; o < a.blocks.size(); ++o) observedBlock.emplace(a.blocks[o].key, o);
      }
      if (const auto found = observedBlock.find(key); found != observedBlock.end()) b = found->second;
    }
    // Land a style left unassigned is no parcel: it is counted, not compared.
    const std::vector<int> assigned = r.generated.assignedOf(r.generated.blocks[k].parcels);
    if (b < a.blocks.size()) {
      blockOfEntry[k] = b;
      generatedIn[b].insert(generatedIn[b].end(), assigned.begin(), assigned.end());
      continue;
    }
    const auto [it, added] = unmatchedOf.emplace(key, unmatched.size());
    if (added) unmatched.push_back({id, key, 0.0, {}});
    Unmatched& u = unmatched[it->second];
    for (const Polygon& part : r.generated.blocks[k].parts) u.area += area(part);
    u.parcels.insert(u.parcels.end(), assigned.begin(), assigned.end());
    blockOfEntry[k] = a.blocks.size() + it->second;
  }
  if (!r.observedSides) {
    auto sides = std::make_shared<std::vector<analysis::PreparedSet>>(a.blocks.size() + 1);
    // The city's side (the largest item, last in the vector) first.
    parallelFor(sides->size(), [&](std::size_t t) {
      const std::size_t b = t == 0 ? a.blocks.size() : t - 1;
      (*sides)[b] = analysis::prepareSet(b < a.blocks.size() ? pick(a.metrics, a.blocks[b].parcels) : r.observedLots);
    });
    r.observedSides = std::move(sides);
  }
  const std::vector<analysis::PreparedSet>& observedSides = *r.observedSides;
  // Street access of parcels not measured yet is not known: NaN, not the 0 they hold.
  constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();
  std::vector<char> pending(a.blocks.size() + unmatched.size(), 0);
  for (std::size_t k : r.generated.contextPending) pending[blockOfEntry[k]] = 1;
  const bool reuse = keep && unmatched.empty() && keep->size() == a.blocks.size() && r.blocks.size() == a.blocks.size();
  if (!reuse) r.blocks.assign(a.blocks.size(), {});
  std::vector<std::size_t> todo;
  for (std::size_t b = 0; b < a.blocks.size(); ++b) {
    if (!reuse || !(*keep)[b]) todo.push_back(b);
  }
  // The city-wide comparison (the largest item) first, beside the blocks.
  parallelFor(todo.size() + 1, [&](std::size_t t) {
    if (t == 0) {
      std::vector<int> all;
      if (!r.generated.unassigned.empty()) {
        all.resize(r.generated.parcels.size());
        for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
      }
      r.city = analysis::compareSets(
          observedSides.back(),
          analysis::prepareSet(r.generated.unassigned.empty() ? r.generated.metrics
                                                              : pick(r.generated.metrics, r.generated.assignedOf(all))),
          bins, quantile, &r.histograms);
      r.histogramBins = bins;
      r.histogramQuantile = quantile;
      return;
    }
    const std::size_t b = todo[t - 1];
    analysis::BlockComparison& c = r.blocks[b];
    c.blockId = a.blocks[b].id;
    c.blockKey = a.blocks[b].key;
    c.blockArea = a.statistics[b].blockArea;
    const analysis::PreparedSet generated = analysis::prepareSet(pick(r.generated.metrics, generatedIn[b]));
    c.comparison = analysis::compareSets(observedSides[b], generated, bins, quantile);
    if (pending[b]) c.comparison.generated.streetAccessShare = kNotMeasured;
  });
  if (!unmatched.empty()) {
    const analysis::PreparedSet none = analysis::prepareSet({});
    r.blocks.resize(a.blocks.size() + unmatched.size());
    parallelFor(unmatched.size(), [&](std::size_t u) {
      analysis::BlockComparison& c = r.blocks[a.blocks.size() + u];
      c.blockId = unmatched[u].id;
      c.blockKey = unmatched[u].key;
      c.blockArea = unmatched[u].area;
      c.comparison = analysis::compareSets(none, analysis::prepareSet(pick(r.generated.metrics, unmatched[u].parcels)),
                                           bins, quantile);
      if (pending[a.blocks.size() + u]) c.comparison.generated.streetAccessShare = kNotMeasured;
    });
  }
  if (!r.generated.contextPending.empty()) r.city.generated.streetAccessShare = kNotMeasured;
}

}  // namespace detail

CompareResult compare(const CompareRequest& request, const ProgressFn& progress) {
  detail::checkRequest(request);
  return compare(request,
                 std::make_shared<const pipeline::ObservedData>(
                     pipeline::loadObservedInStreetBlocks(request.input, request.streets ? &*request.streets : nullptr,
                                                          request.parameters, scaledProgress(progress, 0.0, 0.45))),
                 scaledProgress(progress, 0.45, 1.0));
}

CompareResult compare(const CompareRequest& request, std::shared_ptr<const pipeline::ObservedData> observed,
                      const ProgressFn& progress, std::vector<PremadeBlock>* premade, const OutcomeLibrary* reusable,
                      OutcomeLibrary* keep) {
  detail::checkRequest(request);
  CompareResult r;
  r.observed = std::move(observed);
  const analysis::ObservedAnalysis& a = r.observed->analysis;
  detail::requireBlocks(request, *r.observed);
  pipeline::GenerateRequest g = detail::generateRequest(request, r.observed.get());
  g.premade = premade;
  g.reusable = reusable;
  g.keep = keep;
  r.generated = pipeline::generate(g, scaledProgress(progress, 0.0, 0.85));

  // Both sets measured with the same metrics; compared block by block, in parallel.
  reportProgress(progress, 0.85, "comparing");
  const auto compareStart = std::chrono::steady_clock::now();
  detail::compareStage(r, request);
  const double measure = r.generated.timings.stages().empty() ? 0.0 : r.generated.timings.stages().back().second;
  r.seconds = {{"read", secondsIn(r.observed->layer.timings)},
               {"blocks", secondsIn(a.timings)},
               {"generate", secondsIn(r.generated.timings) - measure},
               {"metrics", measure + secondsSince(compareStart)}};
  if (r.observed->streets)
    r.seconds.insert(r.seconds.begin() + 2, {"streets", secondsIn(r.observed->streets->timings)});
  reportProgress(progress, 1.0, "comparing");
  return r;
}

namespace {

// The Yang et al. 2013 `undesirable` flag after the columns of a parcel
// table whose parcel_id column indexes `metrics`.
RowSource withUndesirable(const RowSource& rows, const std::vector<ParcelMetrics>& metrics) {
  std::size_t id = 0;
  while (rows.columns[id].name != "parcel_id") ++id;
  return rows.with({"undesirable", Column::Type::Integer, ""},
                   [&metrics, id](std::size_t, const std::vector<Value>& row) -> Value {
                     return std::int64_t(analysis::isUndesirable(metrics[std::get<std::int64_t>(row[id])]));
                   });
}

// observed_parcels.csv and generated_parcels.csv (the latter also the
// attributes of parcels.gpkg), made row by row as they are written.
RowSource observedRowsOf(const CompareResult& r) {
  return withUndesirable(analysis::parcelRows(r.observed->layer.parcels, r.observed->analysis),
                         r.observed->analysis.metrics);
}

RowSource generatedRowsOf(const CompareResult& r, std::vector<int>* parcelOfRow = nullptr) {
  return withUndesirable(pipeline::generatedParcelRows(r.generated, parcelOfRow), r.generated.metrics);
}

// The geometry of each row of generatedRowsOf, from its parcelOfRow.
io::PolygonSource generatedShapes(const CompareResult& r, const std::vector<int>& parcelOfRow) {
  return [&r, &parcelOfRow](std::size_t row, std::vector<Polygon>& parts) {
    parts.push_back(r.generated.parcels[static_cast<std::size_t>(parcelOfRow[row])]);
  };
}

Json summaryJson(const analysis::SetSummary& s) {
  return Json::object()
      .set("parcels", s.parcels)
      .set("mean_area", s.meanArea)
      .set("sd_area", s.sdArea)
      .set("mean_width", s.meanWidth)
      .set("sd_width", s.sdWidth)
      .set("mean_aspect_ratio", s.meanAspectRatio)
      .set("street_access_share", s.streetAccessShare)
      .set("mean_p_angle", s.meanPAngle)
      .set("mean_p_area", s.meanPArea)
      .set("undesirable_share", s.undesirableShare);
}

}  // namespace

int blockAt(const CompareResult& r, const Point& p) {
  const auto& blocks = r.observed->analysis.blocks;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (const Polygon& part : blocks[b].parts) {
      const Box box = bounds(part);
      if (p.x < box.minX || p.x > box.maxX || p.y < box.minY || p.y > box.maxY) continue;
      if (pointInPolygon(p, part)) return static_cast<int>(b);
    }
  }
  return -1;
}

std::vector<std::pair<std::string, Table>> comparisonTables(const CompareResult& r) {
  std::vector<std::pair<std::string, Table>> tables;
  tables.emplace_back("observed_parcels.csv", observedRowsOf(r).table());
  tables.emplace_back("generated_parcels.csv", generatedRowsOf(r).table());
  tables.emplace_back("blocks.csv", analysis::blockComparisonTable(r.blocks));
  tables.emplace_back("summary.csv", analysis::summaryTable(r.city));
  tables.emplace_back("distances.csv", analysis::distanceTable(r.city));
  return tables;
}

void exportParcels(const CompareResult& r, const std::string& path, const std::vector<std::string>& inputs) {
  io::StagedFile file(path, inputs);
  std::vector<int> order;
  const RowSource table = generatedRowsOf(r, &order);
  io::writePolygonLayer(file.path(), "parcels", generatedShapes(r, order), table, r.observed->layer.frame,
                        r.observed->layer.crs);
  file.commit();
}

void exportTables(const CompareResult& r, const std::string& folder, const std::vector<std::string>& inputs) {
  if (!std::filesystem::is_directory(folder)) throw usageError(folder + ": not a folder");
  for (const auto& [name, table] : comparisonTables(r)) {
    io::StagedFile file((std::filesystem::path(folder) / name).string(), inputs);
    io::writeCsv(file.path(), table);
    file.commit();
  }
}

void exportSession(const CompareRequest& request, const std::string& path) {
  io::StagedFile file(path, {request.input.path});
  io::writeJson(file.path(), sessionJson(request));
  file.commit();
}

namespace {
JobOutcome writeCompare(io::OutputDirectory& out, const CompareRequest& request, const ProgressFn& progress,
                        const FigureRenderer* renderer, std::chrono::steady_clock::time_point started,
                        const PreparedObserved* prepared) {
  const bool figures = value(request, "figures") != 0;
  const bool spatialIndex = value(request, "spatial-index") != 0;
  // run.json's hash of the input, on a thread of its own while the input is
  // read (0.4 s for a 150 MB file).
  std::error_code ec;
  const bool regular = std::filesystem::is_regular_file(request.input.path, ec);
  std::future<std::string> inputHash = std::async(
      std::launch::async, [&request, regular] { return regular ? io::sha256File(request.input.path) : std::string(); });
  const auto result = std::make_shared<const CompareResult>(
      prepared ? compare(request, prepared->data, scaledProgress(progress, 0.0, 0.8), prepared->premade.get())
               : compare(request, scaledProgress(progress, 0.0, 0.8)));
  const CompareResult& r = *result;
  const analysis::ObservedAnalysis& a = r.observed->analysis;

  reportProgress(progress, 0.8, "writing");
  const auto writeStart = std::chrono::steady_clock::now();
  const std::string parcelsFile = "parcels." + request.parcelsFormat;
  std::vector<std::string> outputs = {parcelsFile,  "blocks.gpkg", "observed_parcels.csv", "generated_parcels.csv",
                                      "blocks.csv", "summary.csv", "distances.csv"};
  // The two layers (SQLite inserts, one thread each) are written while this
  // thread formats and writes the tables.
  const Table blocks = analysis::blockComparisonTable(r.blocks);
  const std::string blocksCsv = out.stage("blocks.csv"), blocksGpkg = out.stage("blocks.gpkg");
  std::future<io::LayerWrite> blockWriting = std::async(std::launch::async, [&] {
    // Outlines made by the shards of the run come ready to write.
    const std::vector<io::FileGeometry>& made = r.observed->blocksWritten;
    if (a.blocks.size() != blocks.rows.size()) throw std::logic_error("compare: one outline per row of blocks.csv");
    return io::writePolygonLayer(
        blocksGpkg, "blocks", [&a](std::size_t b, std::vector<Polygon>& parts) { parts = a.blocks[b].parts; },
        RowSource::of(blocks), r.observed->layer.frame, r.observed->layer.crs, spatialIndex,
        [&made](std::size_t b) { return b < made.size() ? &made[b] : nullptr; });
  });
  std::vector<int> order;
  const RowSource generatedTable = generatedRowsOf(r, &order);
  const std::string parcelsGpkg = out.stage(parcelsFile);
  std::future<io::LayerWrite> parcelWriting = std::async(std::launch::async, [&] {
    // Parcels made by the shards of the run come ready to write.
    const io::ReadyGeometry ready = [&r, &order](std::size_t row) -> const io::FileGeometry* {
      if (r.generated.written.empty()) return nullptr;
      const io::FileGeometry& g = r.generated.written[static_cast<std::size_t>(order[row])];
      return g.wkb.empty() ? nullptr : &g;
    };
    return io::writePolygonLayer(parcelsGpkg, "parcels", generatedShapes(r, order), generatedTable,
                                 r.observed->layer.frame, r.observed->layer.crs, spatialIndex, ready);
  });
  io::writeCsv(blocksCsv, blocks);
  io::writeCsv(out.stage("generated_parcels.csv"), generatedTable);
  io::writeCsv(out.stage("observed_parcels.csv"), observedRowsOf(r));
  const io::LayerWrite parcelsWritten = parcelWriting.get();
  const io::LayerWrite blocksWritten = blockWriting.get();
  io::writeCsv(out.stage("summary.csv"), analysis::summaryTable(r.city));
  io::writeCsv(out.stage("distances.csv"), analysis::distanceTable(r.city));
  const double writeSeconds = secondsSince(writeStart);

  double figureSeconds = 0;
  if (figures) {
    reportProgress(progress, 0.85, "figures");
    const auto figureStart = std::chrono::steady_clock::now();
    const auto written = renderer->draw(
        r, request, [&](const std::string& name) { return out.stage(name); }, scaledProgress(progress, 0.85, 0.95));
    outputs.insert(outputs.end(), written.begin(), written.end());
    figureSeconds = secondsSince(figureStart);
  }
  outputs.push_back("summary.json");
  outputs.push_back("run.json");

  Json timing = Json::object();
  for (const auto& [stage, s] : r.seconds) timing.set(stage, s);
  timing.set("write", writeSeconds).set("figures", figureSeconds).set("total", secondsSince(started));
  Json ks = Json::object(), wasserstein = Json::object(), intersection = Json::object();
  for (ComparedMetric m : analysis::kComparedMetrics) {
    ks.set(analysis::metricName(m), r.city.distances(m).ks);
    wasserstein.set(analysis::metricName(m), r.city.distances(m).wasserstein);
    intersection.set(analysis::metricName(m), r.city.distances(m).intersection);
  }
  Json generatedSummary = summaryJson(r.city.generated);
  generatedSummary.set("oversize", r.generated.oversize).set("blocks_failed", r.generated.failedBlocks);
  const Json summary = Json::object()
                           .set("blocks", static_cast<std::int64_t>(a.blocks.size()))
                           .set("style", request.style)
                           .set("seed", static_cast<std::int64_t>(r.generated.seed))
                           .set("observed", summaryJson(r.city.observed))
                           .set("generated", generatedSummary)
                           .set("ks", ks)
                           .set("wasserstein", wasserstein)
                           .set("histogram_intersection", intersection)
                           .set("timing_s", timing);
  io::writeJson(out.stage("summary.json"), summary);

  Json given = Json::array();
  for (const auto& name : request.explicitParameters) given.push(name);
  Json run = runRecord("compare", request.parameters)
                 .set("style", request.style)
                 .set("seed", static_cast<std::int64_t>(r.generated.seed))
                 .set("vtk", figures ? Json(renderer->version) : Json())
                 .set("parameters_given", given)
                 .set("session", sessionJson(withAbsolutePaths(request)));  // read from its own folder
  addObservedRecord(run, *r.observed);
  if (prepared) {
    run.set("ranks", prepared->ranks)
        .set("shards", prepared->shards)
        .set("block_entries_generated_in_shards", r.generated.premadeBlocks);
  }
  if (r.observed->streets) {
    run.set("streets",
            streetRecord(*r.observed->streets).set("lots_outside_street_blocks", r.observed->outsideStreetBlocks));
  }
  run.set(
      "input_file",
      Json::object()
          .set("path", request.input.path)
          .set("layer", request.input.layer)
          .set("where", request.input.where)
          .set("crs_override", request.input.crsOverride)
          .set("bytes",
               regular ? Json(static_cast<std::int64_t>(std::filesystem::file_size(request.input.path, ec))) : Json())
          .set("sha256", regular ? Json(inputHash.get()) : Json()));
  Json failures = Json::array();
  for (const auto& f : r.generated.failures) failures.push(f);
  run.set("generated", Json::object()
                           .set("blocks_subdivided", static_cast<std::int64_t>(r.generated.blocks.size()))
                           .set("blocks_failed", r.generated.failedBlocks)
                           .set("parcels", static_cast<std::int64_t>(r.generated.parcels.size()))
                           .set("parcels_oversize", r.generated.oversize)
                           .set("parcels_without_street_access", r.generated.withoutAccess)
                           .set("unassigned_parcels", r.generated.unassignedParcels)
                           .set("unassigned_area_m2", r.generated.unassignedArea)
                           .set("blocks_with_target_count", r.generated.blocksWithTarget)
                           .set("blocks_at_target_count", r.generated.blocksAtTarget)
                           .set("per_block_bounds_clamped", r.generated.clampedBounds)
                           .set("blocks_by_template", variantCounts(r.generated.blocksByVariant))
                           .set("failures", failures));
  run.set("written", writtenLayersJson({{parcelsFile, parcelsWritten}, {"blocks.gpkg", blocksWritten}}));
  run.set("timing_s", timing);
  Json outputList = Json::array();
  for (const auto& o : outputs) outputList.push(o);
  run.set("outputs", outputList);
  io::writeJson(out.stage("run.json"), run);

  reportProgress(progress, 0.99, "writing");  // a last chance to cancel before anything appears
  out.commit();
  reportProgress(progress, 1.0, "writing");

  char line[512];
  std::snprintf(line, sizeof line,
                "\n%zu blocks: %lld observed parcels, %lld procedural (%s, seed %llu; %lld oversize, %lld blocks "
                "refused)\n  KS area %.3f, width %.3f, aspect ratio %.3f; W1 area %.1f m2, width %.2f m\n"
                "  undesirable share observed %.3f, procedural %.3f; %.1f s",
                a.blocks.size(), static_cast<long long>(r.city.observed.parcels),
                static_cast<long long>(r.city.generated.parcels), request.style.c_str(),
                static_cast<unsigned long long>(r.generated.seed), static_cast<long long>(r.generated.oversize),
                static_cast<long long>(r.generated.failedBlocks), r.city.area.ks, r.city.width.ks,
                r.city.aspectRatio.ks, r.city.area.wasserstein, r.city.width.wasserstein,
                r.city.observed.undesirableShare, r.city.generated.undesirableShare, secondsSince(started));
  std::string told = summarize(*r.observed) + line;
  if (r.generated.clampedBounds > 0) told += "\n  " + clampedBoundsNote(r.generated.clampedBounds);
  return {run, told, result};
}

}  // namespace

std::vector<std::string> inputPaths(const CompareRequest& request) {
  std::vector<std::string> paths = {request.input.path};
  if (request.streets) paths.push_back(request.streets->path);
  paths.insert(paths.end(), request.readFrom.begin(), request.readFrom.end());
  return paths;
}

JobOutcome runCompare(const CompareRequest& request, const std::string& outDir, const ProgressFn& progress,
                      const FigureRenderer* renderer, const PreparedObserved* prepared) {
  const auto started = std::chrono::steady_clock::now();
  const bool figures = value(request, "figures") != 0;
  if (figures && !renderer) throw usageError("compare: this program draws no figures (use --figures 0)");
  if (figures && renderer->check) renderer->check();  // before the long work, not after it
  io::OutputDirectory out(outDir, inputPaths(request));
  try {
    return writeCompare(out, request, progress, renderer, started, prepared);
  } catch (const Error& e) {
    throw out.explain(e);  // a writer's error names --out, not the staging folder, with its cause
  }
}

}  // namespace parcelscope::pipeline
