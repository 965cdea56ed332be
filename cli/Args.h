#pragma once
// Command-line parsing shared by the subcommands. Flags of algorithm parameters
// come from their ParameterDescription, so the CLI cannot drift from the GUI.
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "parcelscope/core/Parameter.h"

namespace parcelscope::cli {

struct FlagSpec {
  std::string name;  ///< without the leading "--"
  std::string help;
  bool takesValue = true;
};

class Args {
public:
  /// Parses `args` (after the subcommand). Throws Error(Usage) on an unknown
  /// flag, a flag given more than once, a missing value, a parameter value that
  /// is not valid (parseValue(): decimal numbers for every parameter, an enum's
  /// labels, true/false/yes/no for a boolean; hexadecimal, inf and nan are
  /// refused) or is out of range.
  Args(const std::vector<std::string>& args, const std::vector<FlagSpec>& flags,
       const std::vector<ParameterDescription>& parameters);

  const std::vector<std::string>& positional() const { return positional_; }
  std::optional<std::string> value(const std::string& flag) const;
  bool has(const std::string& flag) const { return values_.count(flag) > 0; }
  /// Defaults overridden by the user's values.
  const ParameterValues& parameters() const { return parameters_; }
  /// Whether the user gave parameter `name` (as opposed to its default).
  bool given(const std::string& name) const { return given_.count(name) > 0; }

private:
  std::vector<std::string> positional_;
  std::map<std::string, std::string> values_;
  ParameterValues parameters_;
  std::set<std::string> given_;
};

/// Help text listing flags, then the parameters by group (ParameterDescription::group,
/// in order of first appearance), each with unit, range, default and help, and an
/// enum's labels with their numbers.
/// Whether strtod would read all of `text` as a number not written in decimal:
/// hexadecimal ("0x2", "0x1p3"), "inf", "infinity" or "nan" (leading blanks allowed).
bool readsAsNonDecimalNumber(const std::string& text);

std::string usageText(const std::string& synopsis, const std::vector<FlagSpec>& flags,
                      const std::vector<ParameterDescription>& parameters);

}  // namespace parcelscope::cli
