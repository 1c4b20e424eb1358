// Reading of TOML sections for the config parsers (config/ only): number
// ranges, the config text quoted as written, and a per-table reader that
// reports each problem as "file:line: key = value: rule" and every key nobody
// asked for as unknown. Shared by plant_config.cc and modbus_config.cc.
#pragma once

#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/diagnostic.h"

namespace pvtwin::config_detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Shortest text that reads back as x.
inline std::string FormatNumber(double x) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, result.ptr);
}

// The allowed values of a number: an interval whose ends are open or closed;
// an infinite end means no bound on that side.
struct Interval {
  double lo = -kInf;
  bool lo_closed = true;
  double hi = kInf;
  bool hi_closed = true;

  bool Contains(double x) const {
    if (!std::isfinite(x)) return false;
    const bool above_lo = lo_closed ? x >= lo : x > lo;
    const bool below_hi = hi_closed ? x <= hi : x < hi;
    return above_lo && below_hi;
  }

  std::string Rule() const {
    if (std::isinf(hi)) return (lo_closed ? "must be >= " : "must be > ") + FormatNumber(lo);
    return std::string("must be within ") + (lo_closed ? "[" : "(") + FormatNumber(lo) + ", " +
           FormatNumber(hi) + (hi_closed ? "]" : ")");
  }
};

constexpr Interval Closed(double lo, double hi) { return {lo, true, hi, true}; }
constexpr Interval HalfOpen(double lo, double hi) { return {lo, true, hi, false}; }
constexpr Interval LeftOpen(double lo, double hi) { return {lo, false, hi, true}; }
constexpr Interval Above(double lo) { return {lo, false, kInf, true}; }
constexpr Interval AtLeast(double lo) { return {lo, true, kInf, true}; }

// The config text split into lines, to quote values as they were written.
class SourceText {
 public:
  explicit SourceText(std::string_view text) {
    std::size_t start = 0;
    while (start <= text.size()) {
      std::size_t end = text.find('\n', start);
      if (end == std::string_view::npos) end = text.size();
      std::string_view line = text.substr(start, end - start);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      lines_.push_back(line);
      start = end + 1;
    }
  }

  // The node's text as written when it sits on one line; empty otherwise.
  std::string Quote(const toml::source_region& region) const {
    if (region.begin.line == 0 || region.begin.line != region.end.line ||
        region.begin.line > lines_.size()) {
      return "";
    }
    const std::string_view line = lines_[region.begin.line - 1];
    const std::size_t begin = ByteOffset(line, region.begin.column);
    const std::size_t end = ByteOffset(line, region.end.column);
    if (begin >= end) return "";
    return std::string(line.substr(begin, end - begin));
  }

 private:
  // toml++ counts columns in code points, from 1.
  static std::size_t ByteOffset(std::string_view line, std::size_t column) {
    std::size_t offset = 0;
    for (std::size_t cp = 1; cp < column && offset < line.size(); ++cp) {
      ++offset;
      while (offset < line.size() && (static_cast<unsigned char>(line[offset]) & 0xC0) == 0x80) {
        ++offset;
      }
    }
    return offset;
  }

  std::vector<std::string_view> lines_;
};

// Reads the keys of one table, records which were seen, and reports each
// problem as a Diagnostic at the line of the offending value.
class SectionReader {
 public:
  SectionReader(const toml::table& table, const SourceText& source, const std::string& file,
                Diagnostics* errors)
      : table_(table), source_(source), file_(file), errors_(errors) {}

  // Reads a number (TOML integer or float) into *out. Returns true if a valid
  // value was stored; a missing optional key leaves *out untouched.
  bool Number(std::string_view key, bool required, const Interval& range, double* out) {
    const toml::node* node = Find(key, required);
    if (node == nullptr) return false;
    double value = 0.0;
    if (const auto* i = node->as_integer()) {
      value = static_cast<double>(i->get());
    } else if (const auto* f = node->as_floating_point()) {
      value = f->get();
    } else {
      Report(key, *node, "expected a number");
      return false;
    }
    if (!std::isfinite(value)) {
      Report(key, *node, "must be a finite number");
      return false;
    }
    if (!range.Contains(value)) {
      Report(key, *node, range.Rule());
      return false;
    }
    *out = value;
    return true;
  }

  // Reads a TOML integer into *out (floats are rejected).
  bool Integer(std::string_view key, bool required, const Interval& range, int* out) {
    const toml::node* node = Find(key, required);
    if (node == nullptr) return false;
    const auto* i = node->as_integer();
    if (i == nullptr) {
      Report(key, *node, "expected an integer");
      return false;
    }
    const std::int64_t value = i->get();
    if (!range.Contains(static_cast<double>(value))) {
      Report(key, *node, range.Rule());
      return false;
    }
    if (value > std::numeric_limits<int>::max() || value < std::numeric_limits<int>::min()) {
      Report(key, *node, "too large");
      return false;
    }
    *out = static_cast<int>(value);
    return true;
  }

  // Reads a TOML boolean (true/false) into *out.
  bool Boolean(std::string_view key, bool required, bool* out) {
    const toml::node* node = Find(key, required);
    if (node == nullptr) return false;
    const auto* b = node->as_boolean();
    if (b == nullptr) {
      Report(key, *node, "expected true or false");
      return false;
    }
    *out = b->get();
    return true;
  }

  // Reads a non-empty string into *out.
  bool String(std::string_view key, bool required, std::string* out,
              std::string_view type_rule = "expected a string") {
    const toml::node* node = Find(key, required);
    if (node == nullptr) return false;
    const auto* s = node->as_string();
    if (s == nullptr) {
      Report(key, *node, type_rule);
      return false;
    }
    if (s->get().empty()) {
      Report(key, *node, "must not be empty");
      return false;
    }
    *out = s->get();
    return true;
  }

  // Reports a value that was read but breaks a rule only its caller knows.
  void Reject(std::string_view key, std::string_view rule) {
    if (const toml::node* node = table_.get(key)) Report(key, *node, rule);
  }

  // As Reject, with the value left out of the message (a secret).
  void RejectHidden(std::string_view key, std::string_view rule) {
    if (const toml::node* node = table_.get(key)) {
      errors_->push_back({file_, static_cast<int>(node->source().begin.line), std::string(key),
                          "(value not shown)", std::string(rule)});
    }
  }

  // Reads a string that must be one of `choices`; the rule lists them.
  bool Choice(std::string_view key, bool required, const std::vector<std::string_view>& choices,
              std::string* out) {
    std::string rule = "expected one of";
    for (std::size_t i = 0; i < choices.size(); ++i) {
      rule += (i == 0 ? " " : ", ") + std::string(choices[i]);
    }
    std::string value;
    if (!String(key, required, &value, rule)) return false;
    if (std::find(choices.begin(), choices.end(), value) == choices.end()) {
      Reject(key, rule);
      return false;
    }
    *out = value;
    return true;
  }

  // Line of the key's value; of the table itself when the key is absent.
  int Line(std::string_view key) const {
    const toml::node* node = table_.get(key);
    return static_cast<int>((node != nullptr ? node->source() : table_.source()).begin.line);
  }

  // The key's value as written (empty when absent or spanning lines).
  std::string Written(std::string_view key) const {
    const toml::node* node = table_.get(key);
    return node == nullptr || node->is_table() ? "" : source_.Quote(node->source());
  }

  // One "unknown key" error for every key no reader asked for.
  void ReportUnknownKeys() {
    for (const auto& [key, node] : table_) {
      if (std::find(seen_.begin(), seen_.end(), key.str()) == seen_.end()) {
        Report(key.str(), node, "unknown key");
      }
    }
  }

 private:
  const toml::node* Find(std::string_view key, bool required) {
    seen_.emplace_back(key);
    const toml::node* node = table_.get(key);
    if (node == nullptr && required) {
      errors_->push_back({file_, static_cast<int>(table_.source().begin.line), std::string(key), "",
                          "required key missing"});
    }
    return node;
  }

  void Report(std::string_view key, const toml::node& node, std::string_view rule) {
    const std::string value = node.is_table() ? "" : source_.Quote(node.source());
    errors_->push_back({file_, static_cast<int>(node.source().begin.line), std::string(key), value,
                        std::string(rule)});
  }

  const toml::table& table_;
  const SourceText& source_;
  const std::string& file_;
  Diagnostics* errors_;
  std::vector<std::string> seen_;
};

constexpr bool kRequired = true;
constexpr bool kOptional = false;

}  // namespace pvtwin::config_detail

namespace pvtwin {
struct ModbusConfig;
namespace config_detail {

// Reads the `modbus` table ([[modbus.device]] and [[modbus.point]]) into *out
// and validates it as a whole (modbus_config.cc).
void ReadModbusSection(const toml::node& node, const SourceText& source, const std::string& file,
                       ModbusConfig* out, Diagnostics* errors);

}  // namespace config_detail
}  // namespace pvtwin
