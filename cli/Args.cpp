#include "Args.h"

#include <cctype>
#include <cstdlib>
#include <set>
#include <sstream>

#include "parcelscope/core/Error.h"

namespace parcelscope::cli {

// Whether strtod would read all of `text` as a number that is not written in
// decimal: hexadecimal ("0x2", "0x1p3"), "inf", "infinity" or "nan". Leading
// blanks, which strtod skips, are allowed as before.
bool readsAsNonDecimalNumber(const std::string& text) {
  char* end = nullptr;
  std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') return false;  // not a number at all: parseValue says so
  std::size_t i = 0;
  while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
  std::size_t digits = 0;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++digits;
  if (i < text.size() && text[i] == '.') {
    ++i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++digits;
  }
  if (digits == 0) return true;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    std::size_t exponent = 0;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++exponent;
    if (exponent == 0) return true;
  }
  return i != text.size();
}

Args::Args(const std::vector<std::string>& args, const std::vector<FlagSpec>& flags,
           const std::vector<ParameterDescription>& parameters)
    : parameters_(defaultValues(parameters)) {
  std::set<std::string> seen;  // flag names given so far
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() < 3 || a.compare(0, 2, "--") != 0) {
      positional_.push_back(a);
      continue;
    }
    std::string name = a.substr(2), val;
    bool hasInline = false;
    if (auto eq = name.find('='); eq != std::string::npos) {
      val = name.substr(eq + 1);
      name = name.substr(0, eq);
      hasInline = true;
    }
    const ParameterDescription* param = nullptr;
    for (const auto& p : parameters) {
      if (p.name == name) param = &p;
    }
    const FlagSpec* flag = nullptr;
    for (const auto& f : flags) {
      if (f.name == name) flag = &f;
    }
    if (!param && !flag) throw usageError("unknown option --" + name);
    if (!seen.insert(name).second) throw usageError("--" + name + " is given more than once; give it once");
    const bool takesValue = param || flag->takesValue;
    if (takesValue && !hasInline) {
      if (i + 1 >= args.size()) throw usageError("--" + name + " needs a value");
      val = args[++i];
    }
    if (param) {
      if (readsAsNonDecimalNumber(val)) {
        throw usageError("--" + name + " " + val + " is not a decimal number (e.g. 2, -0.5, 1e3)");
      }
      parameters_[name] = parseValue(*param, val);
      given_.insert(name);
    } else {
      values_[name] = val;
    }
  }
}

std::optional<std::string> Args::value(const std::string& flag) const {
  auto it = values_.find(flag);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

namespace {

// After the flag: "X  [0, 50] m, default 1", "N  [2, 500], default 30",
// "LABEL  0 street-width, 1 street-length; default street-width",
// "yes|no  (or 1|0, true|false), default yes".
std::string valueSummary(const ParameterDescription& p) {
  std::ostringstream s;
  s.precision(12);
  switch (p.kind) {
    case ParameterKind::Enum:
      s << "LABEL ";
      for (std::size_t i = 0; i < p.labels.size(); ++i) {
        s << (i ? ", " : " ") << p.minimum + static_cast<double>(i) << " " << p.labels[i];
      }
      s << ";";
      break;
    case ParameterKind::Boolean:
      s << "yes|no  (or 1|0, true|false),";
      break;
    case ParameterKind::Integer:
    case ParameterKind::Real:
      s << (p.integer() ? "N" : "X") << "  [" << p.minimum << ", " << p.maximum << "]"
        << (p.unit.empty() ? "" : " " + p.unit) << ",";
      break;
  }
  s << " default " << formatValue(p, p.defaultValue);
  return s.str();
}

}  // namespace

std::string usageText(const std::string& synopsis, const std::vector<FlagSpec>& flags,
                      const std::vector<ParameterDescription>& parameters) {
  std::ostringstream s;
  s << "usage: " << synopsis << "\n\noptions:\n";
  for (const auto& f : flags) {
    s << "  --" << f.name << (f.takesValue ? " VALUE" : "") << "\n      " << f.help << "\n";
  }
  if (!parameters.empty()) s << "\nparameters:\n";
  for (const auto& [group, members] : groupParameters(parameters)) {
    s << "  " << group << "\n";
    for (const auto& p : members) {
      s << "    --" << p.name << " " << valueSummary(p) << "\n        " << p.help << "\n";
    }
  }
  return s.str();
}

}  // namespace parcelscope::cli
