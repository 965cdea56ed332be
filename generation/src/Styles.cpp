#include "parcelscope/generation/Styles.h"

#include <cmath>

#include "PostProcess.h"
#include "parcelscope/analysis/ObservedAnalysis.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::generation {

const std::vector<const Style*>& styles() {
  // The registry: one line per style.
  static const std::vector<const Style*> all = {&obbStyle(),    &skeletonStyle(), &offsetStyle(), &parishStyle(),
                                                &sextonStyle(), &templateStyle(), &autoStyle()};
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

Subdivision subdivideBlock(const Polygon& block, const std::string& name, const ParameterValues& values,
                           std::uint64_t seed, const StreetWidths& streetWidths) {
  const Style& s = style(name);
  if (&s.resolve({std::nan("")}) != &s) throw usageError("style " + name + " chooses per block; name a concrete one");
  return s.subdivide({block, values, seed, streetWidths});
}

namespace {

// auto: per block, skeleton where at least 90 % of its observed parcels have
// street access (the paper's first variety: every parcel on a street, rears
// abutting), obb otherwise; blocks without observed parcels use skeleton.
class AutoStyle : public Style {
public:
  std::string name() const override { return "auto"; }
  std::string description() const override {
    return "per block: skeleton where >= 90 % of observed parcels have street access, else obb";
  }
  const std::vector<ParameterDescription>& parameters() const override {
    static const std::vector<ParameterDescription> p = [] {
      std::vector<ParameterDescription> all = obbStyle().parameters();
      appendParameters(all, skeletonStyle().parameters());
      return all;
    }();
    return p;
  }
  bool usesStreetWidths() const override { return true; }
  const Style& resolve(const BlockFacts& facts) const override {
    return std::isfinite(facts.accessShare) && facts.accessShare < kAutoSkeletonAccessShare ? obbStyle()
                                                                                            : skeletonStyle();
  }
  Subdivision run(const StyleRun&) const override {
    throw usageError("style auto chooses a style per block; it does not subdivide by itself");
  }
};

}  // namespace

const Style& autoStyle() {
  static const AutoStyle s;
  return s;
}

}  // namespace parcelscope::generation
