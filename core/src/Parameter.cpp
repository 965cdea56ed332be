#include "parcelscope/core/Parameter.h"

#include <cmath>
#include <sstream>

#include "parcelscope/core/Error.h"

namespace parcelscope {

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
    m << "--" << d.name << " " << value << " is outside [" << d.minimum << ", " << d.maximum << "]"
      << (d.unit.empty() ? "" : " " + d.unit);
    throw usageError(m.str());
  }
  if (d.integer && std::floor(value) != value) {
    m << "--" << d.name << " " << value << " must be an integer";
    throw usageError(m.str());
  }
}

}  // namespace parcelscope
