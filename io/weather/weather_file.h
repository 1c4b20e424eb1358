// Weather-forecast files at the I/O edge (issue 15, `pvtwin import-weather`
// and the daemon's fetch): Open-Meteo's JSON and the canonical CSV, read
// into core's ProviderWeather (core/forecast/weather_resample.h).
//
// Open-Meteo JSON (https://open-meteo.com/en/docs): the block `minutely_15`
// when present, else `hourly`, each with `time` and any of
//   global_tilted_irradiance                      → in-plane irradiance
//   shortwave_radiation, diffuse_radiation,       → GHI, DHI (or DHI = GHI −
//   direct_radiation, direct_normal_irradiance      direct horizontal, or from DNI)
//   temperature_2m, dew_point_2m,                 → °C
//   relative_humidity_2m, cloud_cover             → %
//   wind_speed_10m                                → m/s (file: m/s or km/h)
// and the unit of every variable used in `hourly_units` / `minutely_15_units`
// (W/m², °C, %, m/s or km/h; any other unit is an error naming the field).
// Open-Meteo's convention: radiation is the mean of the PRECEDING interval,
// the other variables are instantaneous at the time stamp. `time` is ISO 8601
// local time of `timezone` (a tz database zone, DST included) or, when that
// is not a known zone, of the fixed `utc_offset_seconds`; with
// `timeformat=unixtime` it is unix seconds.
//
// Canonical CSV: `time` plus any of weather_forecast's columns (g_poa_w_m2,
// ghi_w_m2, dhi_w_m2, t_amb_c, wind_m_s at the collector, t_sky_c,
// lw_down_w_m2); each row is the mean over [time, time + step) (doc/contracts.md).
//
// Bad input is an error naming file, field (with array index or line) and
// what was expected: missing arrays, arrays of another length than `time`,
// times not increasing or not evenly spaced, unknown units, values that are
// not numbers, truncated JSON. A null is a missing value (counted and
// reported in notes), never a zero.
#pragma once

#include <string>
#include <vector>

#include "core/common/diagnostic.h"
#include "core/forecast/weather_resample.h"

namespace pvtwin {

struct WeatherFile {
  ProviderWeather weather;
  std::string format;              // "Open-Meteo JSON, hourly", "canonical CSV"
  std::vector<std::string> notes;  // e.g. "hourly.temperature_2m: 2 null values read as missing"
  std::size_t missing_values = 0;  // nulls (JSON) or empty cells (CSV)
};

// Parses text (a JSON object when it starts with '{', else the canonical
// CSV); messages name `name` as the file. True when there was no error.
bool ParseWeatherFile(const std::string& text, const std::string& name, WeatherFile* out,
                      Diagnostics* errors);

// Reads the file at path and parses it as above.
bool ReadWeatherFile(const std::string& path, WeatherFile* out, Diagnostics* errors);

}  // namespace pvtwin
