#include "parcelscope/pipeline/CompareSession.h"

#include "parcelscope/pipeline/StreetsJob.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>

#include "CompareStages.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/io/Writers.h"

namespace parcelscope::pipeline {

namespace {

using detail::secondsSince;

std::uint64_t runSeedOf(const CompareRequest& request) {
  const auto it = request.parameters.find("seed");
  return it == request.parameters.end() ? 1 : static_cast<std::uint64_t>(it->second);
}

bool sameInput(const io::ReadOptions& a, const io::ReadOptions& b) {
  return a.path == b.path && a.layer == b.layer && a.where == b.where && a.crsOverride == b.crsOverride &&
         a.keyField == b.keyField;
}

bool sameStreets(const std::optional<io::StreetReadOptions>& a, const std::optional<io::StreetReadOptions>& b) {
  if (!a || !b) return !a && !b;
  return a->path == b->path && a->layer == b->layer && a->where == b->where && a->crsOverride == b->crsOverride &&
         a->widthField == b->widthField && a->classField == b->classField && a->classWidths == b->classWidths &&
         a->nameField == b->nameField && a->noNodeWhere == b->noNodeWhere;
}

// Analysis and street parameters that shape the blocks (all but k, which only
// moves the bounds), and the streets.
bool sameBlocks(const CompareRequest& a, const CompareRequest& b) {
  for (const auto& d : analysis::analysisParameters()) {
    if (d.name != "k" && compareValue(a, d.name) != compareValue(b, d.name)) return false;
  }
  if (!sameStreets(a.streets, b.streets)) return false;
  if (a.streets) {
    for (const auto& d : pipeline::streetParameters()) {
      if (compareValue(a, d.name) != compareValue(b, d.name)) return false;
    }
  }
  return true;
}

// Which observed blocks' comparisons a new result may take from the last one:
// all but the blocks of changed entries and the stale ones.
std::vector<char> comparisonsToKeep(std::size_t blocks, const pipeline::BlockInputs& inputs,
                                    const std::vector<char>& changedEntries, const std::set<std::int64_t>& stale) {
  std::vector<char> keep(blocks, 1);
  for (std::size_t e = 0; e < changedEntries.size(); ++e) {
    if (changedEntries[e]) keep[static_cast<std::size_t>(inputs.entries[e].blockId)] = 0;
  }
  for (std::int64_t id : stale) {
    if (id >= 0 && static_cast<std::size_t>(id) < keep.size()) keep[static_cast<std::size_t>(id)] = 0;
  }
  return keep;
}

// Measures the deferred context of `entries` in place. Their blocks join
// `stale` first: the outcomes are shared with the state, so should anything
// throw later (a cancel included), the last result's comparisons of those
// blocks are not reused.
void measureDeferred(const pipeline::BlockInputs& inputs,
                     const std::vector<std::shared_ptr<pipeline::BlockOutcome>>& outcomes,
                     const std::vector<std::size_t>& entries, double minFrontage, const ProgressFn& progress,
                     std::set<std::int64_t>& stale) {
  for (std::size_t k : entries) stale.insert(inputs.entries[k].blockId);
  parallelFor(
      entries.size(),
      [&](std::size_t t) { pipeline::measureOutcomeContext(inputs, entries[t], *outcomes[entries[t]], minFrontage); },
      progress ? std::function<void(std::size_t)>([&](std::size_t n) {
        reportProgress(progress, static_cast<double>(n) / static_cast<double>(entries.size()), "measuring context");
      })
               : std::function<void(std::size_t)>());
}

bool sameSample(const generation::ObservedSample* a, const generation::ObservedSample* b) {
  if (!a || !b) return a == b;
  return *a == *b;
}

// Fills `outcomes` and `done` of the new entries from the old ones that hold
// the same block part (key and part), shape, plan and observed sample.
void carryOver(const pipeline::BlockInputs& oldInputs, const std::vector<pipeline::BlockPlan>& oldPlans,
               const std::vector<std::shared_ptr<pipeline::BlockOutcome>>& oldOutcomes,
               const pipeline::BlockInputs& inputs, const std::vector<pipeline::BlockPlan>& plans,
               std::vector<std::shared_ptr<pipeline::BlockOutcome>>& outcomes, std::vector<pipeline::BlockPlan>& done) {
  std::map<std::pair<Key, int>, std::size_t> old;
  for (std::size_t k = 0; k < oldInputs.entries.size() && k < oldOutcomes.size(); ++k) {
    old.emplace(std::make_pair(oldInputs.entries[k].blockKey, oldInputs.entries[k].part), k);
  }
  for (std::size_t k = 0; k < inputs.entries.size(); ++k) {
    const auto& e = inputs.entries[k];
    const auto it = old.find({e.blockKey, e.part});
    if (it == old.end()) continue;
    const std::size_t j = it->second;
    if (!oldOutcomes[j] || oldPlans[j] != plans[k] || !sameVertices(oldInputs.entries[j].shape, e.shape)) continue;
    // What the styles read of the observed parcels (the skeleton's slice
    // widths, the offset depth): a street block keeps its key and shape when
    // the parcels in it change.
    if (!sameSample(oldInputs.entries[j].observed.get(), e.observed.get())) continue;
    if (generation::style(plans[k].style).usesStreetWidths()) {
      const bool widths = inputs.widths.size() == inputs.entries.size() &&
                          oldInputs.widths.size() == oldInputs.entries.size() &&
                          generation::sameStreetWidths(inputs.widths[k], oldInputs.widths[j]);
      if (!widths) continue;
    }
    outcomes[k] = oldOutcomes[j];
    done[k] = oldPlans[j];
  }
}

}  // namespace

struct CompareSession::State {
  CompareRequest request;  // of the last completed update
  std::shared_ptr<const pipeline::ObservedData> observed;
  pipeline::BlockInputs inputs;
  std::vector<pipeline::BlockPlan> plans;  // one per entry; outcomes[k] was made with plans[k]
  // Owned by the session alone (results hold copies), so completeContext can
  // fill in what an update deferred.
  std::vector<std::shared_ptr<pipeline::BlockOutcome>> outcomes;
  std::shared_ptr<const CompareResult> current;
  // Blocks whose parcels a cancelled update replaced: current->blocks still
  // compares their old parcels, so their comparison is not reused.
  std::set<std::int64_t> staleComparisons;
  // False after a cancelled update: outcomes and plans then hold blocks of a
  // request current was not made from, until the next update commits.
  bool outcomesMatchCurrent = true;
};

CompareSession::CompareSession() : state_(std::make_unique<State>()) {}
CompareSession::~CompareSession() = default;

std::shared_ptr<const CompareResult> CompareSession::current() const { return state_->current; }

CompareSession::Update CompareSession::update(const CompareRequest& request, const ProgressFn& progress,
                                              const PartialFn& partial, double partialSeconds, bool deferContext) {
  const auto started = std::chrono::steady_clock::now();
  detail::checkRequest(request);
  State& s = *state_;
  Update u;

  // Observed data: read and analysed again only when the blocks would differ.
  const bool reload = !s.observed || !sameInput(s.request.input, request.input) || !sameBlocks(s.request, request);
  const analysis::BoundsRule rule(compareValue(request, "k"), compareValue(request, "derive") != 0);
  const bool rederive =
      !reload && analysis::BoundsRule(compareValue(s.request, "k"), compareValue(s.request, "derive") != 0) != rule;
  std::shared_ptr<const pipeline::ObservedData> observed = s.observed;
  double readSeconds = 0, blockSeconds = 0;
  if (reload) {
    auto loaded = std::make_shared<pipeline::ObservedData>(
        pipeline::loadObservedInStreetBlocks(request.input, request.streets ? &*request.streets : nullptr,
                                             request.parameters, scaledProgress(progress, 0.0, 0.5)));
    detail::requireBlocks(request, *loaded);
    for (const auto& stage : loaded->layer.timings.stages()) readSeconds += stage.second;
    for (const auto& stage : loaded->analysis.timings.stages()) blockSeconds += stage.second;
    observed = std::move(loaded);
  } else if (rederive) {
    auto copy = std::make_shared<pipeline::ObservedData>(*observed);
    analysis::rederiveBlockBounds(copy->analysis, rule);
    observed = std::move(copy);
  }
  pipeline::BlockInputs fresh;
  const bool newInputs = reload || rederive;
  if (newInputs) fresh = pipeline::prepareBlocks(detail::generateRequest(request, observed.get()));
  pipeline::BlockInputs& inputs = newInputs ? fresh : s.inputs;
  if (newInputs && !reload) inputs.widths = s.inputs.widths;  // same blocks, same streets

  // Plans, and the entries whose plan changed.
  const auto generateStart = std::chrono::steady_clock::now();
  const pipeline::GenerateRequest g = detail::generateRequest(request, observed.get());
  std::int64_t clamped = 0;
  const std::vector<pipeline::BlockPlan> plans = pipeline::planBlocks(g, inputs, &clamped);
  if (std::any_of(plans.begin(), plans.end(),
                  [](const auto& p) { return generation::style(p.style).usesStreetWidths(); })) {
    pipeline::streetWidthsOf(inputs);
  }
  std::vector<std::shared_ptr<pipeline::BlockOutcome>> outcomes =
      reload ? std::vector<std::shared_ptr<pipeline::BlockOutcome>>(plans.size()) : s.outcomes;
  std::vector<pipeline::BlockPlan> done = reload ? std::vector<pipeline::BlockPlan>(plans.size()) : s.plans;
  // A reload (another input, or blocks built anew) keeps the outcomes of the
  // blocks that are the same block by key, the same shape to the bit, with the
  // same plan (and street widths, for the skeleton styles): an edit of the
  // input, or its features in another order, regenerates only what changed.
  if (reload && s.outcomesMatchCurrent) carryOver(s.inputs, s.plans, s.outcomes, inputs, plans, outcomes, done);
  std::vector<std::size_t> todo;
  for (std::size_t k2 = 0; k2 < plans.size(); ++k2) {
    if (!outcomes[k2] || done[k2] != plans[k2]) todo.push_back(k2);
  }
  const double minFrontage = compareValue(request, "min-frontage");
  std::vector<std::shared_ptr<pipeline::BlockOutcome>> made(todo.size());
  const bool shapesOnly = deferContext && !analysis::parcelQuantity(request.metric).context;
  // Set (release) once made[t] is written, so the progress tick may read it.
  std::unique_ptr<std::atomic<bool>[]> ready(new std::atomic<bool>[todo.size()]);
  for (std::size_t t = 0; t < todo.size(); ++t) ready[t] = false;
  // Per-block comparisons of the last result are reused for blocks that did
  // not change, when the bins are the same.
  const bool sameBins = s.current && compareValue(s.request, "bins") == compareValue(request, "bins") &&
                        compareValue(s.request, "histogram-quantile") == compareValue(request, "histogram-quantile");
  auto keepFlags = [&](const std::vector<char>& changedEntries) {
    return comparisonsToKeep(observed->analysis.blocks.size(), inputs, changedEntries, s.staleComparisons);
  };
  const std::uint64_t seed = runSeedOf(request);
  const bool partials = partial && !newInputs && sameBins &&
                        std::all_of(outcomes.begin(), outcomes.end(), [](const auto& o) { return o != nullptr; });
  // The first result in between comes after half the interval, so that a long
  // edit shows something soon (and a short one is not slowed by drawing one);
  // then one per interval.
  auto lastPartial = std::chrono::steady_clock::now() - std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                            std::chrono::duration<double>(0.5 * partialSeconds));
  std::size_t partialDone = 0;
  auto emitPartial = [&] {
    std::vector<const pipeline::BlockOutcome*> pointers;
    std::vector<pipeline::BlockPlan> mixed = done;
    for (const auto& o : outcomes) pointers.push_back(o.get());
    std::size_t n = 0;
    std::vector<char> changed(plans.size(), 0);
    for (std::size_t t = 0; t < todo.size(); ++t) {
      if (!ready[t].load(std::memory_order_acquire)) continue;
      pointers[todo[t]] = made[t].get();
      mixed[todo[t]] = plans[todo[t]];
      changed[todo[t]] = 1;
      ++n;
    }
    // Blocks may finish between the tick and this count; once all have, the
    // final result follows and a result in between would only repeat it.
    if (n == partialDone || n == todo.size()) return;
    partialDone = n;
    CompareResult r;
    r.observed = observed;
    r.generated = pipeline::assembleParcels(inputs, mixed, pointers, seed);
    r.blocks = s.current->blocks;
    r.observedLots = s.current->observedLots;
    r.observedSides = s.current->observedSides;
    const std::vector<char> keep = keepFlags(changed);
    detail::compareStage(r, request, &keep);
    partial(std::make_shared<const CompareResult>(std::move(r)), n, todo.size());
  };
  const ProgressFn sub = scaledProgress(progress, reload ? 0.5 : 0.0, 0.95);
  auto keepFinished = [&] {
    for (std::size_t t = 0; t < todo.size(); ++t) {
      if (!made[t]) continue;
      outcomes[todo[t]] = made[t];
      done[todo[t]] = plans[todo[t]];
    }
  };
  try {
    reportProgress(sub, 0.0, "subdividing");
    // A few blocks run without the progress tick, whose polling would only add latency.
    const bool tick = todo.size() > 32;
    parallelFor(
        todo.size(),
        [&](std::size_t t) {
          // The block's last run, whose splits and measurements the new plan may reuse.
          pipeline::BlockReuse reuse;
          reuse.previous = outcomes[todo[t]].get();
          reuse.previousPlan = outcomes[todo[t]] ? &done[todo[t]] : nullptr;
          reuse.record = true;
          reuse.shapesOnly = shapesOnly;
          made[t] = std::make_shared<pipeline::BlockOutcome>(
              pipeline::runBlock(inputs, todo[t], plans[todo[t]], minFrontage, reuse));
          ready[t].store(true, std::memory_order_release);
        },
        tick ? std::function<void(std::size_t)>([&](std::size_t n) {
          reportProgress(sub, static_cast<double>(n) / static_cast<double>(todo.size()), "subdividing");
          if (partials && secondsSince(lastPartial) >= partialSeconds && n < todo.size()) {
            emitPartial();
            lastPartial = std::chrono::steady_clock::now();
          }
        })
             : std::function<void(std::size_t)>());
    // Asked once more at the end: the loop's ticks may all come before its
    // first block is done, or none at all when its blocks finish at once.
    reportProgress(sub, 1.0, "subdividing");
  } catch (const Error& e) {
    if (e.kind() == Error::Kind::Cancelled && !newInputs) {
      keepFinished();
      for (std::size_t t = 0; t < todo.size(); ++t) {
        if (made[t]) s.staleComparisons.insert(inputs.entries[todo[t]].blockId);
      }
      s.outcomesMatchCurrent = false;
      s.outcomes = std::move(outcomes);
      s.plans = std::move(done);
    }
    throw;
  }
  keepFinished();
  // Context an earlier update deferred, of blocks this one did not regenerate.
  std::vector<std::size_t> completed;
  if (!shapesOnly) {
    for (std::size_t k2 = 0; k2 < outcomes.size(); ++k2) {
      if (!outcomes[k2]->contextMeasured) completed.push_back(k2);
    }
    measureDeferred(inputs, outcomes, completed, minFrontage, {}, s.staleComparisons);
  }

  // The result: every block's parcels, measured; per-block comparisons kept
  // where neither side changed.
  CompareResult r;
  r.observed = observed;
  std::vector<const pipeline::BlockOutcome*> pointers;
  for (const auto& o : outcomes) pointers.push_back(o.get());
  r.generated = pipeline::assembleParcels(inputs, plans, pointers, seed);
  r.generated.clampedBounds = clamped;
  const double generateSeconds = secondsSince(generateStart);

  const auto compareStart = std::chrono::steady_clock::now();
  std::vector<char> keep;
  if (!reload && s.current) r.observedSides = s.current->observedSides;  // the same observed parcels and blocks
  if (!reload && sameBins) {
    std::vector<char> changed(plans.size(), 0);
    for (std::size_t t : todo) changed[t] = 1;
    for (std::size_t t : completed) changed[t] = 1;
    keep = keepFlags(changed);
    r.blocks = s.current->blocks;
    r.observedLots = s.current->observedLots;
  }
  detail::compareStage(r, request, keep.empty() ? nullptr : &keep);
  r.seconds = {{"read", readSeconds},
               {"blocks", blockSeconds},
               {"generate", generateSeconds},
               {"metrics", secondsSince(compareStart)}};

  // Commit. The replaced outcomes and result are freed in the background:
  // freeing every block's parcels and splits took longer than comparing them
  // (12-19 ms on cambridge_ma), on the path to the caller.
  releaseInBackground(
      std::make_shared<const std::vector<std::shared_ptr<pipeline::BlockOutcome>>>(std::move(s.outcomes)));
  releaseInBackground(std::move(s.current));
  if (newInputs) s.inputs = std::move(fresh);
  s.observed = observed;
  s.plans = std::move(done);
  s.outcomes = std::move(outcomes);
  s.request = request;
  s.current = std::make_shared<const CompareResult>(std::move(r));
  s.staleComparisons.clear();
  s.outcomesMatchCurrent = true;
  reportProgress(progress, 1.0, "done");

  u.result = s.current;
  u.reloaded = reload;
  u.blocksRegenerated = todo.size();
  u.blocksTotal = plans.size();
  u.seconds = secondsSince(started);
  return u;
}

CompareSession::Update CompareSession::completeContext(const ProgressFn& progress) {
  const auto started = std::chrono::steady_clock::now();
  State& s = *state_;
  Update u;
  u.result = s.current;
  u.blocksTotal = s.outcomes.size();
  if (!s.current || s.current->generated.contextPending.empty() || !s.outcomesMatchCurrent) return u;
  const std::vector<std::size_t> todo = s.current->generated.contextPending;
  const double minFrontage = compareValue(s.request, "min-frontage");
  measureDeferred(s.inputs, s.outcomes, todo, minFrontage, progress, s.staleComparisons);

  CompareResult r;
  r.observed = s.observed;
  std::vector<const pipeline::BlockOutcome*> pointers;
  for (const auto& o : s.outcomes) pointers.push_back(o.get());
  r.generated = pipeline::assembleParcels(s.inputs, s.plans, pointers, runSeedOf(s.request));
  r.generated.clampedBounds = s.current->generated.clampedBounds;
  r.observedSides = s.current->observedSides;
  r.observedLots = s.current->observedLots;
  r.blocks = s.current->blocks;
  const std::vector<char> keep =
      comparisonsToKeep(s.observed->analysis.blocks.size(), s.inputs, {}, s.staleComparisons);
  detail::compareStage(r, s.request, &keep);
  r.seconds = s.current->seconds;
  for (auto& [stage, seconds] : r.seconds) {
    if (stage == "metrics") seconds += secondsSince(started);
  }

  releaseInBackground(std::move(s.current));
  s.current = std::make_shared<const CompareResult>(std::move(r));
  s.staleComparisons.clear();
  u.result = s.current;
  u.blocksRegenerated = 0;
  u.seconds = secondsSince(started);
  return u;
}

CompareRequest withAbsolutePaths(CompareRequest request) {
  request.input.path = std::filesystem::absolute(request.input.path).lexically_normal().string();
  if (request.streets) {
    request.streets->path = std::filesystem::absolute(request.streets->path).lexically_normal().string();
  }
  return request;
}

Json streetOptionsJson(const io::StreetReadOptions& st) {
  Json classWidths = Json::object();
  for (const auto& [value, width] : st.classWidths) classWidths.set(value, width);
  return Json::object()
      .set("path", st.path)
      .set("layer", st.layer)
      .set("where", st.where)
      .set("width_field", st.widthField)
      .set("class_field", st.classField)
      .set("class_widths", classWidths)
      .set("name_field", st.nameField)
      .set("no_node_where", st.noNodeWhere);
}

Json sessionJson(const CompareRequest& request) {
  Json parameters = Json::object();
  for (const auto& name : request.explicitParameters) {
    const auto it = request.parameters.find(name);
    if (it != request.parameters.end()) parameters.set(name, it->second);
  }
  Json overrides = Json::array();
  auto add = [&](Json block, const BlockOverride& o) {
    Json values = Json::object();
    for (const auto& [name, v] : o.parameters) values.set(name, v);
    overrides.push(block.set("style", o.style).set("parameters", values));
  };
  for (const auto& [key, o] : request.overrides) add(Json::object().set("block_key", keyText(key)), o);
  for (const auto& [id, o] : request.overridesById) add(Json::object().set("block_id", id), o);
  Json session = Json::object()
                     .set("parcelscope_session", 2)
                     .set("input", Json::object()
                                       .set("path", request.input.path)
                                       .set("layer", request.input.layer)
                                       .set("where", request.input.where)
                                       .set("crs", request.input.crsOverride)
                                       .set("key_field", request.input.keyField));
  if (const auto& st = request.streets) session.set("streets", streetOptionsJson(*st));
  return session.set("style", request.style)
      .set("metric", request.metric)
      .set("parameters", parameters)
      .set("overrides", overrides);
}

CompareRequest readSession(const std::string& path) {
  Json root = io::readJson(path);
  if (!root.find("parcelscope_session")) {
    if (const Json* inner = root.find("session")) {  // a compare run.json
      Json session = *inner;
      root = std::move(session);
    }
  }
  auto bad = [&](const std::string& what) { return inputError(path + ": session " + what); };
  if (!root.isObject() || !root.find("parcelscope_session")) {
    throw bad("file expected (no parcelscope_session member)");
  }
  // Versions 1 and 2 are read; a later one may mean what this version cannot.
  if (const Json* v = root.find("parcelscope_session"); !v->isNumber() || !(v->number() == 1 || v->number() == 2)) {
    throw bad("version " + v->dump(0) + (v->isNumber() ? "" : " (a number is expected)") +
              " is not one this version reads (1 or 2): write it again with this version of ParcelScope");
  }
  auto text = [&](const Json& object, const char* key, const std::string& where) -> std::string {
    const Json* v = object.find(key);
    if (!v || v->isNull()) return "";
    if (!v->isString()) throw bad("member " + where + key + " is not a string");
    return v->string();
  };
  CompareRequest request;
  const Json* input = root.find("input");
  if (!input || !input->isObject()) throw bad("has no input object");
  request.input.path = text(*input, "path", "input.");
  if (request.input.path.empty()) throw bad("member input.path is missing");
  const std::filesystem::path given(request.input.path);
  if (given.is_relative()) {
    request.input.path = (std::filesystem::path(path).parent_path() / given).lexically_normal().string();
  }
  request.input.layer = text(*input, "layer", "input.");
  request.input.where = text(*input, "where", "input.");
  request.input.crsOverride = text(*input, "crs", "input.");
  request.input.keyField = text(*input, "key_field", "input.");
  if (const Json* st = root.find("streets"); st && !st->isNull()) {
    if (!st->isObject()) throw bad("member streets is not an object");
    io::StreetReadOptions o;
    o.path = text(*st, "path", "streets.");
    if (o.path.empty()) throw bad("member streets.path is missing");
    if (std::filesystem::path(o.path).is_relative()) {
      o.path = (std::filesystem::path(path).parent_path() / o.path).lexically_normal().string();
    }
    o.layer = text(*st, "layer", "streets.");
    o.where = text(*st, "where", "streets.");
    o.widthField = text(*st, "width_field", "streets.");
    o.classField = text(*st, "class_field", "streets.");
    o.nameField = text(*st, "name_field", "streets.");
    o.noNodeWhere = text(*st, "no_node_where", "streets.");
    if (const Json* widths = st->find("class_widths"); widths && !widths->isNull()) {
      if (!widths->isObject()) throw bad("member streets.class_widths is not an object");
      for (const auto& [value, width] : widths->members()) {
        if (!width.isNumber() || !(width.number() >= 0) || width.number() > io::kMaxStreetWidth) {
          throw bad("member streets.class_widths." + value + " is not a width of 0 to " +
                    std::to_string(static_cast<int>(io::kMaxStreetWidth)) + " m");
        }
        o.classWidths[value] = width.number();
      }
    }
    request.streets = std::move(o);
  }
  // Styles and bounds are checked here, naming the file and the member, not
  // later as if given on the command line.
  auto checkStyleName = [&](const std::string& style, const std::string& member, bool all) {
    if (style.empty() || (all && style == "all")) return;
    try {
      generation::style(style);
    } catch (const Error& e) {
      throw bad("member " + member + ": " + e.what());
    }
  };
  auto checkBounds = [&](const ParameterValues& values, const std::string& member) {
    for (const auto& [low, high] : {std::pair{"a-min", "a-max"}, std::pair{"w-min", "w-max"}}) {
      const auto l = values.find(low), h = values.find(high);
      if (l != values.end() && h != values.end() && l->second > h->second) {
        throw bad("member " + member + ": " + low + " is above " + high);
      }
    }
  };
  if (const std::string style = text(root, "style", ""); !style.empty()) {
    checkStyleName(style, "style", true);
    request.style = style;
  }
  if (const std::string metric = text(root, "metric", ""); !metric.empty()) {
    try {
      analysis::parcelQuantity(metric);
    } catch (const Error& e) {
      throw bad("member metric: " + std::string(e.what()));
    }
    request.metric = metric;
  }

  std::vector<ParameterDescription> descriptions = compareParameters();
  for (const auto& d : pipeline::streetParameters()) descriptions.push_back(d);
  request.parameters = defaultValues(descriptions);
  auto readValues = [&](const Json& object, const std::string& where, ParameterValues& into,
                        std::set<std::string>* names) {
    for (const auto& [name, v] : object.members()) {
      if (!v.isNumber()) throw bad("member " + where + name + " is not a number");
      const auto d = std::find_if(descriptions.begin(), descriptions.end(),
                                  [&](const ParameterDescription& x) { return x.name == name; });
      if (d == descriptions.end()) throw bad("member " + where + name + " is not a parameter of compare");
      try {
        checkValue(*d, v.number());  // said here, naming the file, not later as if given on the command line
      } catch (const Error& e) {
        throw bad("member " + where + name + ": " + e.what());
      }
      into[name] = v.number();
      if (names) names->insert(name);
    }
  };
  if (const Json* p = root.find("parameters")) {
    if (!p->isObject()) throw bad("member parameters is not an object");
    readValues(*p, "parameters.", request.parameters, &request.explicitParameters);
    checkBounds(request.parameters, "parameters");
  }
  if (const Json* o = root.find("overrides")) {
    if (!o->isArray()) throw bad("member overrides is not an array");
    std::size_t index = 0;
    for (const Json& item : o->elements()) {
      const std::string where = "overrides[" + std::to_string(index++) + "].";
      if (!item.isObject()) throw bad("member " + where.substr(0, where.size() - 1) + " is not an object");
      const Json* id = item.find("block_id");
      const Json* key = item.find("block_key");
      std::optional<Key> parsedKey;
      if (key) {
        if (key->isString()) parsedKey = parseKey(key->string());
        if (!parsedKey) throw bad("member " + where + "block_key is not 16 hexadecimal digits");
      } else if (!id || !id->isNumber()) {
        throw bad("member " + where + "block_key (or block_id) is missing or not a number");
      }
      pipeline::BlockOverride override;
      override.style = text(item, "style", where);
      checkStyleName(override.style, where + "style", false);
      if (const Json* p = item.find("parameters")) {
        if (!p->isObject()) throw bad("member " + where + "parameters is not an object");
        readValues(*p, where + "parameters.", override.parameters, nullptr);
        checkBounds(override.parameters, where + "parameters");
      }
      // A block named twice: which entry holds is not for the reader to guess.
      const bool fresh = parsedKey
                             ? request.overrides.emplace(*parsedKey, override).second
                             : request.overridesById.emplace(static_cast<std::int64_t>(id->number()), override).second;
      if (!fresh) {
        throw bad("member " + where +
                  (parsedKey ? "block_key " + keyText(*parsedKey)
                             : "block_id " + std::to_string(static_cast<std::int64_t>(id->number()))) +
                  ": an earlier override names the same block");
      }
    }
  }
  request.readFrom = {path};  // --out must not replace the session file
  return request;
}

}  // namespace parcelscope::pipeline
