// Benchmark: the stats pipeline (read + project + clean + metrics + blocks) on
// cambridge_ma against a plain GDAL read of the same file (every feature and its
// geometry fetched). Target: the pipeline within 3x of the plain read.
//   build/release/tests/bench/parcelscope_bench
#include <benchmark/benchmark.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <cstdio>
#include <filesystem>

#include "parcelscope/analysis/StatsJob.h"

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

}  // namespace

BENCHMARK_MAIN();
