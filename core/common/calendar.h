// Calendar and solar-day helpers: the local mean solar day that the
// backtest, the forecast skill and the gap diagnosis split data by (a day
// runs from local mean solar midnight to midnight, so solar noon is its
// middle at every longitude), and its calendar date.
#pragma once

#include <cstdint>
#include <string>

#include "core/common/plant.h"

namespace pvtwin {

inline constexpr std::int64_t kSecondsPerDay = 86400;

// Local mean solar time − UTC in seconds: λ/(2π) · 86400 s, rounded.
std::int64_t SolarDayOffsetS(const Plant& plant);

// Start (unix s) of the local mean solar day that contains t_s.
std::int64_t SolarDayStartS(std::int64_t t_s, std::int64_t solar_offset_s);

// Start (unix s) of the local mean solar day with the given calendar date
// (proleptic Gregorian; month 1…12, day 1…31, not checked here).
std::int64_t SolarDayStartOfDateS(int year, int month, int day, std::int64_t solar_offset_s);

// "YYYY-MM-DD": the calendar date of local mean solar time at t_s.
std::string SolarDate(std::int64_t t_s, std::int64_t solar_offset_s);

}  // namespace pvtwin
