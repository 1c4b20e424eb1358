#include "io/platform/time_format.h"

#include <charconv>
#include <chrono>
#include <cstdio>

#include "io/platform/local_time.h"

namespace pvtwin {
namespace {

constexpr std::int64_t kSecondsPerDay = 86400;

constexpr bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// A left-to-right reader over one cell.
class Cursor {
 public:
  explicit Cursor(std::string_view text) : text_(text) {}

  bool AtEnd() const { return pos_ == text_.size(); }
  char Peek() const { return AtEnd() ? '\0' : text_[pos_]; }
  bool Consume(char c) {
    if (Peek() != c) return false;
    ++pos_;
    return true;
  }
  // Exactly n decimal digits.
  bool Digits(int n, int* out) {
    int value = 0;
    for (int i = 0; i < n; ++i) {
      if (!IsDigit(Peek())) return false;
      value = value * 10 + (text_[pos_++] - '0');
    }
    *out = value;
    return true;
  }
  // One or more digits, discarded (fractions of a second).
  bool SkipDigits() {
    const std::size_t start = pos_;
    while (IsDigit(Peek())) ++pos_;
    return pos_ > start;
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

bool ParseUnixSeconds(std::string_view text, std::int64_t* unix_s, std::string* error) {
  const char* kRule = "expected unix seconds (digits, optionally with a fraction)";
  std::size_t pos = 0;
  bool negative = false;
  if (pos < text.size() && (text[pos] == '-' || text[pos] == '+')) negative = text[pos++] == '-';
  std::int64_t whole = 0;
  std::size_t n_digits = 0;
  for (; pos < text.size() && IsDigit(text[pos]); ++pos, ++n_digits) {
    if (n_digits == 15) {  // ±3e7 years is far beyond any measurement
      *error = "unix seconds out of range";
      return false;
    }
    whole = whole * 10 + (text[pos] - '0');
  }
  if (n_digits == 0) {
    *error = kRule;
    return false;
  }
  bool has_fraction = false;
  if (pos < text.size() && text[pos] == '.') {
    ++pos;
    for (; pos < text.size() && IsDigit(text[pos]); ++pos) {
      if (text[pos] != '0') has_fraction = true;
    }
  }
  if (pos != text.size()) {
    *error = kRule;
    return false;
  }
  // floor: -1.5 s lies in the second that starts at -2.
  *unix_s = negative ? -whole - (has_fraction ? 1 : 0) : whole;
  return true;
}

// A naive wall-clock time (as if UTC seconds) in zone: the instant, or in
// the repeated hour of autumn the earliest one after after_s (rows count
// forward through the hour twice).
bool ResolveNaive(std::int64_t wall_s, const NaiveTimeZone& zone, std::int64_t after_s,
                  std::int64_t* unix_s, std::string* error) {
  std::int64_t candidates[2] = {0, 0};
  const int n = zone.Resolve(wall_s, candidates);
  if (n == 0) {
    *error = "this local time does not exist in " + zone.name() +
             " (the clocks skip it in spring); a logger that keeps standard time all year "
             "needs a fixed offset, e.g. --timezone +01:00";
    return false;
  }
  *unix_s = n == 2 && candidates[0] <= after_s ? candidates[1] : candidates[0];
  return true;
}

bool ParseIso(std::string_view text, const NaiveTimeZone* zone, std::int64_t after_s,
              std::int64_t* unix_s, std::string* error) {
  const char* kRule =
      "expected ISO 8601 time YYYY-MM-DDTHH:MM:SS with Z or ±HH:MM, or unix seconds";
  Cursor c(text);
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  if (!c.Digits(4, &year) || !c.Consume('-') || !c.Digits(2, &month) || !c.Consume('-') ||
      !c.Digits(2, &day) || !(c.Consume('T') || c.Consume('t') || c.Consume(' ')) ||
      !c.Digits(2, &hour) || !c.Consume(':') || !c.Digits(2, &minute)) {
    *error = kRule;
    return false;
  }
  if (c.Consume(':')) {
    if (!c.Digits(2, &second)) {
      *error = kRule;
      return false;
    }
    if ((c.Consume('.') || c.Consume(',')) && !c.SkipDigits()) {
      *error = kRule;
      return false;
    }
  }
  int offset_s = 0;
  bool naive = false;
  if (c.Consume('Z') || c.Consume('z')) {
    offset_s = 0;
  } else if (c.Peek() == '+' || c.Peek() == '-') {
    const int sign = c.Peek() == '-' ? -1 : 1;
    c.Consume(c.Peek());
    int offset_h = 0, offset_min = 0;
    if (!c.Digits(2, &offset_h)) {
      *error = kRule;
      return false;
    }
    if (!c.AtEnd()) {
      c.Consume(':');
      if (!c.Digits(2, &offset_min)) {
        *error = kRule;
        return false;
      }
    }
    if (offset_h > 23 || offset_min > 59) {
      *error = "UTC offset out of range";
      return false;
    }
    offset_s = sign * (offset_h * 3600 + offset_min * 60);
  } else if (c.AtEnd()) {
    if (zone == nullptr) {
      *error =
          "time needs Z or a ±HH:MM offset (local time is ambiguous; --timezone says "
          "which zone naive times are in)";
      return false;
    }
    naive = true;
  }
  if (!c.AtEnd()) {
    *error = kRule;
    return false;
  }
  const std::chrono::year_month_day date{std::chrono::year{year},
                                         std::chrono::month{static_cast<unsigned>(month)},
                                         std::chrono::day{static_cast<unsigned>(day)}};
  if (!date.ok()) {
    *error = "no such date";
    return false;
  }
  if (hour > 23 || minute > 59 || second > 59) {
    *error = "time of day out of range";
    return false;
  }
  const std::int64_t days = std::chrono::sys_days{date}.time_since_epoch().count();
  const std::int64_t wall_s = days * kSecondsPerDay + hour * 3600 + minute * 60 + second;
  if (naive) return ResolveNaive(wall_s, *zone, after_s, unix_s, error);
  *unix_s = wall_s - offset_s;
  return true;
}

}  // namespace

namespace {

// Unix seconds use only a sign, digits and a decimal point; anything else
// (a '-' after the year, ':', 'T') is read as ISO 8601.
bool LooksLikeUnixSeconds(std::string_view text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    if (!(IsDigit(ch) || ch == '.' || (i == 0 && (ch == '-' || ch == '+')))) return false;
  }
  return true;
}

}  // namespace

bool ParseTime(std::string_view text, std::int64_t* unix_s, std::string* error) {
  return ParseTimeIn(text, nullptr, 0, unix_s, error);
}

bool ParseTimeIn(std::string_view text, const NaiveTimeZone* zone, std::int64_t after_s,
                 std::int64_t* unix_s, std::string* error) {
  if (text.empty()) {
    *error = "must not be empty";
    return false;
  }
  return LooksLikeUnixSeconds(text) ? ParseUnixSeconds(text, unix_s, error)
                                    : ParseIso(text, zone, after_s, unix_s, error);
}

std::string FormatIsoUtc(std::int64_t unix_s) {
  std::int64_t days = unix_s / kSecondsPerDay;
  std::int64_t seconds = unix_s % kSecondsPerDay;
  if (seconds < 0) {
    seconds += kSecondsPerDay;
    --days;
  }
  const std::chrono::year_month_day date{
      std::chrono::sys_days{std::chrono::days{static_cast<std::chrono::days::rep>(days)}}};
  char buf[48];
  std::snprintf(buf, sizeof buf, "%04d-%02u-%02uT%02d:%02d:%02dZ", static_cast<int>(date.year()),
                static_cast<unsigned>(date.month()), static_cast<unsigned>(date.day()),
                static_cast<int>(seconds / 3600), static_cast<int>(seconds / 60 % 60),
                static_cast<int>(seconds % 60));
  return buf;
}

bool ParseTimeArgument(std::string_view text, std::int64_t now_s, std::int64_t* unix_s,
                       std::string* error) {
  constexpr std::string_view kForms =
      "expected ISO 8601 with Z or an offset, unix seconds, a date YYYY-MM-DD (00:00 UTC), "
      "\"now\" or a time relative to now such as -14d, -6h, -30m";
  if (text == "now") {
    *unix_s = now_s;
    return true;
  }
  // Relative: sign, digits, one unit letter.
  if (text.size() >= 3 && (text.front() == '-' || text.front() == '+') &&
      std::string_view("dhms").find(text.back()) != std::string_view::npos) {
    const std::string_view digits = text.substr(1, text.size() - 2);
    std::int64_t n = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), n);
    const std::int64_t unit_s = text.back() == 'd'   ? 86400
                                : text.back() == 'h' ? 3600
                                : text.back() == 'm' ? 60
                                                     : 1;
    if (ec == std::errc() && end == digits.data() + digits.size() && n <= 36500LL * 86400) {
      *unix_s = now_s + (text.front() == '-' ? -1 : 1) * n * unit_s;
      return true;
    }
    *error = std::string(kForms);
    return false;
  }
  // A date alone: its midnight UTC.
  if (text.size() == 10 && text[4] == '-' && text[7] == '-') {
    return ParseTime(std::string(text) + "T00:00:00Z", unix_s, error) ||
           (*error = std::string(kForms), false);
  }
  if (ParseTime(text, unix_s, error)) return true;
  *error += " (" + std::string(kForms) + ")";
  return false;
}

}  // namespace pvtwin
