// Realism of the auto style on cities it was not trained on: for each shared
// dataset, the auto rule trained on the other five (leave one city out)
// against the paper's rule (style access, k = 2), the parish baseline, the
// bundled rule (trained on all six, this one included) and the calibration.
// Each row: KS area / KS width / KS aspect ratio / median per-block
// |n_generated / n_observed - 1|, and whether the left-out rule beats the
// paper's rule and parish on every measure.
//
//   parcelscope_realism_bench [--variants | --votes] [CITY ...]   (default: all six; about 4-7 min)
//
// --variants: then, the rule's neighbours and features tried (each feature
// left out in turn), each measured leaving each city out.
// --votes: then, ways of voting (neighbours, extra votes for the paper's
// style, the paper's style for blocks far from every training block), each
// measured leaving each city out and on each city's cross-validated halves.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
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

// A way of choosing a block's style from the training rows nearest it: `k`
// neighbours vote (each with weight 1, or with `weighted` 1 / distance), the
// paper's rule's style gets `paperVote` more votes, and a block farther than
// `far` (squared standardised distance to its nearest row) takes the paper's
// style. Ties go to the paper's style when it has votes, else to the nearer.
struct Vote {
  std::size_t k;
  double paperVote;
  double far;
  bool weighted = false;
  bool withOthers = false;      // cross-validated halves: the other cities' table rows too
  const char* prior = nullptr;  // the style taking the paper's place above (null: the paper's rule's)
};

std::string choose(const generation::AutoRule& rule, const pipeline::BlockCalibration& b, const Vote& v) {
  const std::string prior = v.prior ? v.prior : b.styleBefore;
  const auto near = rule.nearest(b.features, v.k);
  if (near.empty() || near.front().first > v.far) return prior;
  std::map<std::string, double> score;
  if (v.paperVote > 0) score[prior] += v.paperVote;
  for (const auto& [d, i] : near) score[rule.rows()[i].style] += v.weighted ? 1 / (std::sqrt(d) + 1e-9) : 1.0;
  std::string best = v.paperVote > 0 ? prior : rule.rows()[near.front().second].style;
  double most = score[best];
  for (const auto& [d, i] : near) {
    const std::string& st = rule.rows()[i].style;
    if (score[st] > most) {
      best = st;
      most = score[st];
    }
  }
  return best;
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
  const bool votes = !args.empty() && args.front() == "--votes";
  if (votes) args.erase(args.begin());
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
      "cross-validated halves | left-out beats paper | beats parish | halves beat paper |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n");
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
    const bool halvesBeat = better(c.crossFitted, c.crossPaper);
    failures += !beatsPaper + !beatsParish;
    std::printf("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", r.city->name, text(c.before).c_str(),
                text(parish).c_str(), text(rule).c_str(), text(c.autoRule).c_str(), text(c.after).c_str(),
                text(c.crossFitted).c_str(), beatsPaper ? "yes" : "no", beatsParish ? "yes" : "no",
                halvesBeat ? "yes" : "no");
  }
  if (votes) {
    // Each way of voting, the city left out and each city's halves
    // cross-validated (the rule of a half trained on the other half's own
    // calibration), against the paper's rule.
    std::vector<Vote> ways;
    for (std::size_t k : {3, 5, 7}) {
      for (double paper : {0.0, 1.0, 2.0, 3.0}) {
        if (paper >= static_cast<double>(k)) continue;
        for (double far : {HUGE_VAL, 2.0, 1.0}) ways.push_back({k, paper, far});
      }
    }
    for (std::size_t k : {3, 5, 7, 11, 15}) ways.push_back({k, 0, HUGE_VAL, true});
    for (std::size_t k : {3, 5, 7}) ways.push_back({k, 0, HUGE_VAL, true, true});
    // The skeleton style (observed slice widths) as the prior instead of the paper's rule.
    for (double paper : {1.0, 2.0, 3.0, 100.0}) ways.push_back({3, paper, HUGE_VAL, false, false, "skeleton"});
    for (double far : {4.0, 2.0, 1.0, 0.5}) ways.push_back({3, 0, far, true, false, "skeleton"});
    std::printf(
        "| neighbours | paper's votes | far | weighted | left out: cities / measures better / mean objective | "
        "cross-validated: cities / measures better / mean objective | trained on all six |\n"
        "|---|---|---|---|---|---|---|\n");
    for (const Vote& v : ways) {
      int outCities = 0, outMeasures = 0, cvCities = 0, cvMeasures = 0;
      double outObjective = 0, cvObjective = 0, inObjective = 0;
      int inCities = 0, inMeasures = 0;
      std::string detail;
      for (const Run& r : runs) {
        const pipeline::Calibration& c = r.c;
        const generation::AutoRule out = leftOut(r.city->name, v.k, generation::AutoRule::kWeights);
        const generation::AutoRule all = leftOut("", v.k, generation::AutoRule::kWeights);
        std::vector<std::size_t> outEntries, inEntries, cvEntries(c.blocks.size());
        for (const auto& b : c.blocks) outEntries.push_back(pipeline::entryOfStyle(c, choose(out, b, v)));
        for (const auto& b : c.blocks) inEntries.push_back(pipeline::entryOfStyle(c, choose(all, b, v)));
        for (int half = 0; half < 2; ++half) {
          std::vector<generation::AutoRule::Row> rows;
          for (const auto& b : c.blocks) {
            if (b.half != half) rows.push_back({b.features, b.styleHalf});
          }
          if (v.withOthers) rows.insert(rows.end(), out.rows().begin(), out.rows().end());
          if (rows.empty()) continue;
          const generation::AutoRule rule(std::move(rows), v.k);
          for (std::size_t i = 0; i < c.blocks.size(); ++i) {
            if (c.blocks[i].half == half) cvEntries[i] = pipeline::entryOfStyle(c, choose(rule, c.blocks[i], v));
          }
        }
        const pipeline::FitMeasures fo = pipeline::fitMeasures(c.board, r.all, outEntries);
        const pipeline::FitMeasures fc = pipeline::fitMeasures(c.board, r.all, cvEntries);
        const pipeline::FitMeasures fi = pipeline::fitMeasures(c.board, r.all, inEntries);
        inCities += better(fi, c.before);
        inMeasures += measuresBetter(fi, c.before);
        inObjective += pipeline::cityObjective(fi) / static_cast<double>(runs.size());
        outCities += better(fo, c.before);
        outMeasures += measuresBetter(fo, c.before);
        cvCities += better(fc, c.before);
        cvMeasures += measuresBetter(fc, c.before);
        outObjective += pipeline::cityObjective(fo) / static_cast<double>(runs.size());
        cvObjective += pipeline::cityObjective(fc) / static_cast<double>(runs.size());
        detail +=
            std::string("  ") + r.city->name + ": out " + text(fo) + ", cv " + text(fc) + ", all " + text(fi) + "\n";
      }
      std::printf(
          "| %zu | %g | %g | %s%s%s | %d of %zu / %d of %zu / %.3f | %d of %zu / %d of %zu / %.3f | %d / %d / %.3f "
          "|\n%s",
          v.k, v.paperVote, v.far, v.weighted ? "yes" : "no", v.withOthers ? ", halves with the other cities" : "",
          v.prior ? ", prior skeleton" : "", outCities, runs.size(), outMeasures, 4 * runs.size(), outObjective,
          cvCities, runs.size(), cvMeasures, 4 * runs.size(), cvObjective, inCities, inMeasures, inObjective,
          detail.c_str());
      std::fflush(stdout);
    }
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
