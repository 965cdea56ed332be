#pragma once
// A small column-typed table: what analysis produces and io/ writes as CSV or
// as the attribute part of a vector layer.
#include <cstdint>
#include <functional>
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

/// A table whose rows are made when they are read, so that a large table
/// (hundreds of thousands of parcels) is written without being held whole.
struct RowSource {
  std::vector<Column> columns;
  std::size_t rows = 0;
  /// Row `i`'s values (one per column) into `out`, which comes empty; may be
  /// called from several threads at once, rows in any order.
  std::function<void(std::size_t i, std::vector<Value>& out)> row;

  /// Every row, held.
  Table table() const;
  /// The rows of `table`, which must outlive the source.
  static RowSource of(const Table& table);
  /// This source with one more column, whose value in a row is `value` of
  /// the row's index and its other values.
  RowSource with(Column column, std::function<Value(std::size_t, const std::vector<Value>&)> value) const;
};

}  // namespace parcelscope
