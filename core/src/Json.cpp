#include "parcelscope/core/Json.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "parcelscope/core/Table.h"

namespace parcelscope {

std::size_t Table::column(const std::string& name) const {
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i].name == name) return i;
  }
  throw std::out_of_range("no column " + name);
}

Table RowSource::table() const {
  Table t;
  t.columns = columns;
  t.rows.resize(rows);
  for (std::size_t i = 0; i < rows; ++i) row(i, t.rows[i]);
  return t;
}

RowSource RowSource::of(const Table& table) {
  RowSource s;
  s.columns = table.columns;
  s.rows = table.rows.size();
  s.row = [&table](std::size_t i, std::vector<Value>& out) { out = table.rows[i]; };
  return s;
}

RowSource RowSource::with(Column column, std::function<Value(std::size_t, const std::vector<Value>&)> value) const {
  RowSource s = *this;
  s.columns.push_back(std::move(column));
  s.row = [inner = row, value = std::move(value)](std::size_t i, std::vector<Value>& out) {
    inner(i, out);
    out.push_back(value(i, out));
  };
  return s;
}

Json Json::object() {
  Json j;
  j.value_ = std::make_shared<Object>();
  return j;
}

Json Json::array() {
  Json j;
  j.value_ = std::make_shared<Array>();
  return j;
}

Json& Json::set(const std::string& key, Json value) {
  auto* o = std::get_if<std::shared_ptr<Object>>(&value_);
  if (!o) throw std::logic_error("Json::set on a non-object");
  for (auto& kv : **o) {
    if (kv.first == key) {
      kv.second = std::move(value);
      return *this;
    }
  }
  (*o)->emplace_back(key, std::move(value));
  return *this;
}

Json& Json::push(Json value) {
  auto* a = std::get_if<std::shared_ptr<Array>>(&value_);
  if (!a) throw std::logic_error("Json::push on a non-array");
  (*a)->push_back(std::move(value));
  return *this;
}

bool Json::isNull() const { return std::holds_alternative<std::nullptr_t>(value_); }
bool Json::isNumber() const {
  return std::holds_alternative<std::int64_t>(value_) || std::holds_alternative<double>(value_);
}
bool Json::isString() const { return std::holds_alternative<std::string>(value_); }
bool Json::isObject() const { return std::holds_alternative<std::shared_ptr<Object>>(value_); }
bool Json::isArray() const { return std::holds_alternative<std::shared_ptr<Array>>(value_); }

const Json* Json::find(const std::string& key) const {
  const auto* o = std::get_if<std::shared_ptr<Object>>(&value_);
  if (!o) return nullptr;
  for (const auto& kv : **o) {
    if (kv.first == key) return &kv.second;
  }
  return nullptr;
}

double Json::number() const {
  if (const auto* i = std::get_if<std::int64_t>(&value_)) return static_cast<double>(*i);
  if (const auto* d = std::get_if<double>(&value_)) return *d;
  throw std::logic_error("Json::number on a non-number");
}

const std::string& Json::string() const {
  if (const auto* s = std::get_if<std::string>(&value_)) return *s;
  throw std::logic_error("Json::string on a non-string");
}

bool Json::boolean() const {
  if (const auto* b = std::get_if<bool>(&value_)) return *b;
  throw std::logic_error("Json::boolean on a non-boolean");
}

std::vector<std::pair<std::string, Json>> Json::members() const {
  const auto* o = std::get_if<std::shared_ptr<Object>>(&value_);
  return o ? **o : Object{};
}

std::vector<Json> Json::elements() const {
  const auto* a = std::get_if<std::shared_ptr<Array>>(&value_);
  return a ? **a : Array{};
}

namespace {
void escape(std::string& out, const std::string& s) {
  out += '"';
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  out += '"';
}
}  // namespace

void Json::write(std::string& out, int indent, int depth) const {
  const std::string pad = indent > 0 ? "\n" + std::string(static_cast<std::size_t>(indent * (depth + 1)), ' ') : "";
  const std::string end = indent > 0 ? "\n" + std::string(static_cast<std::size_t>(indent * depth), ' ') : "";
  if (std::holds_alternative<std::nullptr_t>(value_)) {
    out += "null";
  } else if (auto* b = std::get_if<bool>(&value_)) {
    out += *b ? "true" : "false";
  } else if (auto* i = std::get_if<std::int64_t>(&value_)) {
    out += std::to_string(*i);
  } else if (auto* d = std::get_if<double>(&value_)) {
    if (!std::isfinite(*d)) {
      out += "null";
    } else {
      // The shortest text that reads back as the same double: coordinates
      // and parameters written here are read back bit for bit.
      char buf[32];
      const auto written = std::to_chars(buf, buf + sizeof buf, *d);
      out.append(buf, written.ptr);
    }
  } else if (auto* s = std::get_if<std::string>(&value_)) {
    escape(out, *s);
  } else if (auto* o = std::get_if<std::shared_ptr<Object>>(&value_)) {
    out += '{';
    bool first = true;
    for (const auto& kv : **o) {
      if (!first) out += ',';
      first = false;
      out += pad;
      escape(out, kv.first);
      out += indent > 0 ? ": " : ":";
      kv.second.write(out, indent, depth + 1);
    }
    if (!(*o)->empty()) out += end;
    out += '}';
  } else if (auto* a = std::get_if<std::shared_ptr<Array>>(&value_)) {
    out += '[';
    bool first = true;
    for (const auto& v : **a) {
      if (!first) out += ',';
      first = false;
      out += pad;
      v.write(out, indent, depth + 1);
    }
    if (!(*a)->empty()) out += end;
    out += ']';
  }
}

std::string Json::dump(int indent) const {
  std::string out;
  write(out, indent, 0);
  return out;
}

}  // namespace parcelscope
