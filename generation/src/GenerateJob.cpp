#include "parcelscope/generation/GenerateJob.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "parcelscope/analysis/StatsJob.h"
#include "parcelscope/analysis/StreetWidth.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"

namespace parcelscope::generation {

ObbParameters blockParameters(const GenerateRequest& request, double aMin, double aMax, double wMin,
                              double wMax) {
  ObbParameters p = obbParametersFrom(request.parameters);
  auto pick = [&](const char* name, double perBlock, double& target) {
    if (!request.explicitParameters.count(name) && std::isfinite(perBlock)) target = perBlock;
  };
  pick("a-min", aMin, p.aMin);
  pick("a-max", aMax, p.aMax);
  pick("w-min", wMin, p.wMin);
  pick("w-max", wMax, p.wMax);
  return p;
}

const std::vector<std::pair<std::string, std::string>>& generationStyles() {
  static const std::vector<std::pair<std::string, std::string>> styles = {
      {"obb", "OBB recursive subdivision (Vanegas et al. 2012, 4.3)"},
      {"skeleton", "straight-skeleton strips along the streets (4.2); --offset M leaves patios"},
      {"offset", "skeleton with a finite offset (30 m unless --offset) and patios subdivided by OBB"},
      {"auto", "per block: skeleton where >= 90 % of observed parcels have street access, else obb"},
  };
  return styles;
}

std::vector<ParameterDescription> generationParameterDescriptions() {
  std::vector<ParameterDescription> params = obbParameterDescriptions();
  auto add = [&](const std::vector<ParameterDescription>& more) {
    for (const auto& d : more) {
      bool seen = false;
      for (const auto& p : params) seen = seen || p.name == d.name;
      if (!seen) params.push_back(d);
    }
  };
  add(skeletonParameterDescriptions());
  add(analysis::analysisParameters());
  return params;
}

namespace {
constexpr double kDefaultOffsetStyleDepth = 30.0;  // m, style offset without --offset
}  // namespace

Subdivision subdivideBlock(const Polygon& block, const std::string& style, const SkeletonParameters& parameters,
                           std::uint64_t seed, const StreetWidths& streetWidths) {
  if (style == "obb") return subdivideObb(block, parameters.bounds, seed);
  SkeletonParameters p = parameters;
  if (style == "offset") {
    if (p.offset <= 0) p.offset = kDefaultOffsetStyleDepth;
    p.subdividePatios = true;
  } else if (style != "skeleton") {
    throw usageError("no subdivision style '" + style + "'");
  }
  return subdivideSkeleton(block, p, seed, streetWidths);
}

namespace {
// A block's seed key: its centroid in the input CRS, rounded to about 0.1 m, so
// that adding, removing or renumbering other blocks does not reseed it.
std::int64_t positionKey(const Polygon& shape, const io::LocalFrame& frame) {
  const Point c = frame.toSource(centroid(shape));
  const double q = frame.isGeographic() ? 1e-6 : 0.1;
  const auto qx = static_cast<std::uint64_t>(std::llround(c.x / q));
  const auto qy = static_cast<std::uint64_t>(std::llround(c.y / q));
  return static_cast<std::int64_t>(qx * 0x9E3779B97F4A7C15ull ^ qy);
}
}  // namespace

GeneratedParcels generate(const GenerateRequest& request, const ProgressFn& progress) {
  {
    std::string names;
    bool known = false;
    for (const auto& [name, help] : generationStyles()) {
      known = known || name == request.style;
      names += (names.empty() ? "" : ", ") + name;
    }
    if (!known) throw usageError("--style " + request.style + " is not available (styles: " + names + ")");
  }
  const SkeletonParameters skeleton = skeletonParametersFrom(request.parameters);
  const ObbParameters global = obbParametersFrom(request.parameters);
  if (global.aMin > global.aMax) throw usageError("--a-min must not exceed --a-max");
  if (global.wMin > global.wMax) throw usageError("--w-min must not exceed --w-max");
  auto seedIt = request.parameters.find("seed");
  GeneratedParcels out;
  out.seed = seedIt == request.parameters.end() ? 1 : static_cast<std::uint64_t>(seedIt->second);

  // Blocks and their own bounds (NaN where they have none).
  struct Unit {
    std::int64_t blockId;
    Polygon shape;
    ObbParameters p;
    double accessShare;  // of the block's observed parcels; NaN when unknown
  };
  std::vector<Unit> units;
  if (request.fromParcels) {
    analysis::ObservedData loaded;
    if (!request.observed) {
      loaded = analysis::loadObserved(request.input, request.parameters, scaledProgress(progress, 0.0, 0.4));
    }
    const analysis::ObservedData& observed = request.observed ? *request.observed : loaded;
    for (std::size_t b = 0; b < observed.analysis.blocks.size(); ++b) {
      const auto& s = observed.analysis.statistics[b];
      const ObbParameters p = blockParameters(request, s.aMin, s.aMax, s.wMin, s.wMax);
      for (const Polygon& shape : observed.analysis.blocks[b].parts) {
        units.push_back({observed.analysis.blocks[b].id, shape, p, s.streetAccessShare});
      }
    }
    if (request.observed) {
      out.source = request.observed->layer;
    } else {
      out.source = std::move(loaded.layer);
    }
  } else {
    io::ReadOptions in = request.input;
    in.numericFields = {"block_id", "a_min", "a_max", "w_min", "w_max", "street_access_share"};
    out.source = io::readParcels(in, scaledProgress(progress, 0.0, 0.2));
    for (std::size_t i = 0; i < out.source.parcels.size(); ++i) {
      const auto& f = out.source.fields[i];
      const std::int64_t id = std::isfinite(f[0]) ? static_cast<std::int64_t>(f[0]) : out.source.parcels[i].sourceFid;
      units.push_back({id, out.source.parcels[i].shape, blockParameters(request, f[1], f[2], f[3], f[4]), f[5]});
    }
  }
  // Per-block bounds (derived from observed parcels or read from the input) are
  // clamped into the parameters' ranges: a block of tiny slivers can derive an
  // A_max below the 1 m2 minimum, and a zero would make splitting endless.
  const auto& descriptions = obbParameterDescriptions();
  auto clampTo = [&](const char* name, double& value) {
    for (const auto& d : descriptions) {
      if (d.name == name && (value < d.minimum || value > d.maximum)) {
        value = std::clamp(value, d.minimum, d.maximum);
        ++out.clampedBounds;
      }
    }
  };
  for (Unit& u : units) {
    clampTo("a-min", u.p.aMin);
    clampTo("a-max", u.p.aMax);
    clampTo("w-min", u.p.wMin);
    clampTo("w-max", u.p.wMax);
    // A bound the user gave wins over a conflicting per-block one.
    if (request.explicitParameters.count("a-min")) {
      u.p.aMax = std::max(u.p.aMax, u.p.aMin);
    } else {
      u.p.aMin = std::min(u.p.aMin, u.p.aMax);
    }
    if (request.explicitParameters.count("w-min")) {
      u.p.wMax = std::max(u.p.wMax, u.p.wMin);
    } else {
      u.p.wMin = std::min(u.p.wMin, u.p.wMax);
    }
  }

  // Subdivide every block, in parallel; each block's seed depends only on its id.
  out.timings.start("subdivide");
  std::vector<std::string> styles(units.size(), request.style);
  if (request.style == "auto") {
    for (std::size_t k = 0; k < units.size(); ++k) {
      const double share = units[k].accessShare;
      styles[k] = std::isfinite(share) && share < kAutoSkeletonAccessShare ? "obb" : "skeleton";
    }
  }
  // Street widths from the block layout, for the skeleton styles' StreetWidth rule.
  std::vector<StreetWidths> widths;
  if (std::count(styles.begin(), styles.end(), "obb") != static_cast<long>(styles.size())) {
    std::vector<const Polygon*> shapes;
    for (const Unit& u : units) shapes.push_back(&u.shape);
    widths = analysis::streetWidths(shapes);
  }
  std::vector<Subdivision> results(units.size());
  const ProgressFn sub = scaledProgress(progress, request.fromParcels ? 0.4 : 0.2, 0.9);
  parallelFor(
      units.size(),
      [&](std::size_t k) {
        const Unit& u = units[k];
        const std::uint64_t seed = blockSeed(out.seed, positionKey(u.shape, out.source.frame));
        SkeletonParameters p = skeleton;
        p.bounds = u.p;
        results[k] = subdivideBlock(u.shape, styles[k], p, seed, widths.empty() ? StreetWidths{} : widths[k]);
      },
      [&](std::size_t done) {
        reportProgress(sub, static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(1, units.size())),
                       "subdividing");
      });

  for (std::size_t k = 0; k < units.size(); ++k) {
    Block block;
    block.id = static_cast<int>(out.blocks.size());
    block.parts = {units[k].shape};
    for (Polygon& parcel : results[k].parcels) {
      block.parcels.push_back(static_cast<int>(out.parcels.size()));
      out.parcels.push_back(std::move(parcel));
    }
    out.blocks.push_back(std::move(block));
    out.blockIds.push_back(units[k].blockId);
    out.blockStyles.push_back(results[k].fallback ? "obb" : styles[k]);
    out.oversize += results[k].oversize;
    out.withoutAccess += results[k].withoutAccess;
    out.patioParcels += results[k].patioParcels;
    if (results[k].fallback) {
      ++out.fallbackBlocks;
      out.failures.push_back("block " + std::to_string(units[k].blockId) + ": skeleton not usable (" +
                             results[k].fallbackReason + "), subdivided with obb");
    }
    if (results[k].failed) {
      ++out.failedBlocks;
      out.failures.push_back("block " + std::to_string(units[k].blockId) + ": " + results[k].failure);
    }
  }
  reportProgress(progress, 0.9, "measuring");
  out.timings.start("measure");
  const double minFrontage = global.minFrontage;
  out.metrics = analysis::measureParcels(out.parcels, out.blocks, 0.05, minFrontage);
  out.timings.stop();
  reportProgress(progress, 1.0, "measuring");
  return out;
}

Table generatedParcelTable(const GeneratedParcels& g, std::vector<std::vector<Polygon>>* geometries) {
  Table table;
  table.columns = {{"parcel_id", Column::Type::Integer, ""}, {"block_id", Column::Type::Integer, ""}};
  for (Column& c : analysis::metricColumns()) table.columns.push_back(std::move(c));
  for (std::size_t b = 0; b < g.blocks.size(); ++b) {
    for (int i : g.blocks[b].parcels) {
      std::vector<Value> row = {std::int64_t(i), g.blockIds[b]};
      for (Value& v : analysis::metricValues(g.metrics[i])) row.push_back(std::move(v));
      table.rows.push_back(std::move(row));
      if (geometries) geometries->push_back({g.parcels[i]});
    }
  }
  return table;
}

analysis::JobOutcome runGenerate(const GenerateRequest& request, const std::string& outDir,
                                 const ProgressFn& progress) {
  io::OutputDirectory out(outDir, {request.input.path});
  const GeneratedParcels g = generate(request, scaledProgress(progress, 0.0, 0.9));

  reportProgress(progress, 0.9, "writing");
  std::vector<std::vector<Polygon>> geometries;
  const Table table = generatedParcelTable(g, &geometries);
  io::writePolygonLayer(out.stage("parcels.gpkg"), "parcels", geometries, table, g.source.frame, g.source.crs);
  io::writeCsv(out.stage("parcels.csv"), table);

  Json perBlock = Json::array();
  for (const char* name : {"a-min", "a-max", "w-min", "w-max"}) {
    if (!request.explicitParameters.count(name)) perBlock.push(name);
  }
  std::int64_t withAccess = 0;
  for (const auto& m : g.metrics) withAccess += m.streetAccess;
  Json failures = Json::array();
  for (const auto& f : g.failures) failures.push(f);
  Json run = analysis::runRecord("generate", request.parameters)
                 .set("style", request.style)
                 .set("from_parcels", request.fromParcels)
                 .set("seed", static_cast<std::int64_t>(g.seed))
                 .set("per_block_parameters_where_available", perBlock);
  run.set("input", Json::object()
                       .set("path", g.source.path)
                       .set("layer", g.source.layerName)
                       .set("crs", g.source.crs.name)
                       .set("local_frame", g.source.frame.describe()));
  run.set("counts", Json::object()
                        .set("blocks", static_cast<std::int64_t>(g.blocks.size()))
                        .set("blocks_failed", g.failedBlocks)
                        .set("parcels", static_cast<std::int64_t>(g.parcels.size()))
                        .set("parcels_oversize", g.oversize)
                        .set("parcels_without_street_access", g.withoutAccess)
                        .set("patio_parcels", g.patioParcels)
                        .set("blocks_fallback_obb", g.fallbackBlocks)
                        .set("per_block_bounds_clamped", g.clampedBounds)
                        .set("parcels_with_street_access_measured", withAccess));
  Json styleCounts = Json::object();
  for (const auto& [name, help] : generationStyles()) {
    const auto n = std::count(g.blockStyles.begin(), g.blockStyles.end(), name);
    if (n > 0) styleCounts.set(name, static_cast<std::int64_t>(n));
  }
  run.set("blocks_by_style", styleCounts);
  run.set("failures", failures);
  run.set("outputs", Json::array().push("parcels.gpkg").push("parcels.csv").push("run.json"));
  io::writeJson(out.stage("run.json"), run);
  out.commit();
  reportProgress(progress, 1.0, "writing");
  std::string summary = std::to_string(g.blocks.size()) + " blocks of " + g.source.path + " subdivided (" +
                        request.style + ", seed " + std::to_string(g.seed) + ") into " +
                        std::to_string(g.parcels.size()) + " parcels\n  " + std::to_string(g.oversize) +
                        " oversize (no admissible split), " + std::to_string(g.withoutAccess) +
                        " without street access (" + std::to_string(g.patioParcels) + " patio parcels), " +
                        std::to_string(g.fallbackBlocks) + " blocks fell back to obb, " +
                        std::to_string(g.failedBlocks) + " blocks refused";
  for (const auto& f : g.failures) summary += "\n  " + f;
  return {run, summary};
}

}  // namespace parcelscope::generation
