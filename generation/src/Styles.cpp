#include "parcelscope/generation/Styles.h"

#include <algorithm>
#include <cmath>

#include "PostProcess.h"
#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/generation/AutoRule.h"

namespace parcelscope::generation {

const std::vector<const Style*>& styles() {
  // The registry: one line per style.
  static const std::vector<const Style*> all = {&obbStyle(),    &skeletonStyle(), &offsetStyle(), &parishStyle(),
                                                &sextonStyle(), &templateStyle(), &accessStyle(), &autoStyle()};
  return all;
}

const Style& style(const std::string& name) {
  std::string names;
  for (const Style* s : styles()) {
    if (s->name() == name) return *s;
    names += (names.empty() ? "" : ", ") + s->name();
  }
  throw usageError("no subdivision style '" + name + "' (styles: " + names + ")");
}

const std::vector<std::pair<std::string, std::string>>& generationStyles() {
  static const std::vector<std::pair<std::string, std::string>> list = [] {
    std::vector<std::pair<std::string, std::string>> out;
    for (const Style* s : styles()) out.emplace_back(s->name(), s->description());
    return out;
  }();
  return list;
}

std::vector<ParameterDescription> generationParameterDescriptions() {
  std::vector<ParameterDescription> params;
  for (const Style* s : styles()) appendParameters(params, s->parameters());
  appendParameters(params, analysis::analysisParameters());
  return params;
}

ParameterValues styleValues(const Style& s, const ParameterValues& values) {
  ParameterValues out;
  for (const ParameterDescription& d : s.parameters()) {
    const auto it = values.find(d.name);
    out[d.name] = it == values.end() ? d.defaultValue : it->second;
  }
  return out;
}

Subdivision Style::subdivide(const StyleRun& r) const {
  Subdivision out = run(r);
  const ObbParameters bounds = obbParametersFrom(r.values);
  if (detail::mergeSlivers(r.block, out, bounds.minFrontage) > 0 && name() != obbStyle().name()) {
    out = detail::fallBackToObb(r.block, bounds, r.seed, "a sliver parcel no neighbour could take");
    detail::mergeSlivers(r.block, out, bounds.minFrontage);
  }
  return out;
}

bool choosesPerBlock(const Style& s) { return &s.resolve({}) != &s; }

Subdivision subdivideBlock(const Polygon& block, const std::string& name, const ParameterValues& values,
                           std::uint64_t seed, const StreetWidths& streetWidths) {
  const Style& s = style(name);
  if (choosesPerBlock(s)) throw usageError("style " + name + " chooses per block; name a concrete one");
  return s.subdivide({block, values, seed, streetWidths});
}

namespace {

// A style that picks a concrete style per block and reads every parameter of
// the styles it may pick.
class ChoosingStyle : public Style {
public:
  explicit ChoosingStyle(std::vector<const Style*> choices) : choices_(std::move(choices)) {
    for (const Style* s : choices_) appendParameters(parameters_, s->parameters());
  }
  const std::vector<ParameterDescription>& parameters() const override { return parameters_; }
  bool usesStreetWidths() const override {
    return std::any_of(choices_.begin(), choices_.end(), [](const Style* s) { return s->usesStreetWidths(); });
  }
  Subdivision run(const StyleRun&) const override {
    throw usageError("style " + name() + " chooses a style per block; it does not subdivide by itself");
  }

private:
  std::vector<const Style*> choices_;
  std::vector<ParameterDescription> parameters_;
};

// access: Vanegas et al.'s rule. Per block, skeleton where at least 90 % of
// its observed parcels have street access (the paper's first variety: every
// parcel on a street, rears abutting), obb otherwise; blocks without observed
// parcels use skeleton.
class AccessStyle : public ChoosingStyle {
public:
  AccessStyle() : ChoosingStyle({&obbStyle(), &skeletonStyle()}) {}
  std::string name() const override { return "access"; }
  std::string description() const override {
    return "per block: skeleton where >= 90 % of observed parcels have street access, else obb (the paper's rule)";
  }
  const Style& resolve(const BlockFacts& facts) const override {
    return std::isfinite(facts.accessShare) && facts.accessShare < kAccessSkeletonShare ? obbStyle() : skeletonStyle();
  }
  // The paper slices each street evenly (4.2, step 4).
  void pinValues(ParameterValues& values) const override {
    if (values.count("slice-widths")) values["slice-widths"] = 0;
  }
};

// auto: the style the calibrated blocks most like this one got
// (AutoRule::bundled(), docs/algorithms/auto.md); without observed parcels,
// the paper's rule.
class AutoStyle : public ChoosingStyle {
public:
  AutoStyle()
      : ChoosingStyle(
            {&obbStyle(), &skeletonStyle(), &offsetStyle(), &parishStyle(), &sextonStyle(), &templateStyle()}) {}
  std::string name() const override { return "auto"; }
  std::string description() const override {
    return "per block: the style of the most similar calibrated blocks of the shared datasets (3 nearest, each "
           "voting by closeness, in block and observed parcel features)";
  }
  const Style& resolve(const BlockFacts& facts) const override {
    if (!facts.shape || !facts.observed || facts.observed->areas.empty()) return accessStyle().resolve(facts);
    return style(AutoRule::bundled().predict(
        autoFeatures(*facts.shape, *facts.observed, facts.accessShare, facts.observedShare)));
  }
};

}  // namespace

const Style& accessStyle() {
  static const AccessStyle s;
  return s;
}

const Style& autoStyle() {
  static const AutoStyle s;
  return s;
}

}  // namespace parcelscope::generation
