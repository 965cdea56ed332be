#pragma once
// The one error hierarchy of ParcelScope. Libraries throw these; the command line
// maps them to exit codes (Usage -> 2, everything else -> 1) and the GUI shows
// their message. Messages are one line and name the operation, the input and,
// where there is one, the feature.
#include <stdexcept>
#include <string>

namespace parcelscope {

class Error : public std::runtime_error {
public:
  enum class Kind {
    Input,     ///< bad or unreadable input data (file, format, CRS, feature)
    Geometry,  ///< a geometric precondition does not hold
    IO,        ///< writing or renaming an output failed
    Usage,     ///< a command-line argument or parameter value is wrong
    Cancelled  ///< a progress callback asked to stop
  };
  Error(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const noexcept { return kind_; }

private:
  Kind kind_;
};

inline Error inputError(const std::string& m) { return Error(Error::Kind::Input, m); }
inline Error geometryError(const std::string& m) { return Error(Error::Kind::Geometry, m); }
inline Error ioError(const std::string& m) { return Error(Error::Kind::IO, m); }
inline Error usageError(const std::string& m) { return Error(Error::Kind::Usage, m); }

}  // namespace parcelscope
