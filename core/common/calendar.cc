#include "core/common/calendar.h"

#include <cmath>
#include <cstdio>

#include "core/common/units.h"

namespace pvtwin {

namespace {

std::int64_t FloorDiv(std::int64_t a, std::int64_t b) {
  std::int64_t q = a / b;
  if ((a % b != 0) && ((a < 0) != (b < 0))) --q;
  return q;
}

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant,
// "chrono-Compatible Low-Level Date Algorithms", days_from_civil).
std::int64_t DaysFromCivil(std::int64_t y, int m, int d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const std::int64_t yoe = y - era * 400;
  const std::int64_t doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

// Inverse of DaysFromCivil (civil_from_days).
void CivilFromDays(std::int64_t z, std::int64_t* y, int* m, int* d) {
  z += 719468;
  const std::int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const std::int64_t doe = z - era * 146097;
  const std::int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const std::int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const std::int64_t mp = (5 * doy + 2) / 153;
  *d = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  *m = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  *y = yoe + era * 400 + (*m <= 2 ? 1 : 0);
}

}  // namespace

std::int64_t SolarDayOffsetS(const Plant& plant) {
  return static_cast<std::int64_t>(
      std::llround(plant.longitude_rad / (2.0 * kPi) * static_cast<double>(kSecondsPerDay)));
}

std::int64_t SolarDayStartS(std::int64_t t_s, std::int64_t solar_offset_s) {
  return FloorDiv(t_s + solar_offset_s, kSecondsPerDay) * kSecondsPerDay - solar_offset_s;
}

std::int64_t SolarDayStartOfDateS(int year, int month, int day, std::int64_t solar_offset_s) {
  return DaysFromCivil(year, month, day) * kSecondsPerDay - solar_offset_s;
}

std::string SolarDate(std::int64_t t_s, std::int64_t solar_offset_s) {
  std::int64_t y = 0;
  int m = 0, d = 0;
  CivilFromDays(FloorDiv(t_s + solar_offset_s, kSecondsPerDay), &y, &m, &d);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%04lld-%02d-%02d", static_cast<long long>(y), m, d);
  return buf;
}

}  // namespace pvtwin
