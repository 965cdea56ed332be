#pragma once
// A small column-typed table: what analysis produces and io/ writes as CSV or
// as the attribute part of a vector layer.
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace parcelscope {

using Value = std::variant<std::int64_t, double, std::string>;

struct Column {
  enum class Type { Integer, Real, String };
  std::string name;
  Type type;
  std::string unit;  ///< "m", "m2", "deg" or "" (documentation only)
};

struct Table {
  std::vector<Column> columns;
  std::vector<std::vector<Value>> rows;  ///< each row has one value per column

  /// Index of the column named `name`; throws std::out_of_range if absent.
  std::size_t column(const std::string& name) const;
};

}  // namespace parcelscope
