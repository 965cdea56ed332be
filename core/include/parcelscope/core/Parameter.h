#pragma once
// One description per algorithm parameter. The same description feeds the
// command-line flags (`--name value`), the GUI sliders and the run record, so
// the three cannot drift apart.
#include <map>
#include <string>
#include <vector>

namespace parcelscope {

struct ParameterDescription {
  std::string name;     ///< flag and JSON key, e.g. "block-tolerance"
  std::string help;     ///< one sentence
  std::string unit;     ///< "m", "m2", "" for dimensionless
  double minimum;       ///< inclusive
  double maximum;       ///< inclusive
  double defaultValue;
  bool integer = false;
};

/// Values by parameter name; filled from defaults, then overridden by the user.
using ParameterValues = std::map<std::string, double>;

/// Defaults of every description in `descriptions`.
ParameterValues defaultValues(const std::vector<ParameterDescription>& descriptions);

/// Appends to `to` the descriptions of `more` whose name `to` does not hold yet,
/// so that a parameter shared by two algorithms (e.g. min-frontage) is listed once.
void appendParameters(std::vector<ParameterDescription>& to, const std::vector<ParameterDescription>& more);

/// Throws Error(Usage) naming the parameter when `value` is outside its range or
/// not an integer where one is required.
void checkValue(const ParameterDescription& description, double value);

}  // namespace parcelscope
