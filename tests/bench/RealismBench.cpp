// Realism of the auto style on cities it was not trained on: for each shared
// dataset, the auto rule trained on the other five (leave one city out)
// against the paper's rule (style access, k = 2), the parish baseline, the
// bundled rule (trained on all six, this one included) and the calibration.
// Each row: KS area / KS width / KS aspect ratio / median per-block
// |n_generated / n_observed - 1|, and whether the left-out rule beats the
// paper's rule and parish on every measure.
//
//   parcelscope_realism_bench [--variants] [CITY ...]   (default: all six; about 7 min)
//
// --variants: then, the rule's neighbours and features tried (each feature
// left out in turn), each measured leaving each city out.
#include <algorithm>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "parcelscope/generation/AutoRule.h"
#include "parcelscope/pipeline/Calibrate.h"

using namespace parcelscope;

namespace {

struct City {
  const char* name;
  const char* path;
  const char* where;
  const char* crs;
};

const City kCities[] = {
    {"cambridge_ma", "cambridge_ma/ASSESSING_ParcelsFY2014.topojson", "ML <> 'ROAD'", ""},
    {"paris_18e", "paris_18e/cadastre-75118-parcelles.json", "", ""},
    {"malibu_ca", "malibu_ca/parcels.geojson", "", ""},
    {"eatonville_wa", "eatonville_wa/parcels.geojson", "", "EPSG:2286"},
    {"seoul_jamsil", "seoul_jamsil/parcels.geojson", "", ""},
    {"rhone_69114", "rhone_69114/parcelles.json", "", ""},
};

std::string text(const pipeline::FitMeasures& f) {
  char s[96];
  std::snprintf(s, sizeof s, "%.3f / %.3f / %.3f / %.3f", f.ksArea, f.ksWidth, f.ksAspectRatio, f.medianCountError);
  return s;
}

bool better(const pipeline::FitMeasures& a, const pipeline::FitMeasures& b) {
  return a.ksArea < b.ksArea && a.ksWidth < b.ksWidth && a.ksAspectRatio < b.ksAspectRatio &&
         a.medianCountError < b.medianCountError;
}

// The rule trained on every city but `city`, with `k` neighbours and `weights`.
generation::AutoRule leftOut(const char* city, std::size_t k, const generation::AutoFeatures& weights) {
  return generation::AutoRule::fromCsv(generation::AutoRule::bundledTable(), "datasets/auto_rule.csv", {city}, k,
                                       weights);
}

int measuresBetter(const pipeline::FitMeasures& a, const pipeline::FitMeasures& b) {
  return (a.ksArea < b.ksArea) + (a.ksWidth < b.ksWidth) + (a.ksAspectRatio < b.ksAspectRatio) +
         (a.medianCountError < b.medianCountError);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  const bool variants = !args.empty() && args.front() == "--variants";
  if (variants) args.erase(args.begin());
  struct Run {
    const City* city;
    pipeline::Calibration c;
    std::vector<std::size_t> all;
  };
  std::vector<Run> runs;
  for (const City& city : kCities) {
    if (!args.empty() && std::find(args.begin(), args.end(), city.name) == args.end()) continue;
    pipeline::CompareRequest request;
    request.input.path = std::string(PARCELSCOPE_SHARED_DATASETS) + "/" + city.path;
    request.input.where = city.where;
    request.input.crsOverride = city.crs;
    request.style = "auto";
    request.parameters = defaultValues(pipeline::compareParameters());
    request.parameters["figures"] = 0;
    try {
      Run r{&city, pipeline::calibrate(request), {}};
      r.all.resize(r.c.blocks.size());
      std::iota(r.all.begin(), r.all.end(), 0);
      runs.push_back(std::move(r));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: %s\n", city.name, e.what());
      return 2;
    }
  }
  std::printf(
      "| dataset | paper (access) | parish | auto, this city left out | auto, bundled | calibrated | "
      "left-out beats paper | beats parish |\n|---|---|---|---|---|---|---|---|\n");
  int failures = 0;
  for (const Run& r : runs) {
    const pipeline::Calibration& c = r.c;
    const pipeline::FitMeasures rule = pipeline::fitMeasures(
        c.board, r.all,
        pipeline::entriesOf(c,
                            leftOut(r.city->name, generation::AutoRule::kNeighbours, generation::AutoRule::kWeights)));
    const pipeline::FitMeasures parish = pipeline::fitMeasures(
        c.board, r.all, std::vector<std::size_t>(r.all.size(), pipeline::entryOfStyle(c, "parish")));
    const bool beatsPaper = better(rule, c.before), beatsParish = better(rule, parish);
    failures += !beatsPaper + !beatsParish;
    std::printf("| %s | %s | %s | %s | %s | %s | %s | %s |\n", r.city->name, text(c.before).c_str(),
                text(parish).c_str(), text(rule).c_str(), text(c.autoRule).c_str(), text(c.after).c_str(),
                beatsPaper ? "yes" : "no", beatsParish ? "yes" : "no");
  }
  if (variants) {
    // Neighbours and features, each variant measured leaving each city out:
    // how many of the cities' measures beat the paper's rule.
    std::printf(
        "| neighbours | feature left out | measures better than paper | cities better on all four | mean "
        "objective |\n|---|---|---|---|---|\n");
    for (std::size_t k : {1, 3, 5, 7, 11, 15, 25}) {
      for (int drop = -1; drop < static_cast<int>(generation::kAutoFeatures); ++drop) {
        generation::AutoFeatures w = generation::AutoRule::kWeights;
        if (drop >= 0) w[static_cast<std::size_t>(drop)] = 0;
        int measures = 0, cities = 0;
        double objective = 0;
        for (const Run& r : runs) {
          const pipeline::FitMeasures f =
              pipeline::fitMeasures(r.c.board, r.all, pipeline::entriesOf(r.c, leftOut(r.city->name, k, w)));
          measures += measuresBetter(f, r.c.before);
          cities += better(f, r.c.before);
          objective += pipeline::cityObjective(f) / static_cast<double>(runs.size());
        }
        std::printf("| %zu | %s | %d of %zu | %d of %zu | %.3f |\n", k,
                    drop < 0 ? "none" : generation::autoFeatureNames()[static_cast<std::size_t>(drop)], measures,
                    4 * runs.size(), cities, runs.size(), objective);
        std::fflush(stdout);
      }
    }
  }
  return failures == 0 ? 0 : 1;
}
