#include "io/local_time.h"

#include "config/plant_config.h"

#include <cstdlib>
#include <ctime>

namespace pvtwin {

bool UseTimeZone(const std::string& iana, std::string* error) {
  if (!TimeZoneExists(iana)) {
    *error = "timezone = \"" + iana + "\": not a zone of the tz database (e.g. \"Europe/Vienna\")";
    return false;
  }
  ::setenv("TZ", iana.c_str(), 1);
  ::tzset();
  return true;
}

std::int64_t NextLocalTime(std::int64_t now_s, int hour, int minute) {
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

}  // namespace pvtwin
