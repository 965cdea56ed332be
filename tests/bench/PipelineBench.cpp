// Benchmarks. 1) The stats pipeline (read + project + clean + metrics + blocks) on
// cambridge_ma against a plain GDAL read of the same file (every feature and its
// geometry fetched). Target: the pipeline within 3x of the plain read.
// 2) OBB subdivision of every block. 3) The whole `compare` job, stage by stage
// (figures only when an X server answers: run under scripts/with-xvfb.sh).
// 4) The application's session update and its procedural view's geometry.
// 5) Each style's time per block.
//   build/release/tests/bench/parcelscope_bench
//   scripts/with-xvfb.sh build/release/tests/bench/parcelscope_bench --benchmark_filter=Compare
#include <benchmark/benchmark.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <cpl_json.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/CompareSession.h"
#include "parcelscope/pipeline/GenerateJob.h"
#include "parcelscope/pipeline/StatsJob.h"
#include "parcelscope/pipeline/StreetEditor.h"
#include "parcelscope/pipeline/StreetsJob.h"
#include "parcelscope/viz/CompareFigures.h"
#include "parcelscope/viz/Scenes.h"

namespace {

const std::string kCambridge =
    std::string(PARCELSCOPE_SHARED_DATASETS) + "/cambridge_ma/ASSESSING_ParcelsFY2014.topojson";

bool haveData(benchmark::State& state) {
  if (std::filesystem::exists(kCambridge)) return true;
  state.SkipWithError(("shared dataset not found: " + kCambridge).c_str());
  return false;
}

void PlainGdalRead(benchmark::State& state) {
  if (!haveData(state)) return;
  GDALAllRegister();
  std::int64_t features = 0;
  for (auto _ : state) {
    GDALDatasetUniquePtr ds(GDALDataset::Open(kCambridge.c_str(), GDAL_OF_VECTOR));
    OGRLayer* layer = ds->GetLayer(0);
    std::int64_t n = 0;
    for (auto& f : *layer) {
      benchmark::DoNotOptimize(f->GetGeometryRef());
      ++n;
    }
    features = n;
  }
  state.counters["features"] = static_cast<double>(features);
  state.counters["features_per_s"] =
      benchmark::Counter(static_cast<double>(features), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(PlainGdalRead)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

void StatsPipeline(benchmark::State& state) {
  if (!haveData(state)) return;
  const auto params = parcelscope::defaultValues(parcelscope::analysis::analysisParameters());
  parcelscope::io::ReadOptions in;
  in.path = kCambridge;
  std::size_t parcels = 0, blocks = 0;
  for (auto _ : state) {
    const auto d = parcelscope::pipeline::loadObserved(in, params);
    parcels = d.layer.parcels.size();
    blocks = d.analysis.blocks.size();
  }
  state.counters["parcels"] = static_cast<double>(parcels);
  state.counters["blocks"] = static_cast<double>(blocks);
  state.counters["parcels_per_s"] =
      benchmark::Counter(static_cast<double>(parcels), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(StatsPipeline)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

// The blocks of an analysed input and their plans under `style` with default
// parameters, as generate() makes them (per-block bounds, each block's seed,
// street widths for the skeleton styles).
std::pair<parcelscope::pipeline::BlockInputs, std::vector<parcelscope::pipeline::BlockPlan>> plannedBlocks(
    const parcelscope::pipeline::ObservedData& observed, const std::string& style) {
  parcelscope::pipeline::GenerateRequest request;
  request.fromParcels = true;
  request.observed = &observed;
  request.style = style;
  request.parameters = parcelscope::defaultValues(parcelscope::generation::generationParameterDescriptions());
  auto inputs = parcelscope::pipeline::prepareBlocks(request);
  if (style != "obb") parcelscope::pipeline::streetWidthsOf(inputs);
  auto plans = parcelscope::pipeline::planBlocks(request, inputs);
  return {std::move(inputs), std::move(plans)};
}

// OBB subdivision of every cambridge_ma block with its own derived bounds
// (Vanegas et al. 2012 report 1-10 ms per block after an edit). Single thread.
void ObbSubdivisionPerBlock(benchmark::State& state) {
  if (!haveData(state)) return;
  parcelscope::io::ReadOptions in;
  in.path = kCambridge;
  const auto d =
      parcelscope::pipeline::loadObserved(in, parcelscope::defaultValues(parcelscope::analysis::analysisParameters()));
  const auto [inputs, plans] = plannedBlocks(d, "obb");
  std::size_t blocks = 0, parcels = 0;
  for (auto _ : state) {
    blocks = parcels = 0;
    for (std::size_t k = 0; k < inputs.entries.size(); ++k) {
      parcels += parcelscope::generation::subdivideObb(inputs.entries[k].shape, plans[k].bounds(), plans[k].seed)
                     .parcels.size();
      ++blocks;
    }
  }
  state.counters["blocks"] = static_cast<double>(blocks);
  state.counters["parcels"] = static_cast<double>(parcels);
  state.counters["blocks_per_s"] =
      benchmark::Counter(static_cast<double>(blocks), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(ObbSubdivisionPerBlock)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

// Planning every cambridge_ma block (auto style: per-block bounds, overrides,
// the style's values, the seed from the block key), as each session update
// does before it knows which blocks changed.
void PlanBlocks(benchmark::State& state) {
  if (!haveData(state)) return;
  parcelscope::io::ReadOptions in;
  in.path = kCambridge;
  const auto d =
      parcelscope::pipeline::loadObserved(in, parcelscope::defaultValues(parcelscope::analysis::analysisParameters()));
  parcelscope::pipeline::GenerateRequest request;
  request.fromParcels = true;
  request.observed = &d;
  request.style = "auto";
  request.parameters = parcelscope::defaultValues(parcelscope::generation::generationParameterDescriptions());
  const auto inputs = parcelscope::pipeline::prepareBlocks(request);
  std::size_t plans = 0;
  for (auto _ : state) plans = parcelscope::pipeline::planBlocks(request, inputs).size();
  state.counters["blocks"] = static_cast<double>(plans);
}
BENCHMARK(PlanBlocks)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// The road graph and street blocks of cambridge_ma's 2,614 centre lines (lines
// read once, outside the loop; widths the default). Target: at most 0.5 s.
void StreetGraphAndBlocks(benchmark::State& state) {
  const std::string path = std::string(PARCELSCOPE_SHARED_DATASETS) + "/cambridge_ma/TRANS_Centerlines.geojson";
  if (!std::filesystem::exists(path)) {
    state.SkipWithError(("shared dataset not found: " + path).c_str());
    return;
  }
  parcelscope::io::StreetReadOptions options;
  options.path = path;
  const auto layer = parcelscope::io::readStreets(options);
  std::vector<parcelscope::analysis::StreetLine> lines;
  for (const auto& f : layer.streets) lines.push_back({f.line, f.width, f.name, f.noNode, f.key});
  std::size_t blocks = 0, edges = 0;
  for (auto _ : state) {
    auto graph = parcelscope::analysis::buildRoadGraph(lines);
    parcelscope::analysis::fillStreetWidths(graph, {}, 12.0);
    blocks = parcelscope::analysis::streetBlocks(graph).blocks.size();
    edges = graph.edges.size();
  }
  state.counters["edges"] = static_cast<double>(edges);
  state.counters["blocks"] = static_cast<double>(blocks);
}
BENCHMARK(StreetGraphAndBlocks)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

// A node of cambridge_ma's street network dragged as the application drags
// it (observed parcels in the blocks of their streets, as the window edits
// them): each iteration is one move, 1, 2 or 3 m from where the drag began,
// applied in place of the move before (undo, then apply). Nodes of degree 3 or
// more, every 7th. Counters: seconds of the edit's stages (EditReport) per
// move. Argument: 0 obb, 1 skeleton. Target (issue 26): the whole drag to
// the view at most 50 ms.
void StreetEditorMove(benchmark::State& state) {
  if (!haveData(state)) return;
  const std::string centreLines = std::string(PARCELSCOPE_SHARED_DATASETS) + "/cambridge_ma/TRANS_Centerlines.geojson";
  parcelscope::pipeline::CompareRequest request;
  request.input.path = kCambridge;
  request.input.where = "ML <> 'ROAD'";
  request.streets = parcelscope::io::StreetReadOptions{};
  request.streets->path = centreLines;
  request.parameters = parcelscope::defaultValues(parcelscope::pipeline::compareParameters());
  for (const auto& d : parcelscope::pipeline::streetParameters()) request.parameters.emplace(d.name, d.defaultValue);
  request.style = state.range(0) ? "skeleton" : "obb";
  auto observed = std::make_shared<const parcelscope::pipeline::ObservedData>(
      parcelscope::pipeline::loadObservedInStreetBlocks(request.input, &*request.streets, request.parameters, {}));
  parcelscope::pipeline::StreetEditor editor(request, observed);
  std::vector<std::pair<parcelscope::Key, parcelscope::Point>> nodes;
  int seen = 0;
  for (const auto& n : editor.network().graph.nodes) {
    if (n.degree >= 3 && seen++ % 7 == 0) nodes.push_back({n.key, n.at});
  }
  double blocks = 0, subdivide = 0, match = 0, edit = 0;
  std::int64_t moves = 0;
  for (auto _ : state) {
    const auto& [key, at] = nodes[static_cast<std::size_t>(moves / 3) % nodes.size()];
    const int step = static_cast<int>(moves % 3) + 1;
    if (step > 1) editor.undo();
    parcelscope::pipeline::StreetEdit e;
    e.op = parcelscope::pipeline::StreetEdit::Op::MoveNode;
    e.node = key;
    e.to = {at.x + step, at.y};
    const parcelscope::pipeline::EditReport r = editor.apply(e);
    benchmark::DoNotOptimize(editor.snapshot());
    blocks += r.secondsBlocks;
    subdivide += r.secondsSubdivide;
    match += r.secondsMatch;
    edit += r.seconds;
    ++moves;
  }
  const double n = static_cast<double>(std::max<std::int64_t>(1, moves));
  state.counters["blocks_ms"] = 1000 * blocks / n;
  state.counters["subdivide_ms"] = 1000 * subdivide / n;
  state.counters["match_ms"] = 1000 * match / n;
  state.counters["rest_ms"] = 1000 * (edit - blocks - subdivide - match) / n;
}
BENCHMARK(StreetEditorMove)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

// Runs `compare` into `out` and adds the seconds of each stage (summary.json)
// to `seconds`; returns the summary.
CPLJSONObject runTimed(const parcelscope::pipeline::CompareRequest& request, const std::filesystem::path& out,
                       std::map<std::string, double>& seconds) {
  std::filesystem::remove_all(out);
  parcelscope::viz::runCompare(request, out.string());
  CPLJSONDocument summary;
  summary.Load((out / "summary.json").string());
  for (const auto& stage : summary.GetRoot().GetObj("timing_s").GetChildren()) {
    seconds[stage.GetName()] += stage.ToDouble();
  }
  return summary.GetRoot();
}

// The whole `compare` job on cambridge_ma (right-of-way filtered as in the
// README), as the command line runs it: read, blocks, generation, metrics,
// tables and figures. Counters give the seconds of each stage (summary.json).
void CompareCambridge(benchmark::State& state) {
  if (!haveData(state)) return;
  const bool figures = std::getenv("DISPLAY") != nullptr;
  parcelscope::pipeline::CompareRequest request;
  request.input.path = kCambridge;
  request.input.where = "ML <> 'ROAD'";
  request.parameters = parcelscope::defaultValues(parcelscope::pipeline::compareParameters());
  request.parameters["figures"] = figures ? 1 : 0;
  const auto out = std::filesystem::temp_directory_path() / "parcelscope-bench-compare";
  std::map<std::string, double> seconds;
  for (auto _ : state) runTimed(request, out, seconds);
  std::filesystem::remove_all(out);
  for (const auto& [stage, s] : seconds) {
    state.counters[stage + "_s"] = benchmark::Counter(s, benchmark::Counter::kAvgIterations);
  }
  state.SetLabel(figures ? "with figures" : "no X server: without figures");
}
BENCHMARK(CompareCambridge)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(3);

// The whole `compare` (figures off) on about 500,000 parcels: cambridge_ma
// (right-of-way filtered) tiled by translation, copies on a square grid with
// 300 m between them, written once to the temporary folder. Target (issue 5):
// 500,000 parcels generated and measured in under 10 s on 2 cores. Counters:
// the parcels read and the seconds of each stage (summary.json).
std::filesystem::path tiledCambridge(std::size_t target) {
  namespace fs = std::filesystem;
  const fs::path file = fs::temp_directory_path() / ("parcelscope-bench-cambridge-" + std::to_string(target) + ".gpkg");
  if (fs::exists(file)) return file;
  parcelscope::io::ReadOptions in;
  in.path = kCambridge;
  in.where = "ML <> 'ROAD'";
  const auto layer = parcelscope::io::readParcels(in);
  parcelscope::Box all = parcelscope::bounds(layer.parcels.front().shape);
  for (const auto& p : layer.parcels) {
    const auto b = parcelscope::bounds(p.shape);
    all = {std::min(all.minX, b.minX), std::min(all.minY, b.minY), std::max(all.maxX, b.maxX),
           std::max(all.maxY, b.maxY)};
  }
  const std::size_t copies = (target + layer.parcels.size() - 1) / layer.parcels.size();
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(copies))));
  const double dx = all.width() + 300, dy = all.height() + 300;
  parcelscope::Table table;
  table.columns = {{"copy", parcelscope::Column::Type::Integer, ""},
                   {"source_fid", parcelscope::Column::Type::Integer, ""}};
  std::vector<std::vector<parcelscope::Polygon>> geometries;
  for (std::size_t c = 0; c < copies; ++c) {
    const double ox = (static_cast<double>(c % side) - 0.5 * static_cast<double>(side - 1)) * dx;
    const double oy = (static_cast<double>(c / side) - 0.5 * static_cast<double>(side - 1)) * dy;
    for (const auto& p : layer.parcels) {
      parcelscope::Polygon q = p.shape;
      for (auto& v : q.outer) v = {v.x + ox, v.y + oy};
      for (auto& h : q.holes)
        for (auto& v : h) v = {v.x + ox, v.y + oy};
      geometries.push_back({std::move(q)});
      table.rows.push_back({static_cast<std::int64_t>(c), p.sourceFid});
    }
  }
  const fs::path partial = file.string() + ".partial";
  fs::remove(partial);
  parcelscope::io::writePolygonLayer(partial.string(), "parcels", geometries, table, layer.frame, layer.crs);
  fs::rename(partial, file);
  return file;
}

void CompareTiled500k(benchmark::State& state) {
  if (!haveData(state)) return;
  parcelscope::pipeline::CompareRequest request;
  request.input.path = tiledCambridge(500000).string();
  request.parameters = parcelscope::defaultValues(parcelscope::pipeline::compareParameters());
  request.parameters["figures"] = 0;
  const auto out = std::filesystem::temp_directory_path() / "parcelscope-bench-compare-tiled";
  std::map<std::string, double> seconds;
  double observed = 0, generated = 0;
  for (auto _ : state) {
    const CPLJSONObject summary = runTimed(request, out, seconds);
    observed = summary.GetObj("observed").GetDouble("parcels");
    generated = summary.GetObj("generated").GetDouble("parcels");
  }
  std::filesystem::remove_all(out);
  for (const auto& [stage, s] : seconds) {
    state.counters[stage + "_s"] = benchmark::Counter(s, benchmark::Counter::kAvgIterations);
  }
  state.counters["observed_parcels"] = observed;
  state.counters["generated_parcels"] = generated;
}
BENCHMARK(CompareTiled500k)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// Counters of a per-block timing: blocks, parcels, and the median, 90th
// percentile and mean milliseconds per block.
void perBlockCounters(benchmark::State& state, const std::vector<double>& ms, std::size_t parcels) {
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  for (double x : ms) sum += x;
  state.counters["blocks"] = static_cast<double>(ms.size());
  state.counters["parcels"] = static_cast<double>(parcels);
  if (!sorted.empty()) {
    state.counters["median_ms"] = sorted[sorted.size() / 2];
    state.counters["p90_ms"] = sorted[sorted.size() * 9 / 10];
    state.counters["mean_ms"] = sum / static_cast<double>(sorted.size());
  }
}

// Straight-skeleton subdivision of every cambridge_ma block with its own
// derived bounds, one block at a time (single thread). Target: median at most
// 3 ms per block (Vanegas et al. 2012 report 1-10 ms). Counters give the
// median, 90th percentile and mean per block of the last iteration.
void SkeletonSubdivisionPerBlock(benchmark::State& state) {
  if (!haveData(state)) return;
  namespace gen = parcelscope::generation;
  parcelscope::io::ReadOptions in;
  in.path = kCambridge;
  const auto d =
      parcelscope::pipeline::loadObserved(in, parcelscope::defaultValues(parcelscope::analysis::analysisParameters()));
  const auto [inputs, plans] = plannedBlocks(d, "skeleton");
  std::size_t parcels = 0, fallbacks = 0;
  std::vector<double> ms;
  for (auto _ : state) {
    parcels = fallbacks = 0;
    ms.clear();
    for (std::size_t k = 0; k < inputs.entries.size(); ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      const auto sub = gen::subdivideSkeleton(inputs.entries[k].shape, gen::skeletonParametersFrom(plans[k].values),
                                              plans[k].seed, inputs.widths[k]);
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      parcels += sub.parcels.size();
      fallbacks += sub.fallback;
    }
  }
  perBlockCounters(state, ms, parcels);
  state.counters["fallbacks"] = static_cast<double>(fallbacks);
}
BENCHMARK(SkeletonSubdivisionPerBlock)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

// Each concrete style on every cambridge_ma block (the ROAD features left
// out), with the block's plan as generate() makes it (derived bounds, seed,
// street widths, the observed parcels for sexton and template), one block at a time
// (single thread). Counters: median, 90th percentile and mean per block.
void StylePerBlock(benchmark::State& state, const char* style) {
  if (!haveData(state)) return;
  namespace gen = parcelscope::generation;
  parcelscope::io::ReadOptions in;
  in.path = kCambridge;
  in.where = "ML <> 'ROAD'";
  const auto d =
      parcelscope::pipeline::loadObserved(in, parcelscope::defaultValues(parcelscope::analysis::analysisParameters()));
  const auto [inputs, plans] = plannedBlocks(d, style);
  const gen::Style& s = gen::style(style);
  static const gen::StreetWidths kNone;
  std::size_t parcels = 0;
  std::vector<double> ms;
  for (auto _ : state) {
    parcels = 0;
    ms.clear();
    for (std::size_t k = 0; k < inputs.entries.size(); ++k) {
      gen::StyleRun run{inputs.entries[k].shape, plans[k].values, plans[k].seed,
                        s.usesStreetWidths() ? inputs.widths[k] : kNone};
      run.observed = inputs.entries[k].observed.get();
      run.observedShare = inputs.entries[k].observedShare;
      const auto t0 = std::chrono::steady_clock::now();
      parcels += s.subdivide(run).parcels.size();
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  perBlockCounters(state, ms, parcels);
}
BENCHMARK_CAPTURE(StylePerBlock, obb, "obb")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(StylePerBlock, skeleton, "skeleton")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(StylePerBlock, offset, "offset")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(StylePerBlock, parish, "parish")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(StylePerBlock, sexton, "sexton")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(StylePerBlock, template, "template")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace

// The incremental session behind the GUI on cambridge_ma: one global change
// (omega, every block regenerated), one block's override (one block), and the
// W_max slider with the bounds set for every block (every block regenerated,
// reusing its splits), each alternating between two values so that every
// iteration regenerates. With a third argument 1, the update defers the
// neighbours and street access as the application does: the time is to the
// result its views are drawn from, and `context_ms` is what completeContext
// took after it (outside the timed part).
void SessionUpdate(benchmark::State& state) {
  if (!haveData(state)) return;
  const bool global = state.range(0) == 1;
  const bool wMax = state.range(0) == 2;
  parcelscope::pipeline::CompareRequest request;
  request.input.path = kCambridge;
  request.input.where = "ML <> 'ROAD'";
  request.style = state.range(1) == 1 ? "skeleton" : "obb";
  request.parameters = parcelscope::defaultValues(parcelscope::pipeline::compareParameters());
  request.parameters["figures"] = 0;
  if (wMax) {  // as the application does once a bound slider moves: all four bounds set
    for (const char* bound : {"a-min", "a-max", "w-min", "w-max"}) request.explicitParameters.insert(bound);
  }
  parcelscope::pipeline::CompareSession session;
  session.update(request);
  int i = 0;
  std::size_t regenerated = 0;
  double generateMs = 0, metricsMs = 0, contextMs = 0;
  const bool defer = state.range(2) == 1;
  for (auto _ : state) {
    if (wMax) {
      request.parameters["w-max"] = ++i % 2 ? 25.0 : 35.0;
    } else if (global) {
      request.parameters["omega"] = ++i % 2 ? 0.25 : 0.35;
      request.explicitParameters.insert("omega");
    } else {
      request.overridesById[100].parameters["a-max"] = ++i % 2 ? 400.0 : 600.0;
    }
    const auto update = session.update(request, {}, {}, 0.5, defer);
    regenerated = update.blocksRegenerated;
    for (const auto& [stage, seconds] : update.result->seconds) {
      if (stage == "generate") generateMs += 1e3 * seconds;
      if (stage == "metrics") metricsMs += 1e3 * seconds;
    }
    if (defer) {
      state.PauseTiming();
      contextMs += 1e3 * session.completeContext().seconds;
      state.ResumeTiming();
    }
  }
  if (defer) state.counters["context_ms"] = benchmark::Counter(contextMs, benchmark::Counter::kAvgIterations);
  state.counters["blocks_regenerated"] = static_cast<double>(regenerated);
  state.counters["generate_ms"] = benchmark::Counter(generateMs, benchmark::Counter::kAvgIterations);
  state.counters["metrics_ms"] = benchmark::Counter(metricsMs, benchmark::Counter::kAvgIterations);
  state.SetLabel(request.style +
                 (wMax     ? ", W_max for every block"
                  : global ? ", omega for every block"
                           : ", one block's A_max") +
                 (defer ? ", context after" : ""));
}
BENCHMARK(SessionUpdate)
    ->Args({1, 0, 0})
    ->Args({1, 0, 1})
    ->Args({0, 0, 0})
    ->Args({2, 0, 0})
    ->Args({2, 0, 1})
    ->Args({1, 1, 0})
    ->Args({0, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);

// The display geometry behind the procedural view after an omega change on
// cambridge_ma: every generated parcel triangulated again and handed to VTK,
// grouped by block as the application does (MapLayer::setShapes).
void MapLayerUpdate(benchmark::State& state) {
  if (!haveData(state)) return;
  parcelscope::pipeline::CompareRequest request;
  request.input.path = kCambridge;
  request.input.where = "ML <> 'ROAD'";
  request.style = "obb";
  request.parameters = parcelscope::defaultValues(parcelscope::pipeline::compareParameters());
  request.parameters["figures"] = 0;
  request.explicitParameters.insert("omega");
  parcelscope::pipeline::CompareSession session;
  std::array<std::shared_ptr<const parcelscope::pipeline::CompareResult>, 2> results;
  for (int k = 0; k < 2; ++k) {
    request.parameters["omega"] = k == 0 ? 0.25 : 0.35;
    results[static_cast<std::size_t>(k)] = session.update(request).result;
  }
  parcelscope::viz::MapLayer layer;
  // The scale drawn at: 0 exact; 9 m per pixel is the whole city in the
  // application's view (shapes simplified to half a pixel).
  layer.setMetresPerPixel(static_cast<double>(state.range(0)));
  std::size_t i = 0, shapes = 0;
  for (auto _ : state) {
    const parcelscope::pipeline::CompareResult& r = *results[++i % 2];
    std::vector<const parcelscope::Polygon*> polygons;
    std::vector<int> blocks(r.generated.parcels.size(), -1);
    for (std::size_t b = 0; b < r.generated.blocks.size(); ++b) {
      for (int p : r.generated.blocks[b].parcels) blocks[static_cast<std::size_t>(p)] = static_cast<int>(b);
    }
    for (const auto& parcel : r.generated.parcels) polygons.push_back(&parcel);
    layer.setShapes(polygons, std::vector<double>(polygons.size(), 1.0), blocks);
    shapes = polygons.size();
  }
  state.counters["shapes"] = static_cast<double>(shapes);
  state.counters["points"] = static_cast<double>(layer.pointsDrawn());
}
BENCHMARK(MapLayerUpdate)->Arg(0)->Arg(9)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

BENCHMARK_MAIN();
