// Realism of the auto style on cities it was not trained on: for each shared
// dataset, the auto rule trained on the other five (leave one city out)
// against the paper's rule (style access, k = 2), the parish baseline, the
// bundled rule (trained on all six, this one included) and the calibration.
// Each row: KS area / KS width / KS aspect ratio / median per-block
// |n_generated / n_observed - 1|, and whether the left-out rule beats the
// paper's rule and parish on every measure.
//
//   parcelscope_realism_bench [--variants | --votes | --labels | --quantiles] [CITY ...]
//   (default: all six; about 4-7 min)
//
// --variants: then, the rule's neighbours and features tried (each feature
// left out in turn), each measured leaving each city out.
// --votes: then, ways of voting (neighbours, extra votes for the paper's
// style, the paper's style for blocks far from every training block), each
// measured leaving each city out and on each city's cross-validated halves.
// --labels: then, training labels (calibrated, or each block's own best
// style) and choices (the vote, or one of the nearest drawn at random).
// --quantiles: then, percentiles of area, width and aspect ratio, observed,
// the paper's rule and the rule with the city left out; per style the left-out
// rule picks, its parcels' aspect ratios and widths beside the observed ones.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "parcelscope/generation/AutoRule.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/pipeline/BlockSource.h"
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

// Cities better than the paper's rule on all four measures, measures better,
// and the mean objective over `cities` cities.
struct Tally {
  int cities = 0, measures = 0;
  double objective = 0;
  void add(const pipeline::FitMeasures& f, const pipeline::FitMeasures& paper, std::size_t of) {
    cities += better(f, paper);
    measures += measuresBetter(f, paper);
    objective += pipeline::cityObjective(f) / static_cast<double>(of);
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  const bool variants = !args.empty() && args.front() == "--variants";
  if (variants) args.erase(args.begin());
  const bool votes = !args.empty() && args.front() == "--votes";
  if (votes) args.erase(args.begin());
  const bool labels = !args.empty() && args.front() == "--labels";
  if (labels) args.erase(args.begin());
  const bool quantiles = !args.empty() && args.front() == "--quantiles";
  if (quantiles) args.erase(args.begin());
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
    // Sexton (which takes the block's own observed count, areas and access) for blocks far from every row.
    for (double far : {36.0, 16.0, 9.0, 4.0}) ways.push_back({3, 0, far, true, false, "sexton"});
    std::printf(
        "| neighbours | paper's votes | far | weighted | left out: cities / measures better / mean objective | "
        "cross-validated: cities / measures better / mean objective | trained on all six |\n"
        "|---|---|---|---|---|---|---|\n");
    for (const Vote& v : ways) {
      Tally outTally, cvTally, inTally;
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
        inTally.add(fi, c.before, runs.size());
        outTally.add(fo, c.before, runs.size());
        cvTally.add(fc, c.before, runs.size());
        detail +=
            std::string("  ") + r.city->name + ": out " + text(fo) + ", cv " + text(fc) + ", all " + text(fi) + "\n";
      }
      std::printf(
          "| %zu | %g | %g | %s%s%s | %d of %zu / %d of %zu / %.3f | %d of %zu / %d of %zu / %.3f | %d / %d / %.3f "
          "|\n%s",
          v.k, v.paperVote, v.far, v.weighted ? "yes" : "no", v.withOthers ? ", halves with the other cities" : "",
          v.prior ? (std::string(", prior ") + v.prior).c_str() : "", outTally.cities, runs.size(), outTally.measures,
          4 * runs.size(), outTally.objective, cvTally.cities, runs.size(), cvTally.measures, 4 * runs.size(),
          cvTally.objective, inTally.cities, inTally.measures, inTally.objective, detail.c_str());
      std::fflush(stdout);
    }
  }
  if (quantiles) {
    // Where the distributions differ: the 10th, 50th and 90th percentiles of
    // area, width and aspect ratio, observed, the paper's rule and the rule
    // with the city left out.
    auto pct = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      std::string out;
      for (double q : {0.1, 0.5, 0.9}) {
        char c[32];
        std::snprintf(c, sizeof c, "%s%.3g", out.empty() ? "" : " / ",
                      v.empty() ? NAN : v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))]);
        out += c;
      }
      return out;
    };
    std::printf(
        "| dataset | parcels | area p10 / p50 / p90 (m2) | width p10 / p50 / p90 (m) | aspect ratio p10 / p50 / p90 "
        "|\n|---|---|---|---|---|\n");
    for (const Run& r : runs) {
      const pipeline::Calibration& c = r.c;
      std::vector<double> a, w, q;
      for (std::size_t b = 0; b < c.blocks.size(); ++b) {
        const auto s = pipeline::observedSample(c.board.observed->analysis, b);
        a.insert(a.end(), s->areas.begin(), s->areas.end());
        w.insert(w.end(), s->widths.begin(), s->widths.end());
        q.insert(q.end(), s->aspectRatios.begin(), s->aspectRatios.end());
      }
      std::printf("| %s observed | %zu | %s | %s | %s |\n", r.city->name, a.size(), pct(a).c_str(), pct(w).c_str(),
                  pct(q).c_str());
      const std::vector<std::size_t> out = pipeline::entriesOf(
          c, leftOut(r.city->name, generation::AutoRule::kNeighbours, generation::AutoRule::kWeights));
      for (const auto& [name, entries] :
           {std::pair<const char*, std::vector<std::size_t>>{"paper", c.entryBefore}, {"left out", out}}) {
        a.clear(), w.clear(), q.clear();
        for (const auto& m : pipeline::generatedMetrics(c.board, entries)) {
          a.push_back(m.area), w.push_back(m.width), q.push_back(m.aspectRatio);
        }
        std::printf("| %s %s | %zu | %s | %s | %s |\n", r.city->name, name, a.size(), pct(a).c_str(), pct(w).c_str(),
                    pct(q).c_str());
      }
      // Per style the left-out rule picks: its blocks, parcels, and the share
      // of them above the observed 90th percentile of aspect ratio (0.10 if
      // the style's tail were the observed one).
      std::vector<double> observedAspect;
      for (std::size_t b = 0; b < c.blocks.size(); ++b) {
        const auto s = pipeline::observedSample(c.board.observed->analysis, b);
        observedAspect.insert(observedAspect.end(), s->aspectRatios.begin(), s->aspectRatios.end());
      }
      std::sort(observedAspect.begin(), observedAspect.end());
      const double tail =
          observedAspect[static_cast<std::size_t>(0.9 * static_cast<double>(observedAspect.size() - 1))];
      // Each block's parcels in generatedMetrics' order (blocks in order).
      const auto metrics = pipeline::generatedMetrics(c.board, out);
      std::vector<std::size_t> first(out.size() + 1, 0);
      for (std::size_t b = 0; b < out.size(); ++b) {
        const std::vector<std::size_t> prefix(out.begin(), out.begin() + static_cast<long>(b) + 1);
        first[b + 1] = pipeline::generatedMetrics(c.board, prefix).size();
      }
      std::map<std::string, std::array<std::size_t, 3>> byStyle;  // blocks, parcels, above
      // Per style: aspect ratios and widths of its generated parcels, and of
      // the observed ones in its blocks.
      std::map<std::string, std::array<std::vector<double>, 2>> aspects, widths;
      for (std::size_t b = 0; b < out.size(); ++b) {
        const std::string& style = c.board.entries[out[b]].style;
        auto& t = byStyle[style];
        ++t[0];
        for (std::size_t i = first[b]; i < first[b + 1]; ++i) {
          ++t[1];
          t[2] += metrics[i].aspectRatio > tail;
          aspects[style][0].push_back(metrics[i].aspectRatio);
          widths[style][0].push_back(metrics[i].width);
        }
        const auto s = pipeline::observedSample(c.board.observed->analysis, b);
        aspects[style][1].insert(aspects[style][1].end(), s->aspectRatios.begin(), s->aspectRatios.end());
        widths[style][1].insert(widths[style][1].end(), s->widths.begin(), s->widths.end());
      }
      std::printf("  %s (observed p90 aspect ratio %.2f), left out, per style: blocks / parcels / share above it:",
                  r.city->name, tail);
      for (const auto& [style, t] : byStyle) {
        std::printf(" %s %zu / %zu / %.2f;", style.c_str(), t[0], t[1],
                    t[1] ? static_cast<double>(t[2]) / static_cast<double>(t[1]) : 0.0);
      }
      std::printf("\n  aspect ratio p10 / p50 / p90 per style, generated | observed in its blocks:");
      for (const auto& [style, v] : aspects) {
        std::printf(" %s %s | %s;", style.c_str(), pct(v[0]).c_str(), pct(v[1]).c_str());
      }
      std::printf("\n  width p10 / p50 / p90 (m) per style, generated | observed in its blocks:");
      for (const auto& [style, v] : widths) {
        std::printf(" %s %s | %s;", style.c_str(), pct(v[0]).c_str(), pct(v[1]).c_str());
      }
      std::printf("\n");
    }
  }
  if (labels) {
    // Labels and draws: each block of the training cities labelled with its
    // calibrated style (city-wide) or with its own best style (least
    // calibrationDistance, the block alone); a block's style the vote of its
    // k nearest (1 / distance) or one of its k nearest drawn at random (from
    // the block's key), so that the training labels' mixture is kept.
    std::vector<std::vector<std::string>> ownBest(runs.size());
    for (std::size_t ri = 0; ri < runs.size(); ++ri) {
      const pipeline::Calibration& c = runs[ri].c;
      for (std::size_t b = 0; b < c.blocks.size(); ++b) {
        double least = HUGE_VAL;
        std::string style;
        for (const auto& e : c.board.entries) {
          if (generation::choosesPerBlock(generation::style(e.style))) continue;
          const double d = pipeline::calibrationDistance(e.result.blocks[b].comparison);
          if (d < least) least = d, style = e.style;
        }
        ownBest[ri].push_back(style);
      }
    }
    auto mix = [](std::uint64_t x) {
      x += 0x9e3779b97f4a7c15ULL;
      x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
      x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
      return x ^ (x >> 31);
    };
    std::printf(
        "| labels | k | choice | left out: cities / measures better / mean objective | cross-validated: cities / "
        "measures better / mean objective |\n|---|---|---|---|---|\n");
    for (int own = 0; own < 2; ++own) {
      for (std::size_t k : {1, 3, 5, 7, 11}) {
        for (int draw = 0; draw < 2; ++draw) {
          if (k == 1 && draw) continue;
          auto pick = [&](const generation::AutoRule& rule, const pipeline::BlockCalibration& b) {
            const auto near = rule.nearest(b.features, k);
            if (draw) {
              const std::size_t j = mix(static_cast<std::uint64_t>(b.blockKey)) % near.size();
              return rule.rows()[near[j].second].style;
            }
            std::map<std::string, double> score;
            for (const auto& [d, i] : near) score[rule.rows()[i].style] += 1 / (std::sqrt(d) + 1e-9);
            std::string best = rule.rows()[near.front().second].style;
            for (const auto& [st, w] : score) {
              if (w > score[best]) best = st;
            }
            return best;
          };
          Tally outTally, cvTally;
          std::string detail;
          for (std::size_t ri = 0; ri < runs.size(); ++ri) {
            const pipeline::Calibration& c = runs[ri].c;
            std::vector<generation::AutoRule::Row> train;
            for (std::size_t rj = 0; rj < runs.size(); ++rj) {
              if (rj == ri) continue;
              const auto& cb = runs[rj].c.blocks;
              for (std::size_t b = 0; b < cb.size(); ++b) {
                train.push_back({cb[b].features, own ? ownBest[rj][b] : cb[b].styleAfter});
              }
            }
            const generation::AutoRule out(std::move(train), k);
            std::vector<std::size_t> outEntries, cvEntries(c.blocks.size());
            for (const auto& b : c.blocks) outEntries.push_back(pipeline::entryOfStyle(c, pick(out, b)));
            for (int half = 0; half < 2; ++half) {
              std::vector<generation::AutoRule::Row> rows;
              for (std::size_t b = 0; b < c.blocks.size(); ++b) {
                if (c.blocks[b].half != half)
                  rows.push_back({c.blocks[b].features, own ? ownBest[ri][b] : c.blocks[b].styleHalf});
              }
              if (rows.empty()) continue;
              const generation::AutoRule rule(std::move(rows), k);
              for (std::size_t b = 0; b < c.blocks.size(); ++b) {
                if (c.blocks[b].half == half) cvEntries[b] = pipeline::entryOfStyle(c, pick(rule, c.blocks[b]));
              }
            }
            const pipeline::FitMeasures fo = pipeline::fitMeasures(c.board, runs[ri].all, outEntries);
            const pipeline::FitMeasures fc = pipeline::fitMeasures(c.board, runs[ri].all, cvEntries);
            outTally.add(fo, c.before, runs.size());
            cvTally.add(fc, c.before, runs.size());
            detail += std::string("  ") + runs[ri].city->name + ": out " + text(fo) + ", cv " + text(fc) + "\n";
          }
          std::printf("| %s | %zu | %s | %d / %d / %.3f | %d / %d / %.3f |\n%s", own ? "own best" : "calibrated", k,
                      draw ? "draw" : "vote", outTally.cities, outTally.measures, outTally.objective, cvTally.cities,
                      cvTally.measures, cvTally.objective, detail.c_str());
          std::fflush(stdout);
        }
      }
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
