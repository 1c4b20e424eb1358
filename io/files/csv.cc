#include "io/files/csv.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <istream>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/common/threads.h"
#include "core/common/units.h"
#include "core/data/physical_limits.h"
#include "core/data/qc.h"
#include "io/platform/time_format.h"

namespace pvtwin {
namespace {

constexpr std::string_view kTimeColumn = "time";
// A measurement time a logger can have written: from 1980-01-01T00:00:00Z
// (before any PVT field was logged, and the zero of a clock that lost its
// battery, 1970, or a relative time like -5 lies below) to
// 2200-01-01T00:00:00Z (the weather import's bound as well).
constexpr std::int64_t kEarliestTimeS = 315532800, kLatestTimeS = 7258118400;
constexpr std::string_view kFlowLitrePerHourColumn = "flow_l_h";
constexpr double kLitrePerHourTimesDensityToKgS = 1.0 / 3.6e6;  // (L/h)·(kg/m³) → kg/s
// Values outside the physical limits named one by one per column; the rest
// are counted.
constexpr std::size_t kNamedOutOfLimits = 3;

std::string FormatNumber(double x) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, result.ptr);
}

inline bool IsBlank(char c) { return c == ' ' || c == '\t'; }

inline std::string_view Trim(std::string_view s) {
  while (!s.empty() && IsBlank(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsBlank(s.back())) s.remove_suffix(1);
  return s;
}

// SplitFields for a line without quotes, with one search (memchr) per field
// and the trim inline; false (*fields untouched) for a line with a quote,
// which the general path reads. A row of the canonical CSV has no quotes: at
// 1 min, 14 days (20 160 rows of 16 fields) took 32.1 M instructions in
// SplitFields before this and 26.3 M with it (callgrind). A loop over the
// characters that stops at commas and quotes took 53.7 M: memchr steps
// over a field's digits many bytes at a time.
bool SplitUnquotedFields(std::string_view line, std::vector<std::string_view>* fields) {
  if (line.find('"') != std::string_view::npos) return false;
  fields->clear();
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    fields->push_back(Trim(line.substr(begin, comma - begin)));  // npos: to the end
    if (comma == std::string_view::npos) return true;
    begin = comma + 1;
  }
}

// Splits a line at its commas. A field may be quoted as RFC 4180 writes it
// ("a,b", with "" for a quote inside); an unescaped quoted field is a view
// into the line, one with "" is unescaped into *storage. Returns false (with
// *why) for a quote that is not closed on the line.
bool SplitFields(std::string_view line, std::vector<std::string_view>* fields,
                 std::deque<std::string>* storage, std::string* why) {
  storage->clear();
  if (SplitUnquotedFields(line, fields)) return true;
  fields->clear();
  std::size_t pos = 0;
  while (true) {
    while (pos < line.size() && IsBlank(line[pos])) ++pos;
    if (pos < line.size() && line[pos] == '"') {
      std::string unescaped;
      std::size_t i = pos + 1;
      bool closed = false;
      for (; i < line.size(); ++i) {
        if (line[i] != '"') {
          unescaped += line[i];
        } else if (i + 1 < line.size() && line[i + 1] == '"') {
          unescaped += '"';
          ++i;
        } else {
          closed = true;
          break;
        }
      }
      if (!closed) {
        *why = "quoted field not closed on this line (fields spanning lines are not supported)";
        return false;
      }
      if (unescaped.size() == i - pos - 1) {
        fields->push_back(line.substr(pos + 1, i - pos - 1));
      } else {
        storage->push_back(std::move(unescaped));
        fields->push_back(storage->back());
      }
      pos = line.find(',', i + 1);
      if (!Trim(line.substr(i + 1,
                            pos == std::string_view::npos ? std::string_view::npos : pos - i - 1))
               .empty()) {
        *why = "text after a closing quote";
        return false;
      }
    } else {
      const std::size_t comma = line.find(',', pos);
      fields->push_back(Trim(line.substr(
          pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos)));
      pos = comma;
    }
    if (pos == std::string_view::npos) return true;
    ++pos;
  }
}

// A hint for a file written with another separator or decimal mark.
std::string SeparatorHint(std::string_view header) {
  if (header.find(';') != std::string_view::npos) {
    return "; the header looks separated by ';': pvtwin reads comma-separated files with '.' as "
           "the decimal mark";
  }
  if (header.find('\t') != std::string_view::npos) {
    return "; the header looks separated by tabs: pvtwin reads comma-separated files";
  }
  return "";
}

// Clinger's fast path for a plain decimal, -?digits[.digits] with at most 15
// digits in all: it is m / 10^k with m < 2^53 and 10^k (k ≤ 15) both exact
// doubles, so one IEEE division gives the correctly rounded value, the one
// from_chars gives. False for anything else (exponents, "nan", a leading
// '+', more digits), which the caller reads with from_chars.
bool ParsePlainDecimal(std::string_view text, double* value) {
  static constexpr double kPow10[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  constexpr int kMaxDigits = 15;
  const bool negative = !text.empty() && text[0] == '-';
  // Longer than the digits, the point and the sign allow: not for this path
  // (full-precision numbers, 17 significant digits, stop here).
  if (text.size() > kMaxDigits + 1 + (negative ? 1 : 0)) return false;
  std::size_t i = negative ? 1 : 0;
  std::uint64_t mantissa = 0;
  int digits = 0;
  int decimals = -1;  // digits after the point; -1: no point yet
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c >= '0' && c <= '9') {
      if (++digits > kMaxDigits) return false;
      mantissa = 10 * mantissa + static_cast<std::uint64_t>(c - '0');
      if (decimals >= 0) ++decimals;
    } else if (c == '.' && decimals < 0) {
      decimals = 0;
    } else {
      return false;
    }
  }
  if (digits == 0) return false;
  const double magnitude = static_cast<double>(mantissa) / kPow10[decimals > 0 ? decimals : 0];
  *value = negative ? -magnitude : magnitude;
  return true;
}

// How a column's cells become a channel's values.
enum class Conversion {
  kNone,
  kLitrePerHourToKgS,  // flow_l_h
  kDegToRad,           // aoi_deg
};

struct Column {
  std::string name;                // as written in the header
  std::optional<Channel> channel;  // nullopt: the time column or an ignored one
  std::optional<AirChannel> air;   // an air channel (rh_pct, p_air_hpa), unchecked
  Conversion conversion = Conversion::kNone;
  PhysicalLimit limit;  // PhysicalLimitOf(*channel, the options' area), when channel is set
};

class CsvParser {
 public:
  CsvParser(const std::string& path, const CsvReadOptions& options)
      : path_(path), options_(options) {}

  // Reads the header row. False when the rows cannot be read (no header, or
  // no canonical CSV header); *header_bytes: the bytes it took, its newline
  // included.
  bool ReadHeaderRow(std::istream& in, std::size_t* header_bytes) {
    std::string line;
    if (!std::getline(in, line)) {
      Error(0, "", "", "empty file: a header row is expected");
      return false;
    }
    *header_bytes = line.size() + 1;
    header_ = line;
    return ReadHeader(HeaderNames(header_));
  }

  // Takes the columns of `other`'s header (read by ReadHeaderRow), without
  // its diagnostics: for a parser of the same file's later rows.
  void TakeHeaderOf(const CsvParser& other) {
    ReadHeader(HeaderNames(other.header_));
    errors_.clear();
    warnings_.clear();
  }

  // Reads the rows after line `line_no` until the end of `in`, or, with a
  // byte limit, the rows that start within the next `limit` bytes. Room for
  // the columns is reserved from `reserve_bytes` (the bytes to read, or
  // more when later rows will be appended; 0: none).
  void ReadRows(std::istream& in, int line_no, std::size_t limit, std::size_t reserve_bytes) {
    std::string line;
    std::size_t consumed = 0;
    while (consumed < limit && errors_.size() < kMaxCsvErrors && std::getline(in, line)) {
      ++line_no;
      consumed += line.size() + 1;
      std::string_view row = line;
      if (row.ends_with('\r')) row.remove_suffix(1);
      if (Trim(row).empty()) continue;
      if (series_.time_s.empty()) ReserveRows(reserve_bytes / (line.size() + 1), reserve_bytes);
      ReadRow(line_no, row);
    }
    if (errors_.size() >= kMaxCsvErrors) {
      Error(line_no, "", "", "too many errors; reading stopped here");
    }
    NoteReadError(in);
    last_line_ = line_no;
  }

  void NoteReadError(const std::istream& in) {
    if (in.bad()) Error(0, "", "", "read error");
  }

  bool HasErrors() const { return !errors_.empty(); }

  // Appends the rows `later` read from the lines after this parser's last,
  // with its diagnostics, as one parser reading all of them would have
  // found them. False (nothing appended) when either found an error or the
  // times do not increase across the seam: a parser reading the whole file
  // then reports what it finds.
  bool Append(CsvParser&& later) {
    if (HasErrors() || later.HasErrors()) return false;
    if (!series_.time_s.empty() && !later.series_.time_s.empty() &&
        later.series_.time_s.front() <= series_.time_s.back()) {
      return false;
    }
    // Values outside the limits: the first few of each column named, in
    // line order, as NoteOutOfLimits names them.
    std::array<std::size_t, kNumChannels> named = out_of_limits_;
    for (Diagnostic& w : later.warnings_) {
      const auto column = std::find_if(columns_.begin(), columns_.end(),
                                       [&](const Column& c) { return c.name == w.field; });
      if (column == columns_.end() || !column->channel) continue;
      if (named[static_cast<std::size_t>(*column->channel)]++ >= kNamedOutOfLimits) continue;
      if (w.line > 0) w.line += last_line_;
      warnings_.push_back(std::move(w));
    }
    for (std::size_t c = 0; c < kNumChannels; ++c) out_of_limits_[c] += later.out_of_limits_[c];
    const auto append = [](auto* to, const auto& from) {
      to->insert(to->end(), from.begin(), from.end());
    };
    append(&series_.time_s, later.series_.time_s);
    for (const Column& column : columns_) {
      if (column.channel) append(&series_[*column.channel], later.series_[*column.channel]);
      if (column.air) append(&series_[*column.air], later.series_[*column.air]);
    }
    last_line_ += later.last_line_;
    return true;
  }

  // The series and the diagnostics: true (and *out written) without errors.
  bool Finish(Series* out, Diagnostics* errors, Diagnostics* warnings) {
    SummariseOutOfLimits();
    if (warnings != nullptr) warnings->insert(warnings->end(), warnings_.begin(), warnings_.end());
    if (!errors_.empty()) {
      errors->insert(errors->end(), errors_.begin(), errors_.end());
      return false;
    }
    series_.step_s = MedianStep(series_.time_s);
    const QcCorrections corrected = ApplyPaperCorrections(&series_);
    if (warnings != nullptr) {
      if (corrected.irradiance_zeroed > 0) {
        warnings->push_back({path_, 0, "", "",
                             std::to_string(corrected.irradiance_zeroed) +
                                 " irradiance values above 5000 W/m² set to 0 (paper Table 2)"});
      }
      if (corrected.flow_zeroed > 0) {
        warnings->push_back({path_, 0, "", "",
                             std::to_string(corrected.flow_zeroed) +
                                 " small negative flow values set to 0 (paper Table 1)"});
      }
    }
    *out = std::move(series_);
    return true;
  }

  // The bytes from the read position to the end, 0 when the stream cannot
  // tell (a pipe).
  static std::size_t BytesLeft(std::istream& in) {
    const std::istream::pos_type here = in.tellg();
    if (here == std::istream::pos_type(-1) || !in.seekg(0, std::ios::end)) {
      in.clear();
      return 0;
    }
    const std::istream::pos_type end = in.tellg();
    in.seekg(here);
    return end > here ? static_cast<std::size_t>(end - here) : 0;
  }

 private:
  // The header row without a UTF-8 byte order mark and a CR at its end.
  static std::string_view HeaderNames(std::string_view header) {
    if (header.starts_with("\xEF\xBB\xBF")) header.remove_prefix(3);
    if (header.ends_with('\r')) header.remove_suffix(1);
    return header;
  }

  // Room for about `rows` rows (from the first row's length) and a quarter
  // more, so that the columns of a large file are not copied as they grow.
  // Room only reserved, never written, costs no memory; and no more rows
  // than `bytes_left` can hold (a comma or a newline per cell).
  void ReserveRows(std::size_t rows, std::size_t bytes_left) {
    rows = std::min(rows + rows / 4 + 16, bytes_left / std::max<std::size_t>(columns_.size(), 1));
    series_.time_s.reserve(rows);
    for (const Column& column : columns_) {
      if (column.channel) series_[*column.channel].reserve(rows);
      if (column.air) series_[*column.air].reserve(rows);
    }
  }

  void Error(int line, std::string_view field, std::string_view value, std::string rule) {
    errors_.push_back({path_, line, std::string(field), std::string(value), std::move(rule)});
  }

  // False when the rows cannot be read at all (the header is no canonical
  // CSV header); other problems are errors and the rows are still checked.
  bool ReadHeader(std::string_view header) {
    std::vector<std::string_view> names;
    std::string why;
    if (!SplitFields(header, &names, &unescaped_, &why)) {
      Error(1, "", "", "header: " + why);
      return false;
    }
    if (names.size() == 1 && !SeparatorHint(header).empty()) {
      Error(1, "", "", "the header has a single column" + SeparatorHint(header));
      return false;
    }
    std::array<std::string_view, kNumChannels> seen_as{};  // header name that gave a channel
    for (std::size_t i = 0; i < names.size(); ++i) {
      Column column;
      column.name = std::string(names[i]);
      const std::string_view name = names[i];
      if (name == kTimeColumn) {
        if (time_index_) {
          Error(1, name, "", "duplicate column");
        } else {
          time_index_ = i;
        }
        columns_.push_back(std::move(column));
        continue;
      }
      std::optional<Channel> channel = ChannelFromName(name);
      if (name == kFlowLitrePerHourColumn) {
        channel = Channel::kMdotKgS;
        column.conversion = Conversion::kLitrePerHourToKgS;
      } else if (channel == Channel::kAoiRad) {
        column.conversion = Conversion::kDegToRad;
      }
      if (!channel && AirChannelFromName(name)) {
        column.air = AirChannelFromName(name);
        const bool seen = std::any_of(columns_.begin(), columns_.end(),
                                      [&](const Column& c) { return c.air == column.air; });
        if (seen) Error(1, name, "", "duplicate column");
        column.limit = {-std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity()};
      } else if (!channel) {
        warnings_.push_back({path_, 1,
                             name.empty() ? "column " + std::to_string(i + 1) : std::string(name),
                             "", "unknown column ignored"});
      } else {
        std::string_view& first = seen_as[static_cast<std::size_t>(*channel)];
        if (first.empty()) {
          first = name;
          column.channel = channel;
          column.limit = PhysicalLimitOf(*channel, options_.area_m2);
        } else if (first == name) {
          Error(1, name, "", "duplicate column");
        } else {
          Error(1, name, "",
                "duplicate column (" + std::string(first) + " gives the same channel)");
        }
      }
      columns_.push_back(std::move(column));
    }

    const auto has = [&](Channel c) { return !seen_as[static_cast<std::size_t>(c)].empty(); };
    const auto missing = [&](std::string_view name, const char* alternative) {
      Error(1, name, "", std::string("required column missing") + alternative);
    };
    if (!time_index_) missing(kTimeColumn, "");
    if (!has(Channel::kQThW) && !options_.weather_only) {
      if (!has(Channel::kTInC)) missing("t_in_c", " (or give q_th_w)");
      if (!has(Channel::kTOutC)) missing("t_out_c", " (or give q_th_w)");
    }
    if (!has(Channel::kMdotKgS) && !options_.weather_only)
      missing("flow_kg_s", " (or give flow_l_h)");
    if (!has(Channel::kGPoaWM2)) {
      const bool ghi = has(Channel::kGhiWM2);
      const bool dhi = has(Channel::kDhiWM2);
      if (!ghi && !dhi) {
        missing("g_poa_w_m2", " (or give ghi_w_m2 and dhi_w_m2)");
      } else if (!ghi) {
        missing("ghi_w_m2", " (dhi_w_m2 needs it when g_poa_w_m2 is absent)");
      } else if (!dhi) {
        missing("dhi_w_m2", " (ghi_w_m2 needs it when g_poa_w_m2 is absent)");
      }
    }
    if (!has(Channel::kTAmbC)) missing("t_amb_c", "");
    if (!has(Channel::kPElW) && !options_.weather_only) missing("p_el_w", "");

    for (const Column& column : columns_) {
      if (column.channel) series_[*column.channel].clear();
      if (column.air) series_[*column.air].clear();
    }
    return true;
  }

  void ReadRow(int line_no, std::string_view row) {
    std::string why;
    if (!SplitFields(row, &fields_, &unescaped_, &why)) {
      Error(line_no, "", "", why);
      return;
    }
    if (fields_.size() != columns_.size()) {
      const bool decimal_comma = fields_.size() > columns_.size() &&
                                 row.find(';') == std::string_view::npos &&
                                 row.find('.') == std::string_view::npos;
      Error(line_no, "", "",
            "expected " + std::to_string(columns_.size()) + " fields, found " +
                std::to_string(fields_.size()) +
                (decimal_comma ? " (decimal commas? pvtwin reads '.' as the decimal mark)" : ""));
      return;
    }
    if (time_index_) {
      const std::string_view cell = fields_[*time_index_];
      std::int64_t time_s = 0;
      std::string rule;
      const std::int64_t after_s =
          series_.time_s.empty() ? std::numeric_limits<std::int64_t>::min() : series_.time_s.back();
      if (!ParseTimeIn(cell, options_.naive_time_zone, after_s, &time_s, &rule)) {
        Error(line_no, kTimeColumn, cell, rule);
        return;
      }
      if (time_s < kEarliestTimeS || time_s > kLatestTimeS) {
        Error(line_no, kTimeColumn, cell,
              "not a plausible measurement time: must be within 1980-01-01T00:00:00Z .. "
              "2200-01-01T00:00:00Z");
        return;
      }
      if (!series_.time_s.empty() && time_s <= series_.time_s.back()) {
        Error(line_no, kTimeColumn, cell,
              "must be later than the time of the row before (line " +
                  std::to_string(previous_line_) + ")");
        return;
      }
      series_.time_s.push_back(time_s);
      previous_line_ = line_no;
    }
    for (std::size_t i = 0; i < columns_.size(); ++i) {
      const Column& column = columns_[i];
      if (column.channel) series_[*column.channel].push_back(ReadCell(line_no, column, fields_[i]));
      if (column.air) series_[*column.air].push_back(ReadCell(line_no, column, fields_[i]));
    }
  }

  // One value in its channel's unit; NaN if missing or malformed.
  double ReadCell(int line_no, const Column& column, std::string_view cell) {
    const double kMissing = std::nan("");
    if (cell.empty()) return kMissing;
    // from_chars takes no leading '+'; accept one, but not "+-1".
    std::string_view number = cell;
    if (number.starts_with('+') && !number.starts_with("+-")) number.remove_prefix(1);
    double value = 0.0;
    if (!ParsePlainDecimal(number, &value)) {
      const char* const number_end = number.data() + number.size();
      const auto [end, ec] = std::from_chars(number.data(), number_end, value);
      if (ec != std::errc() || end != number_end) {
        Error(line_no, column.name, cell, "expected a number");
        return kMissing;
      }
    }
    if (std::isnan(value)) return kMissing;
    if (std::isinf(value)) {
      Error(line_no, column.name, cell, "expected a finite number");
      return kMissing;
    }
    switch (column.conversion) {
      case Conversion::kNone:
        break;
      case Conversion::kLitrePerHourToKgS:
        value *= options_.fluid_density_kg_m3 * kLitrePerHourTimesDensityToKgS;
        break;
      case Conversion::kDegToRad:
        value = DegToRad(value);
        break;
    }
    if (column.channel == Channel::kValid && value != 0.0 && value != 1.0) {
      Error(line_no, column.name, cell, "must be 0 or 1");
      return kMissing;
    }
    if (column.channel == Channel::kMdotKgS && value < -kNegativeFlowToleranceKgS) {
      std::string limit = "-" + FormatNumber(kNegativeFlowToleranceKgS) + " kg/s";
      if (column.conversion == Conversion::kLitrePerHourToKgS) {
        char litre_per_hour[32];
        std::snprintf(litre_per_hour, sizeof litre_per_hour, "%.3g",
                      kNegativeFlowToleranceKgS / options_.fluid_density_kg_m3 /
                          kLitrePerHourTimesDensityToKgS);
        limit = "-" + std::string(litre_per_hour) + " L/h (" + limit + ")";
      }
      Error(line_no, column.name, cell,
            "must not be below " + limit +
                "; only small negative readings of a stopped pump are set to 0");
      return kMissing;
    }
    // A channel's cell passes the edge rule of every reader (the paper's
    // night glitch included); an air column's, its own limits.
    const bool passes = column.channel ? PassesEdge(*column.channel, value, options_.area_m2)
                                       : column.limit.Contains(value);
    if (!passes) {
      NoteOutOfLimits(line_no, column, cell);
      return kMissing;
    }
    return value;
  }

  // Values outside the physical limits become missing: the first few are
  // named one by one, the rest of the column is counted.
  void NoteOutOfLimits(int line_no, const Column& column, std::string_view cell) {
    const auto c = static_cast<std::size_t>(*column.channel);
    if (out_of_limits_[c]++ < kNamedOutOfLimits) {
      warnings_.push_back({path_, line_no, column.name, std::string(cell),
                           "outside the physical limits " +
                               DescribeCsvLimit(*column.channel, options_.area_m2) +
                               ": read as missing"});
    }
  }

  void SummariseOutOfLimits() {
    for (const Column& column : columns_) {
      if (!column.channel) continue;
      const std::size_t n = out_of_limits_[static_cast<std::size_t>(*column.channel)];
      if (n <= kNamedOutOfLimits) continue;
      warnings_.push_back({path_, 0, column.name, "",
                           std::to_string(n - kNamedOutOfLimits) + " more values outside " +
                               DescribeCsvLimit(*column.channel, options_.area_m2) +
                               " read as missing (" + std::to_string(n) + " in all)"});
    }
  }

  static double MedianStep(const std::vector<std::int64_t>& time_s) {
    if (time_s.size() < 2) return 0.0;
    std::vector<std::int64_t> steps(time_s.size() - 1);
    for (std::size_t i = 0; i + 1 < time_s.size(); ++i) steps[i] = time_s[i + 1] - time_s[i];
    const auto middle = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
    std::nth_element(steps.begin(), middle, steps.end());
    return static_cast<double>(*middle);
  }

  const std::string& path_;
  const CsvReadOptions& options_;
  std::vector<Column> columns_;
  std::optional<std::size_t> time_index_;
  std::vector<std::string_view> fields_;  // the current row, split
  std::deque<std::string> unescaped_;     // its quoted fields that held ""
  std::array<std::size_t, kNumChannels> out_of_limits_{};
  int previous_line_ = 0;  // line of the last row read
  int last_line_ = 0;      // line of the last line read, blank or not
  std::string header_;     // the header row as read
  Series series_;
  Diagnostics errors_;
  Diagnostics warnings_;
};

}  // namespace

bool ParseCanonicalCsv(std::istream& in, const std::string& path_for_messages,
                       const CsvReadOptions& options, Series* out, Diagnostics* errors,
                       Diagnostics* warnings) {
  assert(out != nullptr && errors != nullptr);
  CsvParser parser(path_for_messages, options);
  std::size_t header_bytes = 0;
  if (parser.ReadHeaderRow(in, &header_bytes)) {
    parser.ReadRows(in, 1, std::numeric_limits<std::size_t>::max(), CsvParser::BytesLeft(in));
  } else {
    parser.NoteReadError(in);
  }
  return parser.Finish(out, errors, warnings);
}

namespace {

// The stream's buffer: the file's size up to 256 kB, where the default 8 kB
// made a 14-day 1-min file (4.6 MB) about 600 reads. Not zeroed, and no
// larger than a small file needs (the fuzzer reads thousands of those), nor
// smaller than the default.
using StreamBuffer = std::unique_ptr<char[]>;
constexpr std::uintmax_t kStreamBufferBytes = std::uintmax_t{1} << 18;

// Opens `path` for binary reading through `buffer` (kept alive beside the
// stream); with the stream's own buffer when the size cannot be read (the
// open then reports why).
void OpenBuffered(const std::string& path, StreamBuffer* buffer, std::ifstream* in) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (!error) {
    const auto bytes =
        static_cast<std::size_t>(std::clamp<std::uintmax_t>(size + 1, 8192, kStreamBufferBytes));
    buffer->reset(new char[bytes]);
    in->rdbuf()->pubsetbuf(buffer->get(), static_cast<std::streamsize>(bytes));
  }
  in->open(path, std::ios::binary);
}

// Reads a large file on two threads: the caller the rows that start in the
// first half of the bytes after the header, a helper the rest from a second
// stream (both here, one after the other, when the system refuses the
// thread). False, with nothing written, when the file is too small to
// split, a half found an error, or the times do not increase across the
// seam: the caller then reads the file again in one piece, which reports
// every error in line order as always. Local times (a naive time zone) are
// read in one piece: a cell in the hour the clocks repeat depends on the
// row before.
bool ReadInTwoHalves(const std::string& path, std::ifstream& in, const CsvReadOptions& options,
                     Series* out, Diagnostics* errors, Diagnostics* warnings) {
  if (options.naive_time_zone != nullptr) return false;
  CsvParser first(path, options);
  std::size_t header_bytes = 0;
  if (!first.ReadHeaderRow(in, &header_bytes) || first.HasErrors()) return false;
  const std::size_t left = CsvParser::BytesLeft(in);
  if (left < options.two_thread_bytes) return false;
  StreamBuffer later_buffer;
  std::ifstream later_in;
  OpenBuffered(path, &later_buffer, &later_in);
  std::string skipped;  // the end of the line in which the middle falls
  if (!later_in.seekg(static_cast<std::streamoff>(header_bytes + left / 2)) ||
      !std::getline(later_in, skipped)) {
    return false;
  }
  const std::size_t split = left / 2 + skipped.size() + 1;  // bytes after the header
  if (split >= left) return false;
  CsvParser later(path, options);
  later.TakeHeaderOf(first);
  RunBoth([&] { later.ReadRows(later_in, 0, left, left - split); },
          [&] { first.ReadRows(in, 1, split, left); });
  if (!first.Append(std::move(later))) return false;
  return first.Finish(out, errors, warnings);
}

}  // namespace

std::string DescribeCsvLimit(Channel c, double area_m2) {
  PhysicalLimit limit = PhysicalLimitOf(c, area_m2);
  if (c == Channel::kAoiRad) limit = {RadToDeg(limit.lo), RadToDeg(limit.hi)};
  return "[" + FormatNumber(limit.lo) + ", " + FormatNumber(limit.hi) + "] " +
         std::string(kChannels[static_cast<std::size_t>(c)].unit);
}

bool ReadCanonicalCsv(const std::string& path, const CsvReadOptions& options, Series* out,
                      Diagnostics* errors, Diagnostics* warnings) {
  assert(out != nullptr && errors != nullptr);
  StreamBuffer buffer;
  std::ifstream in;
  OpenBuffered(path, &buffer, &in);
  if (!in) {
    errors->push_back({path, 0, "", "", std::string("cannot open: ") + std::strerror(errno)});
    return false;
  }
  if (ReadInTwoHalves(path, in, options, out, errors, warnings)) return true;
  in.clear();
  in.seekg(0);
  return ParseCanonicalCsv(in, path, options, out, errors, warnings);
}

void WriteCsv(std::ostream& out, const Series& series, std::span<const Channel> channels) {
  std::string line(kTimeColumn);
  for (const Channel c : channels) {
    line += ',';
    line += ChannelName(c);
  }
  out << line << '\n';
  for (std::size_t i = 0; i < series.size(); ++i) {
    line = FormatIsoUtc(series.time_s[i]);
    for (const Channel c : channels) {
      line += ',';
      double value = series.At(c, i);
      if (std::isnan(value)) continue;
      if (c == Channel::kAoiRad) value = RadToDeg(value);
      line += FormatNumber(value);
    }
    out << line << '\n';
  }
}

bool WriteCsv(const std::string& path, const Series& series, std::span<const Channel> channels,
              std::string* error) {
  // Written beside the target and renamed over it once complete: a full
  // disk or a crash leaves the old file (or none), never a truncated one.
  const std::string partial = path + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    if (!out) {
      *error = "cannot open " + partial + " for writing: " + std::strerror(errno);
      return false;
    }
    WriteCsv(out, series, channels);
    out.close();
    if (!out) {
      *error = "cannot write " + path + ": " + std::strerror(errno);
      std::remove(partial.c_str());
      return false;
    }
  }
  if (std::rename(partial.c_str(), path.c_str()) != 0) {
    *error = "cannot rename " + partial + " to " + path + ": " + std::strerror(errno);
    std::remove(partial.c_str());
    return false;
  }
  return true;
}

}  // namespace pvtwin
