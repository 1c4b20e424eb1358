#include "io/platform/local_time.h"

#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <mutex>
#include <set>

#include "config/plant_config.h"

namespace pvtwin {

namespace {

// The C library knows one zone per process (TZ). Every function here that
// reads local time names the zone it needs and holds this lock while TZ is
// that zone, so a weather file read on a worker thread (its naive times in
// "GMT") can never move the daemon's schedule or its local days to another
// zone, and no two threads set and read TZ at once.
std::mutex& ZoneMutex() {
  static std::mutex mutex;
  return mutex;
}

std::string& ScheduleZone() {  // UseTimeZone's zone; "" = the ambient TZ
  static std::string zone;
  return zone;
}

// With the lock held: makes TZ `iana` ("" leaves it as it is).
void SwitchZoneLocked(const std::string& iana) {
  if (iana.empty()) return;
  const char* current = std::getenv("TZ");
  if (current != nullptr && iana == current) return;
  ::setenv("TZ", iana.c_str(), 1);
  ::tzset();
}

}  // namespace

bool UseTimeZone(const std::string& iana, std::string* error) {
  if (!TimeZoneExists(iana)) {
    *error = "timezone = \"" + iana + "\": not a zone of the tz database (e.g. \"Europe/Vienna\")";
    return false;
  }
  const std::lock_guard lock(ZoneMutex());
  ScheduleZone() = iana;
  SwitchZoneLocked(iana);
  return true;
}

std::int64_t NextLocalTime(std::int64_t now_s, int hour, int minute) {
  const std::lock_guard lock(ZoneMutex());
  SwitchZoneLocked(ScheduleZone());
  const int target = hour * 60 + minute;
  auto local = [](std::int64_t t, int* minute_of_day, int* day_of_year) {
    const std::time_t tt = static_cast<std::time_t>(t);
    std::tm tm{};
    ::localtime_r(&tt, &tm);
    *minute_of_day = tm.tm_hour * 60 + tm.tm_min;
    *day_of_year = tm.tm_year * 400 + tm.tm_yday;
  };
  // Walk whole minutes: the run is due at the first minute that is at or past
  // the target while the minute before was earlier the same local day (or on
  // the day before). Offsets of every zone are whole minutes.
  std::int64_t t = (now_s / 60 + 1) * 60;
  int prev_minute = 0, prev_day = 0;
  local(t - 60, &prev_minute, &prev_day);
  for (int i = 0; i < 3 * 1440; ++i, t += 60) {
    int m = 0, d = 0;
    local(t, &m, &d);
    const bool crossed = m >= target && (prev_minute < target || prev_day != d);
    if (crossed) return t;
    prev_minute = m;
    prev_day = d;
  }
  return t;  // unreachable for any real zone: every local day has the time or a jump past it
}

namespace {

// "+01:00", "-0530", "+1", "UTC+01:00": seconds east of UTC.
std::optional<int> ParseFixedOffset(std::string text) {
  if (text.rfind("UTC", 0) == 0) text = text.substr(3);
  if (text.size() < 2 || (text[0] != '+' && text[0] != '-')) return std::nullopt;
  const int sign = text[0] == '-' ? -1 : 1;
  std::string digits = text.substr(1);
  int hours = 0, minutes = 0;
  const std::size_t colon = digits.find(':');
  std::string h = digits, m;
  if (colon != std::string::npos) {
    h = digits.substr(0, colon);
    m = digits.substr(colon + 1);
  } else if (digits.size() == 4) {
    h = digits.substr(0, 2);
    m = digits.substr(2);
  }
  auto number = [](const std::string& d, int* out) {
    const auto [end, ec] = std::from_chars(d.data(), d.data() + d.size(), *out);
    return !d.empty() && d.size() <= 2 && ec == std::errc() && end == d.data() + d.size();
  };
  if (!number(h, &hours) || (!m.empty() && !number(m, &minutes)) ||
      (colon != std::string::npos && m.size() != 2)) {
    return std::nullopt;
  }
  if (hours > 14 || minutes > 59) return std::nullopt;
  return sign * (hours * 3600 + minutes * 60);
}

// Seconds east of UTC of the process's zone at the instant t.
int OffsetAt(std::int64_t t) {
  const auto tt = static_cast<std::time_t>(t);
  std::tm tm{};
  ::localtime_r(&tt, &tm);
  return static_cast<int>(tm.tm_gmtoff);
}

constexpr std::int64_t kDayS = 86400;

std::int64_t FloorDiv(std::int64_t a, std::int64_t b) { return a / b - (a % b < 0 ? 1 : 0); }

// Days since 1970-01-01 of the civil date at the instant t: in UTC, or in
// the process's zone.
std::int64_t DayNumberAt(std::int64_t t, bool utc) {
  if (utc) return FloorDiv(t, kDayS);
  const auto tt = static_cast<std::time_t>(t);
  std::tm tm{};
  ::localtime_r(&tt, &tm);
  const std::chrono::year_month_day ymd{std::chrono::year{tm.tm_year + 1900},
                                        std::chrono::month{static_cast<unsigned>(tm.tm_mon + 1)},
                                        std::chrono::day{static_cast<unsigned>(tm.tm_mday)}};
  return std::chrono::sys_days{ymd}.time_since_epoch().count();
}

// The first instant whose civil date is day_number or later. Every zone's
// offset lies within ±26 h of UTC, so the date two days either side of the
// UTC midnight brackets it; the date never goes back across midnight in the
// zones of today's tz database, so halving the bracket finds the instant.
std::int64_t DayStart(std::int64_t day_number, bool utc) {
  if (utc) return day_number * kDayS;
  std::int64_t before = (day_number - 2) * kDayS;  // its date is earlier
  std::int64_t after = (day_number + 2) * kDayS;   // its date is day_number or later
  while (after - before > 1) {
    const std::int64_t mid = before + (after - before) / 2;
    (DayNumberAt(mid, false) >= day_number ? after : before) = mid;
  }
  return after;
}

std::string DateText(std::int64_t day_number) {
  const std::chrono::year_month_day ymd{std::chrono::sys_days{std::chrono::days{day_number}}};
  char text[16];
  std::snprintf(text, sizeof text, "%04d-%02u-%02u", static_cast<int>(ymd.year()),
                static_cast<unsigned>(ymd.month()), static_cast<unsigned>(ymd.day()));
  return text;
}

}  // namespace

bool LocalDaysOverlapping(const std::string& iana, std::int64_t from_s, std::int64_t to_s,
                          std::vector<LocalDay>* days, std::string* error) {
  days->clear();
  const bool utc = iana == "UTC";
  if (!utc && !TimeZoneExists(iana)) {
    *error = "timezone = \"" + iana + "\": not a zone of the tz database (e.g. \"Europe/Vienna\")";
    return false;
  }
  const std::lock_guard lock(ZoneMutex());
  if (!utc) SwitchZoneLocked(iana);
  if (to_s <= from_s) return true;
  const std::int64_t last = DayNumberAt(to_s - 1, utc);
  std::int64_t start = DayStart(DayNumberAt(from_s, utc), utc);
  for (std::int64_t day = DayNumberAt(from_s, utc); day <= last; ++day) {
    const std::int64_t end = DayStart(day + 1, utc);
    // A date the zone skipped (Samoa, 2011-12-30) has no instants.
    if (end > start) days->push_back({DateText(day), start, end});
    start = end;
  }
  return true;
}

std::optional<NaiveTimeZone> NaiveTimeZone::Parse(const std::string& text, std::string* error) {
  NaiveTimeZone zone;
  zone.name_ = text;
  if (const std::optional<int> offset = ParseFixedOffset(text)) {
    zone.fixed_offset_s_ = offset;
    return zone;
  }
  if (!TimeZoneExists(text)) {
    *error = "\"" + text +
             "\": expected a zone of the tz database (e.g. \"Europe/Vienna\", daylight saving "
             "time included) or a fixed offset from UTC (e.g. \"+01:00\")";
    return std::nullopt;
  }
  return zone;
}

int NaiveTimeZone::Resolve(std::int64_t wall_s, std::int64_t utc_s[2]) const {
  if (fixed_offset_s_) {
    utc_s[0] = wall_s - *fixed_offset_s_;
    return 1;
  }
  // The offsets in force a day either side hold every offset that can apply
  // at wall_s (zones change their offset at most once a day); each gives a
  // candidate instant, which counts if the zone has that offset then.
  const std::lock_guard lock(ZoneMutex());
  SwitchZoneLocked(name_);
  const std::set<int> offsets = {OffsetAt(wall_s - 86400), OffsetAt(wall_s),
                                 OffsetAt(wall_s + 86400)};
  int n = 0;
  std::set<std::int64_t> found;
  for (const int offset : offsets) {
    const std::int64_t t = wall_s - offset;
    if (OffsetAt(t) == offset) found.insert(t);
  }
  for (const std::int64_t t : found) {
    if (n < 2) utc_s[n++] = t;
  }
  return n;
}

}  // namespace pvtwin
