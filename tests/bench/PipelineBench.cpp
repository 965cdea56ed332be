// Benchmarks. 1) The stats pipeline (read + project + clean + metrics + blocks) on
// cambridge_ma against a plain GDAL read of the same file (every feature and its
// geometry fetched). Target: the pipeline within 3x of the plain read.
// 2) OBB subdivision of every block. 3) The whole `compare` job, stage by stage
// (figures only when an X server answers: run under scripts/with-xvfb.sh).
//   build/release/tests/bench/parcelscope_bench
//   scripts/with-xvfb.sh build/release/tests/bench/parcelscope_bench --benchmark_filter=Compare
#include <benchmark/benchmark.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <cpl_json.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "parcelscope/analysis/StatsJob.h"
#include "parcelscope/generation/GenerateJob.h"
#include "parcelscope/viz/CompareJob.h"

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
    const auto d = parcelscope::analysis::loadObserved(in, params);
    parcels = d.layer.parcels.size();
    blocks = d.analysis.blocks.size();
  }
  state.counters["parcels"] = static_cast<double>(parcels);
  state.counters["blocks"] = static_cast<double>(blocks);
  state.counters["parcels_per_s"] =
      benchmark::Counter(static_cast<double>(parcels), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(StatsPipeline)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

// OBB subdivision of every cambridge_ma block with its own derived bounds
// (Vanegas et al. 2012 report 1-10 ms per block after an edit). Single thread.
void ObbSubdivisionPerBlock(benchmark::State& state) {
  if (!haveData(state)) return;
  parcelscope::io::ReadOptions in;
  in.path = kCambridge;
  const auto d = parcelscope::analysis::loadObserved(
      in, parcelscope::defaultValues(parcelscope::analysis::analysisParameters()));
  parcelscope::generation::GenerateRequest request;
  request.parameters = parcelscope::defaultValues(parcelscope::generation::obbParameterDescriptions());
  std::size_t blocks = 0, parcels = 0;
  for (auto _ : state) {
    blocks = parcels = 0;
    for (std::size_t b = 0; b < d.analysis.blocks.size(); ++b) {
      const auto& s = d.analysis.statistics[b];
      const auto p = parcelscope::generation::blockParameters(request, s.aMin, s.aMax, s.wMin, s.wMax);
      for (const auto& part : d.analysis.blocks[b].parts) {
        parcels += parcelscope::generation::subdivideObb(part, p, b).parcels.size();
        ++blocks;
      }
    }
  }
  state.counters["blocks"] = static_cast<double>(blocks);
  state.counters["parcels"] = static_cast<double>(parcels);
  state.counters["blocks_per_s"] = benchmark::Counter(static_cast<double>(blocks),
                                                      benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(ObbSubdivisionPerBlock)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

// The whole `compare` job on cambridge_ma (right-of-way filtered as in the
// README), as the command line runs it: read, blocks, generation, metrics,
// tables and figures. Counters give the seconds of each stage (summary.json).
void CompareCambridge(benchmark::State& state) {
  if (!haveData(state)) return;
  const bool figures = std::getenv("DISPLAY") != nullptr;
  parcelscope::viz::CompareRequest request;
  request.input.path = kCambridge;
  request.input.where = "ML <> 'ROAD'";
  request.parameters = parcelscope::defaultValues(parcelscope::viz::compareParameters());
  request.parameters["figures"] = figures ? 1 : 0;
  const auto out = std::filesystem::temp_directory_path() / "parcelscope-bench-compare";
  std::map<std::string, double> seconds;
  for (auto _ : state) {
    std::filesystem::remove_all(out);
    parcelscope::viz::runCompare(request, out.string());
    CPLJSONDocument summary;
    summary.Load((out / "summary.json").string());
    for (const auto& stage : summary.GetRoot().GetObj("timing_s").GetChildren()) {
      seconds[stage.GetName()] += stage.ToDouble();
    }
  }
  std::filesystem::remove_all(out);
  for (const auto& [stage, s] : seconds) {
    state.counters[stage + "_s"] = benchmark::Counter(s, benchmark::Counter::kAvgIterations);
  }
  state.SetLabel(figures ? "with figures" : "no X server: without figures");
}
BENCHMARK(CompareCambridge)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(3);

// Straight-skeleton subdivision of every cambridge_ma block with its own
// derived bounds, one block at a time (single thread). Target: median at most
// 3 ms per block (Vanegas et al. 2012 report 1-10 ms). Counters give the
// median, 90th percentile and mean per block of the last iteration.
void SkeletonSubdivisionPerBlock(benchmark::State& state) {
  if (!haveData(state)) return;
  namespace gen = parcelscope::generation;
  parcelscope::io::ReadOptions in;
  in.path = kCambridge;
  const auto d = parcelscope::analysis::loadObserved(
      in, parcelscope::defaultValues(parcelscope::analysis::analysisParameters()));
  gen::GenerateRequest request;
  request.parameters = parcelscope::defaultValues(gen::generationParameterDescriptions());
  gen::SkeletonParameters p = gen::skeletonParametersFrom(request.parameters);
  std::size_t parcels = 0, fallbacks = 0;
  std::vector<double> ms;
  for (auto _ : state) {
    parcels = fallbacks = 0;
    ms.clear();
    for (std::size_t b = 0; b < d.analysis.blocks.size(); ++b) {
      const auto& s = d.analysis.statistics[b];
      p.bounds = gen::blockParameters(request, s.aMin, s.aMax, s.wMin, s.wMax);
      for (const auto& part : d.analysis.blocks[b].parts) {
        const auto t0 = std::chrono::steady_clock::now();
        const auto sub = gen::subdivideSkeleton(part, p, b);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        parcels += sub.parcels.size();
        fallbacks += sub.fallback;
      }
    }
  }
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  for (double x : ms) sum += x;
  state.counters["blocks"] = static_cast<double>(ms.size());
  state.counters["parcels"] = static_cast<double>(parcels);
  state.counters["fallbacks"] = static_cast<double>(fallbacks);
  if (!sorted.empty()) {
    state.counters["median_ms"] = sorted[sorted.size() / 2];
    state.counters["p90_ms"] = sorted[sorted.size() * 9 / 10];
    state.counters["mean_ms"] = sum / static_cast<double>(sorted.size());
  }
}
BENCHMARK(SkeletonSubdivisionPerBlock)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

}  // namespace

BENCHMARK_MAIN();
