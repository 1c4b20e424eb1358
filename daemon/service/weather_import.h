// A weather-forecast file or HTTP body into table weather_forecast: parse
// (io/weather/weather_file.h), bring to 1 min (core/forecast/weather_resample.h),
// write with its source. Shared by `pvtwin import-weather` and the daemon's
// fetch (daemon/service/weather_worker.h), so both read a file the same way.
#pragma once

#include <cstdint>
#include <string>

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
};

// Parses and resamples without writing: the 1-min rows into *rows; false
// (result->status kBadInput, result->errors) on bad input.
bool WeatherTextTo1Min(const Plant& plant, const std::string& text, const std::string& name,
                       WeatherImportResult* result, Series* rows);

// source: what weather_forecast.source records, e.g. "import-weather
// forecast.json" or "fetch https://api.open-meteo.com/...".
WeatherImportResult ImportWeatherText(Store& store, const Plant& plant, const std::string& text,
                                      const std::string& name, const std::string& source);

}  // namespace pvtwin::cli
