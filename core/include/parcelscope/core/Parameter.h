#pragma once
// One description per algorithm parameter, bound in one statement (name, help,
// unit, range, default, group and, for an enum, the label of each value). The
// same description feeds the command-line flags (`--name value`) and their
// --help, the GUI controls and the run record, so they cannot drift apart.
// A parameter two algorithms share (min-frontage) is described once, by a
// function the lists of both return a copy of.
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace parcelscope {

/// What values a parameter takes. Every kind travels as a double (the values,
/// the run record and session files hold numbers).
enum class ParameterKind {
  Real,     ///< any number in [minimum, maximum]
  Integer,  ///< a whole number in [minimum, maximum] (seed, bins, figure sizes)
  Enum,     ///< a whole number in [minimum, maximum], value v named labels[v - minimum]
  Boolean,  ///< 0 (no) or 1 (yes)
};

struct ParameterDescription {
  std::string name;    ///< flag and JSON key, e.g. "block-tolerance"
  std::string help;    ///< one sentence
  std::string unit;    ///< "m", "m2", "" for dimensionless
  double minimum = 0;  ///< inclusive
  double maximum = 0;  ///< inclusive
  double defaultValue = 0;
  ParameterKind kind = ParameterKind::Real;
  /// Heading the parameter is listed under in --help and the GUI ("Blocks",
  /// "Bounds", "Subdivision", "Skeleton", "Comparison", "Figures", "Output").
  std::string group;
  /// Enum only: the name of each value from minimum to maximum, e.g. corner-rule's
  /// {"street-width", "street-length"}; the command line takes them for the numbers.
  std::vector<std::string> labels;
  /// Only changes which files a run writes and how (figures, their size, the
  /// layers' index); nothing a run computes depends on it. The GUI, which
  /// computes and shows, and writes only on export, leaves these out.
  bool outputOnly = false;

  /// Whether only whole numbers are valid (integer, enum and boolean kinds).
  bool integer() const { return kind != ParameterKind::Real; }
};

bool operator==(const ParameterDescription& a, const ParameterDescription& b);
inline bool operator!=(const ParameterDescription& a, const ParameterDescription& b) { return !(a == b); }

/// A real parameter in [minimum, maximum] (`unit`: "m", "m2", "deg", "" ...).
ParameterDescription realParameter(std::string name, std::string help, std::string unit, double minimum, double maximum,
                                   double defaultValue, std::string group);
/// A whole-number parameter in [minimum, maximum].
ParameterDescription integerParameter(std::string name, std::string help, std::string unit, double minimum,
                                      double maximum, double defaultValue, std::string group);
/// An enum whose values 0 .. labels.size() - 1 are named by `labels`; the default is a label.
/// Throws std::logic_error when `defaultLabel` is not one of them.
ParameterDescription enumParameter(std::string name, std::string help, std::vector<std::string> labels,
                                   const std::string& defaultLabel, std::string group);
/// A yes/no parameter: 1 (yes, true) or 0 (no, false).
ParameterDescription booleanParameter(std::string name, std::string help, bool defaultValue, std::string group);
/// `description` marked outputOnly (a setting of the written files only).
ParameterDescription outputOnly(ParameterDescription description);

/// Values by parameter name; filled from defaults, then overridden by the user.
using ParameterValues = std::map<std::string, double>;

/// Sets `target` to the value named `name` in `values`, converted to its
/// type, when there is one; returns whether there was.
template <typename T>
bool readValue(const ParameterValues& values, const std::string& name, T& target) {
  const auto it = values.find(name);
  if (it == values.end()) return false;
  target = static_cast<T>(it->second);
  return true;
}

/// Defaults of every description in `descriptions`.
ParameterValues defaultValues(const std::vector<ParameterDescription>& descriptions);

/// Appends to `to` the descriptions of `more` whose name `to` does not hold yet,
/// so that a parameter shared by two algorithms (e.g. min-frontage) is listed once.
void appendParameters(std::vector<ParameterDescription>& to, const std::vector<ParameterDescription>& more);

/// Throws Error(Usage) naming the parameter when `value` is outside its range or
/// not an integer where one is required.
void checkValue(const ParameterDescription& description, double value);

/// The value `text` gives parameter `description`: a number for every kind,
/// also a label for an enum ("street-length") and true/false/yes/no for a
/// boolean. Throws Error(Usage) naming the parameter when `text` is none of
/// those or the value is not valid (checkValue).
double parseValue(const ParameterDescription& description, const std::string& text);

/// How `value` is shown to a user: the label of an enum's value, yes/no for a
/// boolean, the number otherwise (12 significant digits).
std::string formatValue(const ParameterDescription& description, double value);

/// The groups of `descriptions` in the order they first appear, each with its
/// descriptions in list order (for --help and the GUI).
std::vector<std::pair<std::string, std::vector<ParameterDescription>>> groupParameters(
    const std::vector<ParameterDescription>& descriptions);

}  // namespace parcelscope
