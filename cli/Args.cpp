#include "Args.h"

#include <cstdlib>
#include <sstream>

#include "parcelscope/core/Error.h"

namespace parcelscope::cli {

Args::Args(const std::vector<std::string>& args, const std::vector<FlagSpec>& flags,
           const std::vector<ParameterDescription>& parameters)
    : parameters_(defaultValues(parameters)) {
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
    const bool takesValue = param || flag->takesValue;
    if (takesValue && !hasInline) {
      if (i + 1 >= args.size()) throw usageError("--" + name + " needs a value");
      val = args[++i];
    }
    if (param) {
      char* end = nullptr;
      const double v = std::strtod(val.c_str(), &end);
      if (val.empty() || *end != '\0') throw usageError("--" + name + " " + val + " is not a number");
      checkValue(*param, v);
      parameters_[name] = v;
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

std::string usageText(const std::string& synopsis, const std::vector<FlagSpec>& flags,
                      const std::vector<ParameterDescription>& parameters) {
  std::ostringstream s;
  s.precision(12);
  s << "usage: " << synopsis << "\n\noptions:\n";
  for (const auto& f : flags) {
    s << "  --" << f.name << (f.takesValue ? " VALUE" : "") << "\n      " << f.help << "\n";
  }
  if (!parameters.empty()) s << "\nparameters:\n";
  for (const auto& p : parameters) {
    s << "  --" << p.name << " " << (p.integer ? "N" : "X") << "  [" << p.minimum << ", " << p.maximum
      << "]" << (p.unit.empty() ? "" : " " + p.unit) << ", default " << p.defaultValue << "\n      "
      << p.help << "\n";
  }
  return s.str();
}

}  // namespace parcelscope::cli
