#pragma once
// Minimal ordered JSON value for run records (run.json) and session files. Keys
// keep their insertion order so that records are easy to read and to diff.
// Parsing lives in io (io::readJson, through GDAL's JSON parser).
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace parcelscope {

class Json {
public:
  Json() : value_(nullptr) {}
  Json(std::nullptr_t) : value_(nullptr) {}
  Json(bool b) : value_(b) {}
  Json(int i) : value_(static_cast<std::int64_t>(i)) {}
  Json(long i) : value_(static_cast<std::int64_t>(i)) {}
  Json(long long i) : value_(static_cast<std::int64_t>(i)) {}
  Json(unsigned long i) : value_(static_cast<std::int64_t>(i)) {}
  Json(unsigned long long i) : value_(static_cast<std::int64_t>(i)) {}
  Json(double d) : value_(d) {}
  Json(const char* s) : value_(std::string(s)) {}
  Json(std::string s) : value_(std::move(s)) {}

  static Json object();
  static Json array();

  /// Sets `key` on an object (replacing an existing key) and returns *this.
  Json& set(const std::string& key, Json value);
  /// Appends to an array and returns *this.
  Json& push(Json value);

  std::string dump(int indent = 2) const;

  bool isNull() const;
  bool isNumber() const;  ///< integer or real
  bool isString() const;
  bool isObject() const;
  bool isArray() const;
  /// The value of `key` in an object; nullptr when absent or not an object.
  const Json* find(const std::string& key) const;
  /// The number (integer or real); throws std::logic_error on another type.
  double number() const;
  /// The string; throws std::logic_error on another type.
  const std::string& string() const;
  /// The boolean; throws std::logic_error on another type.
  bool boolean() const;
  /// An object's members in order (empty for a non-object).
  std::vector<std::pair<std::string, Json>> members() const;
  /// An array's elements (empty for a non-array).
  std::vector<Json> elements() const;

private:
  using Object = std::vector<std::pair<std::string, Json>>;
  using Array = std::vector<Json>;
  std::variant<std::nullptr_t, bool, std::int64_t, double, std::string, std::shared_ptr<Object>, std::shared_ptr<Array>>
      value_;
  void write(std::string& out, int indent, int depth) const;
};

}  // namespace parcelscope
