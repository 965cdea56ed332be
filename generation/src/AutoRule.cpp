#include "parcelscope/generation/AutoRule.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "AutoRuleTable.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/generation/Styles.h"

namespace parcelscope::generation {

const std::array<const char*, kAutoFeatures>& autoFeatureNames() {
  static const std::array<const char*, kAutoFeatures> names = {
      "f_log_area", "f_box_ratio", "f_convexity", "f_access", "f_log_mean_area", "f_log_parcels", "f_log_aspect"};
  return names;
}

AutoFeatures autoFeatures(const Polygon& shape, const ObservedSample& observed, double accessShare,
                          double observedShare) {
  const double a = area(shape);
  const OrientedBox box = minimumAreaBox(shape.outer);
  const double hull = std::fabs(signedArea(convexHull(shape.outer)));
  double mean = 0;
  for (double x : observed.areas) mean += x / static_cast<double>(std::max<std::size_t>(1, observed.areas.size()));
  std::vector<double> ratios = observed.aspectRatios;
  double median = 1;
  if (!ratios.empty()) {
    std::nth_element(ratios.begin(), ratios.begin() + static_cast<long>(ratios.size() / 2), ratios.end());
    median = ratios[ratios.size() / 2];
  }
  const double parcels = static_cast<double>(observed.areas.size()) * std::clamp(observedShare, 0.0, 1.0);
  return {std::log10(std::max(a, 1.0)),
          box.length > 0 ? box.width / box.length : 1.0,
          hull > 0 ? std::min(1.0, a / hull) : 1.0,
          std::isfinite(accessShare) ? accessShare : 1.0,
          std::log10(std::max(mean, 1.0)),
          std::log10(std::max(parcels, 1.0)),
          std::log10(std::max(median, 1.0))};
}

AutoRule::AutoRule(std::vector<Row> rows, std::size_t neighbours, const AutoFeatures& weights)
    : rows_(std::move(rows)), neighbours_(neighbours) {
  if (rows_.empty()) throw usageError("the auto rule needs at least one training block");
  if (neighbours_ == 0) throw usageError("the auto rule needs at least one neighbour");
  const double n = static_cast<double>(rows_.size());
  for (const Row& r : rows_) {
    for (std::size_t f = 0; f < kAutoFeatures; ++f) mean_[f] += r.features[f] / n;
  }
  for (const Row& r : rows_) {
    for (std::size_t f = 0; f < kAutoFeatures; ++f) scale_[f] += std::pow(r.features[f] - mean_[f], 2) / n;
  }
  for (std::size_t f = 0; f < kAutoFeatures; ++f) {
    // A left-out feature: an infinite scale, so that it adds nothing to a distance.
    scale_[f] = weights[f] <= 0 ? HUGE_VAL : (scale_[f] > 0 ? std::sqrt(scale_[f]) : 1.0) / weights[f];
  }
}

namespace {

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) {
    if (!field.empty() && field.back() == '\r') field.pop_back();
    fields.push_back(field);
  }
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

}  // namespace

AutoRule AutoRule::fromCsv(const std::string& text, const std::string& source, const std::vector<std::string>& leaveOut,
                           std::size_t neighbours, const AutoFeatures& weights) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line)) throw inputError(source + ": empty auto rule table");
  const std::vector<std::string> header = splitCsvLine(line);
  std::map<std::string, std::size_t> column;
  for (std::size_t i = 0; i < header.size(); ++i) column.emplace(header[i], i);
  auto need = [&](const std::string& name) {
    const auto it = column.find(name);
    if (it == column.end()) throw inputError(source + ": the auto rule table has no column '" + name + "'");
    return it->second;
  };
  std::array<std::size_t, kAutoFeatures> featureColumn{};
  for (std::size_t f = 0; f < kAutoFeatures; ++f) featureColumn[f] = need(autoFeatureNames()[f]);
  const std::size_t styleColumn = need("style");
  const auto cityIt = column.find("city");
  std::vector<Row> rows;
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> fields = splitCsvLine(line);
    const std::string where = source + ":" + std::to_string(number) + ": ";
    if (fields.size() != header.size()) {
      throw inputError(where + std::to_string(fields.size()) + " fields, the header has " +
                       std::to_string(header.size()));
    }
    if (cityIt != column.end() &&
        std::find(leaveOut.begin(), leaveOut.end(), fields[cityIt->second]) != leaveOut.end()) {
      continue;
    }
    Row r;
    for (std::size_t f = 0; f < kAutoFeatures; ++f) {
      const std::string& v = fields[featureColumn[f]];
      std::size_t used = 0;
      try {
        r.features[f] = std::stod(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != v.size() || v.empty() || !std::isfinite(r.features[f])) {
        throw inputError(where + autoFeatureNames()[f] + " is '" + v + "', not a number");
      }
    }
    r.style = fields[styleColumn];
    const Style* s = nullptr;
    try {
      s = &style(r.style);
    } catch (const Error& e) {
      throw inputError(where + e.what());
    }
    if (choosesPerBlock(*s)) throw inputError(where + "style " + r.style + " chooses per block; name a concrete one");
    rows.push_back(std::move(r));
  }
  if (rows.empty()) throw inputError(source + ": the auto rule table has no training blocks");
  return AutoRule(std::move(rows), neighbours, weights);
}

const std::string& AutoRule::bundledTable() {
  static const std::string text(kBundledAutoRuleTable);
  return text;
}

const AutoRule& AutoRule::bundled() {
  static const AutoRule rule = fromCsv(bundledTable(), "datasets/auto_rule.csv");
  return rule;
}

std::vector<std::pair<double, std::size_t>> AutoRule::nearest(const AutoFeatures& x, std::size_t k) const {
  std::vector<std::pair<double, std::size_t>> near;
  near.reserve(rows_.size());
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    double d = 0;
    for (std::size_t f = 0; f < kAutoFeatures; ++f) d += std::pow((x[f] - rows_[i].features[f]) / scale_[f], 2);
    near.emplace_back(d, i);
  }
  k = std::min(k, near.size());
  std::partial_sort(near.begin(), near.begin() + static_cast<long>(k), near.end());
  near.resize(k);
  return near;
}

const std::string& AutoRule::predict(const AutoFeatures& x) const {
  const auto near = nearest(x, neighbours_);
  static const std::string far = kFarStyle;
  if (!near.empty() && near.front().first > kFar * kFar) return far;
  // Each neighbour votes with 1 / its distance: a block at a training row's
  // features takes that row's style (its calibration), others lean to the
  // nearer rows. kVoteFloor keeps a zero distance finite.
  std::map<std::string, double> votes;
  for (const auto& [d, i] : near) votes[rows_[i].style] += 1.0 / (std::sqrt(d) + kVoteFloor);
  // Nearest first, so that a tie goes to the nearer style.
  const std::string* best = nullptr;
  double most = 0;
  for (const auto& [d, i] : near) {
    const std::string& s = rows_[i].style;
    if (votes[s] > most) {
      best = &s;
      most = votes[s];
    }
  }
  return *best;
}

}  // namespace parcelscope::generation
