#include "parcelscope/pipeline/GenerateJob.h"

#include "parcelscope/pipeline/StreetsJob.h"

#include "parcelscope/pipeline/BlockSource.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "parcelscope/analysis/StreetWidth.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"

namespace parcelscope::pipeline {

using namespace generation;

namespace {
// m: edges of generated parcels this close count as shared (they share them exactly).
constexpr double kContactTolerance = 0.05;

}  // namespace

namespace {

void checkStyle(const std::string& style, bool allowAuto, const std::string& where = "") {
  std::string names;
  bool known = false;
  for (const auto& [name, help] : generationStyles()) {
    if (name == "auto" && !allowAuto) continue;
    known = known || name == style;
    names += (names.empty() ? "" : ", ") + name;
  }
  if (!known) {
    throw usageError((where.empty() ? "--style " : where + ": style ") + style + " is not available (styles: " + names +
                     ")");
  }
}

std::uint64_t runSeed(const ParameterValues& values) {
  const auto it = values.find("seed");
  return it == values.end() ? 1 : static_cast<std::uint64_t>(it->second);
}

}  // namespace

Key planKey(const BlockPlan& plan) {
  Key h = hashBytes(plan.style);
  for (const auto& [name, v] : plan.values) {
    h = hashBytes(name, mixKeys(h, name.size()));
    h = hashBytes(std::string_view(reinterpret_cast<const char*>(&v), sizeof v), h);
  }
  return mixKeys(h, plan.seed);
}

bool BlockPlan::operator==(const BlockPlan& o) const {
  return style == o.style && seed == o.seed && values == o.values;
}

BlockInputs prepareBlocks(const GenerateRequest& request, const ProgressFn& progress) {
  return blockSourceOf(request)->blocks(progress);
}

const std::vector<StreetWidths>& streetWidthsOf(BlockInputs& inputs) {
  if (inputs.widths.size() != inputs.entries.size()) {
    std::vector<const Polygon*> shapes;
    for (const auto& e : inputs.entries) shapes.push_back(&e.shape);
    inputs.widths = analysis::streetWidths(shapes);
  }
  return inputs.widths;
}

void requireStyle(const std::string& style) { checkStyle(style, true); }

std::string clampedBoundsNote(std::int64_t clamped) {
  return std::to_string(clamped) +
         " per-block bounds outside their parameter's range (an A_max below 1 m2 from a block of slivers, a "
         "negative A_min) were moved to the range's end (run.json: per_block_bounds_clamped)";
}

namespace {
// The generator parameters of `values` in their ranges and the bound pairs in
// order. The run's values also hold analysis and comparison parameters; an
// override holds generator parameters only (strict).
void checkGeneratorValues(const ParameterValues& values, const std::string& where, bool strict) {
  static const std::vector<ParameterDescription> descriptions = generationParameterDescriptions();
  for (const auto& [name, v] : values) {
    const auto d = std::find_if(descriptions.begin(), descriptions.end(),
                                [&](const ParameterDescription& x) { return x.name == name; });
    if (d == descriptions.end()) {
      if (!strict) continue;
      throw usageError(where + ": no generator parameter named '" + name + "'");
    }
    checkValue(*d, v);
  }
  const ObbParameters p = obbParametersFrom(values);
  if (p.aMin > p.aMax) throw usageError((where.empty() ? "" : where + ": ") + "--a-min must not exceed --a-max");
  if (p.wMin > p.wMax) throw usageError((where.empty() ? "" : where + ": ") + "--w-min must not exceed --w-max");
}
}  // namespace

void requireGeneratorParameters(const ParameterValues& values) { checkGeneratorValues(values, "", false); }

std::vector<BlockPlan> planBlocks(const GenerateRequest& request, const BlockInputs& inputs,
                                  std::int64_t* clampedBounds, const std::vector<char>* skip) {
  checkStyle(request.style, true);
  const auto check = checkGeneratorValues;
  check(request.parameters, "", false);
  std::set<std::int64_t> ids;
  std::set<Key> keys;
  for (const auto& e : inputs.entries) {
    ids.insert(e.blockId);
    keys.insert(e.blockKey);
  }
  std::vector<std::pair<std::string, const BlockOverride*>> overrides;
  for (const auto& [key, o] : request.overrides) {
    const std::string where = "block " + keyText(key);
    if (!keys.count(key)) throw usageError(where + ": no such block (override)");
    overrides.emplace_back(where, &o);
  }
  for (const auto& [id, o] : request.overridesById) {
    const std::string where = "block " + std::to_string(id);
    if (!ids.count(id)) throw usageError(where + ": no such block (override)");
    overrides.emplace_back(where, &o);
  }
  for (const auto& [where, override] : overrides) {
    const BlockOverride& o = *override;
    if (!o.style.empty()) checkStyle(o.style, true, where);
    ParameterValues merged = request.parameters;
    for (const auto& [name, v] : o.parameters) merged[name] = v;
    check(o.parameters, where, true);
    check(merged, where, false);
  }

  // Per-block bounds (derived from observed parcels or read from the input) are
  // clamped into the parameters' ranges: a block of tiny slivers can derive an
  // A_max below the 1 m2 minimum, and a zero would make splitting endless.
  const auto& ranges = obbParameterDescriptions();
  std::int64_t clamped = 0;
  auto clampTo = [&](const char* name, double& value) {
    for (const auto& d : ranges) {
      if (d.name == name && (value < d.minimum || value > d.maximum)) {
        value = std::clamp(value, d.minimum, d.maximum);
        ++clamped;
      }
    }
  };
  std::vector<BlockPlan> plans(inputs.entries.size());
  for (std::size_t k = 0; k < inputs.entries.size(); ++k) {
    if (skip && k < skip->size() && (*skip)[k]) continue;
    const BlockInputs::Entry& e = inputs.entries[k];
    const BlockOverride* override = nullptr;
    if (const auto byKey = request.overrides.find(e.blockKey); byKey != request.overrides.end()) {
      override = &byKey->second;
    } else if (const auto byId = request.overridesById.find(e.blockId); byId != request.overridesById.end()) {
      override = &byId->second;
    }
    const bool overridden = override != nullptr;
    ParameterValues values;
    std::set<std::string> given;
    if (overridden) {
      values = request.parameters;
      given = request.explicitParameters;
      for (const auto& [name, v] : override->parameters) {
        values[name] = v;
        given.insert(name);
      }
    }
    const ParameterValues& v = overridden ? values : request.parameters;
    const std::set<std::string>& explicitNames = overridden ? given : request.explicitParameters;

    ObbParameters p = obbParametersFrom(v);
    auto pick = [&](const char* name, double perBlock, double& target) {
      if (!explicitNames.count(name) && std::isfinite(perBlock)) {
        target = perBlock;
        clampTo(name, target);
      }
    };
    pick("a-min", e.aMin, p.aMin);
    pick("a-max", e.aMax, p.aMax);
    pick("w-min", e.wMin, p.wMin);
    pick("w-max", e.wMax, p.wMax);
    // A bound the user gave wins over a conflicting per-block one.
    if (explicitNames.count("a-min")) {
      p.aMax = std::max(p.aMax, p.aMin);
    } else {
      p.aMin = std::min(p.aMin, p.aMax);
    }
    if (explicitNames.count("w-min")) {
      p.wMax = std::max(p.wMax, p.wMin);
    } else {
      p.wMin = std::min(p.wMin, p.wMax);
    }

    BlockPlan& plan = plans[k];
    const Style& chosen = style(overridden && !override->style.empty() ? override->style : request.style);
    const Style& concrete = chosen.resolve({e.accessShare, &e.shape, e.observed.get(), e.observedShare});
    plan.style = concrete.name();
    plan.values = styleValues(concrete, v);
    chosen.pinValues(plan.values);
    plan.values["a-min"] = p.aMin;
    plan.values["a-max"] = p.aMax;
    plan.values["w-min"] = p.wMin;
    plan.values["w-max"] = p.wMax;
    plan.seed = blockSeed(runSeed(v), static_cast<std::int64_t>(partKey(e.blockKey, e.part)));
  }
  if (clampedBounds) *clampedBounds = clamped;
  return plans;
}

namespace {

// Runs the plan's style on the entry, with what `previous` (made under
// `previousPlan`) left to reuse.
Subdivision subdivideEntry(const BlockInputs& inputs, std::size_t entry, const BlockPlan& plan,
                           const Subdivision* previous = nullptr, const BlockPlan* previousPlan = nullptr,
                           bool record = false) {
  const Style& s = style(plan.style);
  static const StreetWidths kNone;
  const bool widths = s.usesStreetWidths() && inputs.widths.size() == inputs.entries.size();
  StyleRun run{inputs.entries[entry].shape, plan.values, plan.seed, widths ? inputs.widths[entry] : kNone};
  if (previous && previousPlan) {
    run.previous = previous;
    run.previousStyle = &previousPlan->style;
    run.previousValues = &previousPlan->values;
    run.previousSeed = previousPlan->seed;
  }
  run.record = record;
  run.observed = inputs.entries[entry].observed.get();
  run.observedShare = inputs.entries[entry].observedShare;
  return s.subdivide(run);
}

Block entryBlock(const BlockInputs& inputs, std::size_t entry, std::size_t parcels) {
  Block block;
  block.parts = {inputs.entries[entry].shape};
  for (std::size_t i = 0; i < parcels; ++i) block.parcels.push_back(static_cast<int>(i));
  return block;
}

std::vector<analysis::ParcelMetrics> measureEntry(const BlockInputs& inputs, std::size_t entry, const Subdivision& s,
                                                  double minFrontage) {
  return analysis::measureParcels(s.parcels, {entryBlock(inputs, entry, s.parcels.size())}, kContactTolerance,
                                  minFrontage);
}

}  // namespace

namespace {
bool sameParcels(const std::vector<Polygon>& a, const std::vector<Polygon>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), sameVertices);
}
}  // namespace

BlockOutcome runBlock(const BlockInputs& inputs, std::size_t entry, const BlockPlan& plan, double minFrontage,
                      const BlockReuse& reuse) {
  BlockOutcome o;
  const BlockOutcome* previous = reuse.previous && reuse.previousPlan ? reuse.previous : nullptr;
  o.subdivision = subdivideEntry(inputs, entry, plan, previous ? &previous->subdivision : nullptr,
                                 previous ? reuse.previousPlan : nullptr, reuse.record);
  if (previous && sameParcels(o.subdivision.parcels, previous->subdivision.parcels)) {
    o.metrics = previous->metrics;  // the same parcels in the same block: the same measurements
    o.contextMeasured = previous->contextMeasured;
    if (!reuse.shapesOnly) measureOutcomeContext(inputs, entry, o, minFrontage);  // when still deferred
  } else if (reuse.shapesOnly) {
    o.metrics = analysis::measureShapes(o.subdivision.parcels);
    o.contextMeasured = false;
  } else {
    o.metrics = measureEntry(inputs, entry, o.subdivision, minFrontage);
  }
  return o;
}

void measureOutcomeContext(const BlockInputs& inputs, std::size_t entry, BlockOutcome& outcome, double minFrontage) {
  if (outcome.contextMeasured) return;
  const std::vector<Polygon>& parcels = outcome.subdivision.parcels;
  analysis::measureContext(parcels, {entryBlock(inputs, entry, parcels.size())}, kContactTolerance, minFrontage,
                           outcome.metrics);
  outcome.contextMeasured = true;
}

GeneratedParcels assembleParcels(const BlockInputs& inputs, const std::vector<BlockPlan>& plans,
                                 const std::vector<const BlockOutcome*>& outcomes, std::uint64_t seed) {
  if (plans.size() != inputs.entries.size() || outcomes.size() != inputs.entries.size()) {
    throw std::logic_error("assembleParcels: one plan and one outcome per block entry");
  }
  GeneratedParcels out;
  out.source = inputs.source;
  out.streets = inputs.streets;
  out.seed = seed;
  const std::size_t n = inputs.entries.size();
  std::vector<std::size_t> first(n + 1, 0);  // index of each entry's first parcel
  for (std::size_t k = 0; k < n; ++k) first[k + 1] = first[k] + outcomes[k]->subdivision.parcels.size();
  // The copies, entry by entry in parallel into their own slots.
  out.parcels.resize(first[n]);
  out.metrics.resize(first[n]);
  out.blocks.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (!outcomes[k]->contextMeasured) out.contextPending.push_back(k);
    if (!outcomes[k]->written.empty() && out.written.empty()) out.written.resize(first[n]);
  }
  parallelFor(n, [&](std::size_t k) {
    const BlockOutcome& o = *outcomes[k];
    if (o.metrics.size() != o.subdivision.parcels.size()) {
      throw std::logic_error("assembleParcels: block entry " + std::to_string(k) + " is not measured");
    }
    Block& block = out.blocks[k];
    block.id = static_cast<int>(k);
    block.parts = {inputs.entries[k].shape};
    block.parcels.resize(o.subdivision.parcels.size());
    for (std::size_t i = 0; i < o.subdivision.parcels.size(); ++i) {
      block.parcels[i] = static_cast<int>(first[k] + i);
      out.parcels[first[k] + i] = o.subdivision.parcels[i];
    }
    std::copy(o.metrics.begin(), o.metrics.end(), out.metrics.begin() + static_cast<std::ptrdiff_t>(first[k]));
    if (!o.written.empty()) {
      if (o.written.size() != o.subdivision.parcels.size()) {
        throw std::logic_error("assembleParcels: block entry " + std::to_string(k) +
                               " has not one file geometry a parcel");
      }
      std::copy(o.written.begin(), o.written.end(), out.written.begin() + static_cast<std::ptrdiff_t>(first[k]));
    }
  });
  out.blockIds.reserve(n);
  out.blockKeys.reserve(n);
  out.blockStyles.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Subdivision& s = outcomes[k]->subdivision;
    const std::int64_t id = inputs.entries[k].blockId;
    out.blockIds.push_back(id);
    out.blockKeys.push_back(inputs.entries[k].blockKey);
    out.blockStyles.push_back(s.fallback ? "obb" : plans[k].style);
    if (!s.variant.empty()) ++out.blocksByVariant[s.variant];
    out.oversize += s.oversize;
    out.withoutAccess += s.withoutAccess;
    out.patioParcels += s.patioParcels;
    if (s.targetParcels > 0) {
      ++out.blocksWithTarget;
      out.blocksAtTarget += static_cast<int>(s.parcels.size()) == s.targetParcels;
    }
    if (s.unassignedParcels > 0) {
      out.unassigned.resize(out.parcels.size(), 0);
      const std::vector<int>& in = out.blocks[k].parcels;
      for (std::size_t i = in.size() - static_cast<std::size_t>(s.unassignedParcels); i < in.size(); ++i) {
        out.unassigned[static_cast<std::size_t>(in[i])] = 1;
        out.unassignedArea += out.metrics[static_cast<std::size_t>(in[i])].area;
      }
      out.unassignedParcels += s.unassignedParcels;
    }
    if (s.fallback) {
      ++out.fallbackBlocks;
      out.failures.push_back("block " + std::to_string(id) + ": " + plans[k].style + " not usable (" +
                             s.fallbackReason + "), subdivided with obb");
    }
    if (s.failed) {
      ++out.failedBlocks;
      out.failures.push_back("block " + std::to_string(id) + ": " + s.failure);
    }
  }
  return out;
}

Json variantCounts(const std::map<std::string, std::int64_t>& blocksByVariant) {
  Json counts = Json::object();
  for (const auto& [variant, n] : blocksByVariant) counts.set(variant, n);
  return counts;
}

GeneratedParcels generate(const GenerateRequest& request, const ProgressFn& progress) {
  checkStyle(request.style, true);
  requireGeneratorParameters(request.parameters);  // before the input is read
  BlockInputs inputs = prepareBlocks(request, scaledProgress(progress, 0.0, request.fromParcels ? 0.4 : 0.2));
  std::int64_t clamped = 0;
  const std::vector<BlockPlan> plans = planBlocks(request, inputs, &clamped);
  Timings timings;
  timings.start("subdivide");
  if (std::any_of(plans.begin(), plans.end(), [](const BlockPlan& p) { return style(p.style).usesStreetWidths(); })) {
    streetWidthsOf(inputs);
  }
  // Every block in parallel; each block's seed depends only on its position.
  // Entries made elsewhere under the same plan are taken as they are.
  std::vector<BlockOutcome> outcomes(plans.size());
  std::vector<std::size_t> todo;
  std::int64_t premade = 0, reused = 0;
  for (std::size_t k = 0; k < plans.size(); ++k) {
    if (request.premade && k < request.premade->size() && (*request.premade)[k].made &&
        (*request.premade)[k].plan == planKey(plans[k])) {
      outcomes[k] = std::move((*request.premade)[k].outcome);
      (*request.premade)[k] = PremadeBlock{};
      ++premade;
      continue;
    }
    if (request.reusable && k < request.reusable->byEntry.size()) {
      const auto& made = request.reusable->byEntry[k];
      const auto it = made.find(planKey(plans[k]));
      if (it != made.end()) {
        outcomes[k] = it->second;
        ++reused;
        continue;
      }
    }
    todo.push_back(k);
  }
  const ProgressFn sub = scaledProgress(progress, request.fromParcels ? 0.4 : 0.2, 0.9);
  const auto fraction = [&](std::size_t done) {
    return static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(1, todo.size()));
  };
  parallelFor(
      todo.size(),
      [&](std::size_t t) { outcomes[todo[t]].subdivision = subdivideEntry(inputs, todo[t], plans[todo[t]]); },
      [&](std::size_t done) { reportProgress(sub, fraction(done), "subdividing"); });
  reportProgress(progress, 0.9, "measuring");
  timings.start("measure");
  const double minFrontage = obbParametersFrom(request.parameters).minFrontage;
  parallelFor(todo.size(), [&](std::size_t t) {
    outcomes[todo[t]].metrics = measureEntry(inputs, todo[t], outcomes[todo[t]].subdivision, minFrontage);
  });
  std::vector<const BlockOutcome*> pointers;
  for (const BlockOutcome& o : outcomes) pointers.push_back(&o);
  GeneratedParcels out = assembleParcels(inputs, plans, pointers, runSeed(request.parameters));
  if (request.keep) {
    request.keep->byEntry.resize(std::max(request.keep->byEntry.size(), plans.size()));
    for (std::size_t k = 0; k < plans.size(); ++k) {
      request.keep->byEntry[k].emplace(planKey(plans[k]), std::move(outcomes[k]));
    }
  }
  timings.stop();
  out.clampedBounds = clamped;
  out.premadeBlocks = premade;
  out.reusedBlocks = reused;
  out.timings = timings;
  reportProgress(progress, 1.0, "measuring");
  return out;
}

std::vector<int> GeneratedParcels::assignedOf(const std::vector<int>& list) const {
  if (unassigned.empty()) return list;
  std::vector<int> out;
  out.reserve(list.size());
  for (int i : list) {
    if (!unassigned[static_cast<std::size_t>(i)]) out.push_back(i);
  }
  return out;
}

RowSource generatedParcelRows(const GeneratedParcels& g, std::vector<int>* parcelOfRow) {
  RowSource table;
  table.columns = {{"parcel_id", Column::Type::Integer, ""},
                   {"parcel_key", Column::Type::String, ""},
                   {"block_id", Column::Type::Integer, ""},
                   {"block_key", Column::Type::String, ""},
                   {"role", Column::Type::String, ""}};  // "parcel", or "unassigned" land
  for (Column& c : analysis::metricColumns()) table.columns.push_back(std::move(c));
  // Per row: its parcel, its entry of g.blocks and its index in the block
  // (multipart blocks span entries and number their parcels on).
  struct Place {
    int parcel;
    int entry;
    int index;
  };
  auto places = std::make_shared<std::vector<Place>>();
  std::map<Key, int> inBlock;
  for (std::size_t b = 0; b < g.blocks.size(); ++b) {
    int& index = inBlock[g.blockKeys[b]];
    for (int i : g.blocks[b].parcels) {
      places->push_back({i, static_cast<int>(b), index++});
      if (parcelOfRow) parcelOfRow->push_back(i);
    }
  }
  table.rows = places->size();
  table.row = [&g, places](std::size_t r, std::vector<Value>& row) {
    const Place& p = (*places)[r];
    const auto b = static_cast<std::size_t>(p.entry);
    const std::string blockKey = keyText(g.blockKeys[b]);
    row = {std::int64_t(p.parcel), blockKey + "-" + std::to_string(p.index), g.blockIds[b], blockKey,
           std::string(g.isUnassigned(static_cast<std::size_t>(p.parcel)) ? "unassigned" : "parcel")};
    for (Value& v : analysis::metricValues(g.metrics[static_cast<std::size_t>(p.parcel)])) row.push_back(std::move(v));
  };
  return table;
}

Table generatedParcelTable(const GeneratedParcels& g, std::vector<std::vector<Polygon>>* geometries) {
  std::vector<int> order;
  Table table = generatedParcelRows(g, &order).table();
  if (geometries) {
    for (int i : order) geometries->push_back({g.parcels[static_cast<std::size_t>(i)]});
  }
  return table;
}

namespace {
JobOutcome writeGenerate(io::OutputDirectory& out, const GenerateRequest& request, const ProgressFn& progress) {
  const GeneratedParcels g = generate(request, scaledProgress(progress, 0.0, 0.9));

  reportProgress(progress, 0.9, "writing");
  std::vector<std::vector<Polygon>> geometries;
  const Table table = generatedParcelTable(g, &geometries);
  const io::LayerWrite written =
      io::writePolygonLayer(out.stage("parcels.gpkg"), "parcels", geometries, table, g.source->frame, g.source->crs);
  io::writeCsv(out.stage("parcels.csv"), table);

  Json perBlock = Json::array();
  for (const char* name : {"a-min", "a-max", "w-min", "w-max"}) {
    if (!request.explicitParameters.count(name)) perBlock.push(name);
  }
  std::int64_t withAccess = 0;
  for (const auto& m : g.metrics) withAccess += m.streetAccess;
  Json failures = Json::array();
  for (const auto& f : g.failures) failures.push(f);
  Json run = pipeline::runRecord("generate", request.parameters)
                 .set("style", request.style)
                 .set("from_parcels", request.fromParcels)
                 .set("block_source", blockSourceOf(request)->kind())
                 .set("seed", static_cast<std::int64_t>(g.seed))
                 .set("per_block_parameters_where_available", perBlock);
  run.set("input", Json::object()
                       .set("path", g.source->path)
                       .set("layer", g.source->layerName)
                       .set("crs", g.source->crs.name)
                       .set("local_frame", g.source->frame.describe()));
  run.set("counts", Json::object()
                        .set("blocks", static_cast<std::int64_t>(g.blocks.size()))
                        .set("blocks_failed", g.failedBlocks)
                        .set("parcels", static_cast<std::int64_t>(g.parcels.size()))
                        .set("parcels_oversize", g.oversize)
                        .set("parcels_without_street_access", g.withoutAccess)
                        .set("patio_parcels", g.patioParcels)
                        .set("unassigned_parcels", g.unassignedParcels)
                        .set("unassigned_area_m2", g.unassignedArea)
                        .set("blocks_with_target_count", g.blocksWithTarget)
                        .set("blocks_at_target_count", g.blocksAtTarget)
                        .set("blocks_fallback_obb", g.fallbackBlocks)
                        .set("per_block_bounds_clamped", g.clampedBounds)
                        .set("parcels_with_street_access_measured", withAccess));
  Json styleCounts = Json::object();
  for (const auto& [name, help] : generationStyles()) {
    const auto n = std::count(g.blockStyles.begin(), g.blockStyles.end(), name);
    if (n > 0) styleCounts.set(name, static_cast<std::int64_t>(n));
  }
  run.set("blocks_by_style", styleCounts);
  if (!g.blocksByVariant.empty()) run.set("blocks_by_template", variantCounts(g.blocksByVariant));
  if (g.streets) run.set("streets", streetRecord(*g.streets));
  run.set("failures", failures);
  run.set("written", writtenLayersJson({{"parcels.gpkg", written}}));
  run.set("outputs", Json::array().push("parcels.gpkg").push("parcels.csv").push("run.json"));
  io::writeJson(out.stage("run.json"), run);
  out.commit();
  reportProgress(progress, 1.0, "writing");
  std::string summary =
      std::to_string(g.blocks.size()) + " blocks of " + g.source->path + " subdivided (" + request.style + ", seed " +
      std::to_string(g.seed) + ") into " + std::to_string(g.parcels.size()) + " parcels\n  " +
      std::to_string(g.oversize) + " oversize (no admissible split), " + std::to_string(g.withoutAccess) +
      " without street access (" + std::to_string(g.patioParcels) + " patio parcels), " +
      (g.unassignedParcels > 0 ? std::to_string(g.unassignedParcels) + " unassigned, " : "") +
      (g.blocksWithTarget > 0
           ? std::to_string(g.blocksAtTarget) + " of " + std::to_string(g.blocksWithTarget) + " blocks at their count, "
           : "") +
      std::to_string(g.fallbackBlocks) + " blocks fell back to obb, " + std::to_string(g.failedBlocks) +
      " blocks refused";
  if (g.clampedBounds > 0) summary += "\n  " + clampedBoundsNote(g.clampedBounds);
  for (const auto& f : g.failures) summary += "\n  " + f;
  return {run, summary};
}

}  // namespace

JobOutcome runGenerate(const GenerateRequest& request, const std::string& outDir, const ProgressFn& progress) {
  io::OutputDirectory out(outDir, {request.input.path});
  try {
    return writeGenerate(out, request, progress);
  } catch (const Error& e) {
    throw out.explain(e);  // a writer's error names --out, not the staging folder, with its cause
  }
}

}  // namespace parcelscope::pipeline
