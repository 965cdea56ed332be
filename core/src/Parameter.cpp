#include "parcelscope/core/Parameter.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "parcelscope/core/Error.h"

namespace parcelscope {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string number(double v) {
  std::ostringstream s;
  s.precision(12);
  s << v;
  return s.str();
}

// `v` as a user typed it, for messages: an integer in full (4294967295, not
// 4.29497e+09), any other value in the fewest digits that read back as `v`.
std::string exactNumber(double v) {
  char buffer[64];
  if (std::isfinite(v) && std::floor(v) == v && std::fabs(v) < 1e21) {
    std::snprintf(buffer, sizeof buffer, "%.0f", v);
    return buffer;
  }
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
    if (!std::isfinite(v) || std::strtod(buffer, nullptr) == v) break;
  }
  return buffer;
}

// "0 street-width, 1 street-length"
std::string labelList(const ParameterDescription& d) {
  std::string out;
  for (std::size_t i = 0; i < d.labels.size(); ++i) {
    out += (i ? ", " : "") + number(d.minimum + static_cast<double>(i)) + " " + d.labels[i];
  }
  return out;
}

}  // namespace

bool operator==(const ParameterDescription& a, const ParameterDescription& b) {
  return a.name == b.name && a.help == b.help && a.unit == b.unit && a.minimum == b.minimum && a.maximum == b.maximum &&
         a.defaultValue == b.defaultValue && a.kind == b.kind && a.group == b.group && a.labels == b.labels &&
         a.outputOnly == b.outputOnly;
}

ParameterDescription realParameter(std::string name, std::string help, std::string unit, double minimum, double maximum,
                                   double defaultValue, std::string group) {
  ParameterDescription d;
  d.name = std::move(name);
  d.help = std::move(help);
  d.unit = std::move(unit);
  d.minimum = minimum;
  d.maximum = maximum;
  d.defaultValue = defaultValue;
  d.group = std::move(group);
  return d;
}

ParameterDescription integerParameter(std::string name, std::string help, std::string unit, double minimum,
                                      double maximum, double defaultValue, std::string group) {
  ParameterDescription d = realParameter(std::move(name), std::move(help), std::move(unit), minimum, maximum,
                                         defaultValue, std::move(group));
  d.kind = ParameterKind::Integer;
  return d;
}

ParameterDescription enumParameter(std::string name, std::string help, std::vector<std::string> labels,
                                   const std::string& defaultLabel, std::string group) {
  const auto at = std::find(labels.begin(), labels.end(), defaultLabel);
  if (at == labels.end()) throw std::logic_error("parameter " + name + ": default " + defaultLabel + " is no label");
  ParameterDescription d =
      realParameter(std::move(name), std::move(help), "", 0, static_cast<double>(labels.size()) - 1,
                    static_cast<double>(at - labels.begin()), std::move(group));
  d.kind = ParameterKind::Enum;
  d.labels = std::move(labels);
  return d;
}

ParameterDescription booleanParameter(std::string name, std::string help, bool defaultValue, std::string group) {
  ParameterDescription d =
      realParameter(std::move(name), std::move(help), "", 0, 1, defaultValue ? 1 : 0, std::move(group));
  d.kind = ParameterKind::Boolean;
  return d;
}

ParameterDescription outputOnly(ParameterDescription description) {
  description.outputOnly = true;
  return description;
}

ParameterValues defaultValues(const std::vector<ParameterDescription>& descriptions) {
  ParameterValues values;
  for (const auto& d : descriptions) values[d.name] = d.defaultValue;
  return values;
}

void appendParameters(std::vector<ParameterDescription>& to, const std::vector<ParameterDescription>& more) {
  for (const auto& d : more) {
    bool seen = false;
    for (const auto& t : to) seen = seen || t.name == d.name;
    if (!seen) to.push_back(d);
  }
}

void checkValue(const ParameterDescription& d, double value) {
  std::ostringstream m;
  if (!std::isfinite(value) || value < d.minimum || value > d.maximum) {
    m << "--" << d.name << " " << exactNumber(value) << " is outside [" << exactNumber(d.minimum) << ", "
      << exactNumber(d.maximum) << "]" << (d.unit.empty() ? "" : " " + d.unit);
    if (d.kind == ParameterKind::Enum) m << " (" << labelList(d) << ")";
    throw usageError(m.str());
  }
  if (d.integer() && std::floor(value) != value) {
    m << "--" << d.name << " " << exactNumber(value) << " must be an integer";
    throw usageError(m.str());
  }
}

double parseValue(const ParameterDescription& d, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (!text.empty() && *end == '\0') {
    checkValue(d, v);
    return v;
  }
  if (d.kind == ParameterKind::Enum) {
    for (std::size_t i = 0; i < d.labels.size(); ++i) {
      if (d.labels[i] == text) return d.minimum + static_cast<double>(i);
    }
    std::string labels;
    for (const auto& l : d.labels) labels += (labels.empty() ? "" : ", ") + l;
    throw usageError("--" + d.name + " " + text + " is not one of " + labels + " (or " + labelList(d) + ")");
  }
  if (d.kind == ParameterKind::Boolean) {
    const std::string t = lower(text);
    if (t == "true" || t == "yes") return 1;
    if (t == "false" || t == "no") return 0;
    throw usageError("--" + d.name + " " + text + " is not one of 0, 1, true, false, yes, no");
  }
  throw usageError("--" + d.name + " " + text + " is not a number");
}

std::string formatValue(const ParameterDescription& d, double value) {
  if (d.kind == ParameterKind::Boolean && (value == 0 || value == 1)) return value != 0 ? "yes" : "no";
  if (d.kind == ParameterKind::Enum) {
    const double i = value - d.minimum;
    if (i >= 0 && i < static_cast<double>(d.labels.size()) && std::floor(i) == i) {
      return d.labels[static_cast<std::size_t>(i)];
    }
  }
  return number(value);
}

std::vector<std::pair<std::string, std::vector<ParameterDescription>>> groupParameters(
    const std::vector<ParameterDescription>& descriptions) {
  std::vector<std::pair<std::string, std::vector<ParameterDescription>>> groups;
  for (const auto& d : descriptions) {
    auto g = std::find_if(groups.begin(), groups.end(), [&](const auto& x) { return x.first == d.group; });
    if (g == groups.end()) g = groups.insert(groups.end(), {d.group, {}});
    g->second.push_back(d);
  }
  return groups;
}

}  // namespace parcelscope
