#include "parcelscope/pipeline/Leaderboard.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "parcelscope/core/Error.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/StreetsJob.h"

namespace parcelscope::pipeline {

std::vector<std::string> leaderboardStyles() {
  std::vector<std::string> names;
  for (const generation::Style* s : generation::styles()) names.push_back(s->name());
  return names;
}

double fitScore(const analysis::Comparison& c) {
  double fit = 0;
  for (analysis::ComparedMetric m : analysis::kComparedMetrics) {
    const double ks = c.distances(m).ks;
    fit += std::isfinite(ks) ? ks : 1.0;
  }
  return fit;
}

Leaderboard leaderboard(const CompareRequest& request, const ProgressFn& progress) {
  Leaderboard board;
  board.observed = std::make_shared<const ObservedData>(
      loadObservedInStreetBlocks(request.input, request.streets ? &*request.streets : nullptr, request.parameters,
                                 scaledProgress(progress, 0.0, 0.2)));
  const std::vector<std::string> names = leaderboardStyles();
  // The styles that choose per block (access, auto) take the outcome of the
  // concrete style's entry wherever their plan is the same.
  OutcomeLibrary made;
  for (std::size_t i = 0; i < names.size(); ++i) {
    CompareRequest one = request;
    one.style = names[i];
    const auto started = std::chrono::steady_clock::now();
    const double from = 0.2 + 0.8 * static_cast<double>(i) / static_cast<double>(names.size());
    const double to = 0.2 + 0.8 * static_cast<double>(i + 1) / static_cast<double>(names.size());
    LeaderboardEntry entry;
    entry.style = names[i];
    const bool perBlock = generation::choosesPerBlock(generation::style(names[i]));
    entry.result = compare(one, board.observed, scaledProgress(progress, from, to), nullptr, perBlock ? &made : nullptr,
                           perBlock ? nullptr : &made);
    entry.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    board.entries.push_back(std::move(entry));
  }
  const std::size_t blocks = board.observed->analysis.blocks.size();
  board.blockFit.assign(blocks, std::vector<double>(board.entries.size(), 3.0));
  board.bestEntry.assign(blocks, 0);
  for (std::size_t b = 0; b < blocks; ++b) {
    for (std::size_t e = 0; e < board.entries.size(); ++e) {
      const auto& compared = board.entries[e].result.blocks;
      if (b < compared.size()) board.blockFit[b][e] = fitScore(compared[b].comparison);
      if (board.blockFit[b][e] < board.blockFit[b][static_cast<std::size_t>(board.bestEntry[b])]) {
        board.bestEntry[b] = static_cast<int>(e);
      }
    }
  }
  return board;
}

Table leaderboardTable(const Leaderboard& board) {
  Table t;
  t.columns = {{"style", Column::Type::String, ""},
               {"parcels", Column::Type::Integer, ""},
               {"count_ratio", Column::Type::Real, ""}};
  for (const char* prefix : {"ks_", "w1_", "hi_"}) {
    for (analysis::ComparedMetric m : analysis::kComparedMetrics) {
      t.columns.push_back({prefix + std::string(analysis::metricName(m)), Column::Type::Real,
                           std::string(prefix) == "w1_" ? analysis::metricUnit(m) : ""});
    }
  }
  for (const char* name : {"street_access_share", "undesirable_share", "unassigned_share", "fit"}) {
    t.columns.push_back({name, Column::Type::Real, ""});
  }
  t.columns.push_back({"blocks_best", Column::Type::Integer, ""});
  t.columns.push_back({"seconds", Column::Type::Real, "s"});
  for (std::size_t e = 0; e < board.entries.size(); ++e) {
    const LeaderboardEntry& entry = board.entries[e];
    const analysis::Comparison& city = entry.result.city;
    std::vector<Value> row = {entry.style, city.generated.parcels,
                              city.observed.parcels > 0 ? static_cast<double>(city.generated.parcels) /
                                                              static_cast<double>(city.observed.parcels)
                                                        : NAN};
    for (analysis::ComparedMetric m : analysis::kComparedMetrics) row.push_back(city.distances(m).ks);
    for (analysis::ComparedMetric m : analysis::kComparedMetrics) row.push_back(city.distances(m).wasserstein);
    for (analysis::ComparedMetric m : analysis::kComparedMetrics) row.push_back(city.distances(m).intersection);
    std::int64_t best = 0;
    for (int b : board.bestEntry) best += b == static_cast<int>(e);
    // Unassigned land as a share of the blocks' area (parish leaves it; the others none).
    double blockArea = 0;
    for (const Block& block : entry.result.generated.blocks) {
      for (const Polygon& part : block.parts) blockArea += area(part);
    }
    const double unassignedShare = blockArea > 0 ? entry.result.generated.unassignedArea / blockArea : NAN;
    row.insert(row.end(), {city.generated.streetAccessShare, city.generated.undesirableShare, unassignedShare,
                           fitScore(city), best, entry.seconds});
    t.rows.push_back(std::move(row));
  }
  return t;
}

Table leaderboardBlockTable(const Leaderboard& board) {
  Table t;
  t.columns = {{"block_id", Column::Type::Integer, ""},
               {"block_key", Column::Type::String, ""},
               {"observed_parcels", Column::Type::Integer, ""}};
  for (const LeaderboardEntry& e : board.entries) t.columns.push_back({"fit_" + e.style, Column::Type::Real, ""});
  t.columns.push_back({"best_style", Column::Type::String, ""});
  const analysis::ObservedAnalysis& a = board.observed->analysis;
  for (std::size_t b = 0; b < a.blocks.size(); ++b) {
    if (a.blocks[b].parcels.empty()) continue;  // a street block without observed parcels: nothing to fit
    std::vector<Value> row = {static_cast<std::int64_t>(a.blocks[b].id), keyText(a.blocks[b].key),
                              static_cast<std::int64_t>(a.blocks[b].parcels.size())};
    for (double fit : board.blockFit[b]) row.push_back(fit);
    row.push_back(board.entries.empty() ? std::string()
                                        : board.entries[static_cast<std::size_t>(board.bestEntry[b])].style);
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::vector<LayoutMeasures> layoutRows(const Leaderboard& board) {
  const LayoutContext context = layoutContext(*board.observed);
  std::vector<LayoutMeasures> rows = {observedLayout(context, *board.observed)};
  for (const LeaderboardEntry& e : board.entries) rows.push_back(generatedLayout(context, e.result.generated, e.style));
  return rows;
}

namespace {
JobOutcome writeLeaderboard(io::OutputDirectory& out, const Leaderboard& board, const CompareRequest& request,
                            const ProgressFn& progress, const LeaderboardRenderer& draw, double seconds) {
  reportProgress(progress, 0.9, "writing");
  const Table table = leaderboardTable(board);
  io::writeCsv(out.stage("leaderboard.csv"), table);
  io::writeCsv(out.stage("leaderboard_blocks.csv"), leaderboardBlockTable(board));
  std::vector<std::string> outputs = {"leaderboard.csv", "leaderboard_blocks.csv", "layout.csv"};
  io::writeCsv(out.stage("layout.csv"), layoutTable(layoutRows(board)));
  if (draw && compareValue(request, "figures") != 0) {
    for (const std::string& name : draw(board, request, [&](const std::string& n) { return out.stage(n); })) {
      outputs.push_back(name);
    }
  }
  outputs.push_back("run.json");
  Json run = runRecord("compare", request.parameters).set("style", "all");
  addObservedRecord(run, *board.observed);
  if (board.observed->streets) run.set("streets", streetRecord(*board.observed->streets));
  Json styles = Json::object();
  for (const LeaderboardEntry& e : board.entries) styles.set(e.style, e.seconds);
  run.set("seconds_per_style", styles);
  run.set("timing_s", Json::object().set("total", seconds));
  Json list = Json::array();
  for (const std::string& o : outputs) list.push(o);
  run.set("outputs", list);
  io::writeJson(out.stage("run.json"), run);
  out.commit();
  reportProgress(progress, 1.0, "writing");
  std::ostringstream s;
  s.precision(3);
  s << "leaderboard of " << board.entries.size() << " styles on " << board.observed->analysis.blocks.size()
    << " blocks of " << board.observed->layer.path << " (fit: KS area + width + aspect ratio, lower is closer)";
  for (std::size_t e = 0; e < board.entries.size(); ++e) {
    const auto& city = board.entries[e].result.city;
    s << "\n  " << board.entries[e].style << ": fit " << fitScore(city) << ", KS area " << city.area.ks << ", width "
      << city.width.ks << ", aspect ratio " << city.aspectRatio.ks << ", " << city.generated.parcels << " parcels";
  }
  return {run, s.str()};
}
}  // namespace

JobOutcome runLeaderboard(const CompareRequest& request, const std::string& outDir, const ProgressFn& progress,
                          const LeaderboardRenderer& draw) {
  io::OutputDirectory out(outDir, inputPaths(request));
  try {
    const auto started = std::chrono::steady_clock::now();
    const Leaderboard board = leaderboard(request, scaledProgress(progress, 0.0, 0.9));
    return writeLeaderboard(out, board, request, progress, draw,
                            std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  } catch (const Error& e) {
    throw out.explain(e);
  }
}

JobOutcome saveLeaderboard(const Leaderboard& board, const CompareRequest& request, const std::string& outDir,
                           const LeaderboardRenderer& draw) {
  io::OutputDirectory out(outDir, inputPaths(request));
  double seconds = 0;
  for (const LeaderboardEntry& e : board.entries) seconds += e.seconds;
  try {
    return writeLeaderboard(out, board, request, {}, draw, seconds);
  } catch (const Error& e) {
    throw out.explain(e);
  }
}

}  // namespace parcelscope::pipeline
