#include "daemon/service/weather_import.h"

#include "core/forecast/weather_resample.h"
#include "io/platform/time_format.h"

namespace pvtwin::cli {

std::string WeatherImportResult::SummaryLine(const std::string& source) const {
  std::string line = "wrote " + std::to_string(summary.rows) +
                     " 1-min rows into weather_forecast (" + FormatIsoUtc(from_ts) + " .. " +
                     FormatIsoUtc(to_ts) + ") from " + source + " (" + file.format + ")";
  if (file.missing_values > 0) {
    line += "; " + std::to_string(file.missing_values) + " missing values stay missing";
  }
  if (summary.flat_intervals > 0) {
    line += "; " + std::to_string(summary.flat_intervals) +
            " irradiance intervals near sunrise/sunset spread over their daylight minutes";
  }
  return line;
}

bool WeatherTextTo1Min(const Plant& plant, const std::string& text, const std::string& name,
                       WeatherImportResult* result, Series* rows) {
  if (!ParseWeatherFile(text, name, &result->file, &result->errors)) {
    result->status = WeatherImportResult::Status::kBadInput;
    return false;
  }
  WeatherResampleOptions options;
  options.collector_height_m = plant.collector_height_m;
  std::string error;
  if (!ResampleWeatherTo1Min(plant, result->file.weather, options, rows, &result->summary,
                             &error)) {
    result->errors.push_back({name, 0, "", "", error});
    result->status = WeatherImportResult::Status::kBadInput;
    return false;
  }
  result->from_ts = rows->time_s.front();
  result->to_ts = rows->time_s.back() + 60;
  return true;
}

WeatherImportResult ImportWeatherText(Store& store, const Plant& plant, const std::string& text,
                                      const std::string& name, const std::string& source) {
  WeatherImportResult result;
  Series rows;
  if (!WeatherTextTo1Min(plant, text, name, &result, &rows)) return result;
  if (!store.WriteWeatherForecast(rows, source + " (" + result.file.format + ")",
                                  &result.store_error)) {
    result.status = WeatherImportResult::Status::kStoreFailed;
  }
  return result;
}

}  // namespace pvtwin::cli
