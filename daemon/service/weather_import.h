// A weather-forecast file or HTTP body into table weather_forecast: parse
// (io/weather/weather_file.h), bring to 1 min (core/forecast/weather_resample.h),
// write with its source. Shared by `pvtwin import-weather` and the daemon's
// fetch (daemon/service/weather_worker.h), so both read a file the same way.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/common/plant.h"
#include "io/store/store.h"
#include "io/weather/weather_file.h"

namespace pvtwin::cli {

struct WeatherImportResult {
  enum class Status { kOk, kBadInput, kStoreFailed } status = Status::kOk;
  WeatherFile file;
  WeatherResampleSummary summary;
  std::int64_t from_ts = 0, to_ts = 0;  // rows written cover [from_ts, to_ts)
  Diagnostics errors;                   // kBadInput: what is wrong with the input
  std::string store_error;              // kStoreFailed
  // "wrote 2880 1-min rows into weather_forecast (2026-06-20T00:00:00Z ..
  // 2026-06-22T00:00:00Z) from <source>; 2 missing values".
  std::string SummaryLine(const std::string& source) const;
  // One line per irradiance interval above its clear sky (core/forecast/
  // weather_resample.h), the first kNamedAboveClearSky of them, then one
  // counting the rest: "ghi_w_m2 2026-11-29T06:00:00Z .. 2026-11-29T07:00:00Z:
  // 312 W/m² (312 Wh/m²) is more than its clear sky gives (clear sky
  // 3.1 W/m², at most 56 W/m² with cloud enhancement); stored clipped to that
  // (time stamps in local time labelled UTC?)". Empty for a physical file.
  std::vector<std::string> Warnings() const;
};

inline constexpr std::size_t kNamedAboveClearSky = 5;

// Parses and resamples without writing: the 1-min rows into *rows; false
// (result->status kBadInput, result->errors) on bad input.
bool WeatherTextTo1Min(const Plant& plant, const std::string& text, const std::string& name,
                       WeatherImportResult* result, Series* rows);

// source: what weather_forecast.source records, e.g. "import-weather
// forecast.json" or "fetch https://api.open-meteo.com/...". The rows of
// intervals above their clear sky get the source with kAboveClearSkyMark
// appended, written after the others (two transactions: a reader between
// them sees those minutes as they were before).
WeatherImportResult ImportWeatherText(Store& store, const Plant& plant, const std::string& text,
                                      const std::string& name, const std::string& source);

}  // namespace pvtwin::cli
