#include "daemon/service/weather_import.h"

#include "core/common/text.h"
#include "core/forecast/weather_resample.h"
#include "io/platform/time_format.h"

namespace pvtwin::cli {

namespace {

std::string Rounded(double x) { return SignificantDigits(x, 3); }

// The rows of `rows` whose flag is `flagged` (no flags: all are unflagged).
Series RowsFlagged(const Series& rows, const std::vector<std::uint8_t>& flags, bool flagged) {
  Series part;
  part.step_s = rows.step_s;
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    if (!rows.columns[c].empty()) part.columns[c].reserve(rows.size());
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if ((i < flags.size() && flags[i] != 0) != flagged) continue;
    part.time_s.push_back(rows.time_s[i]);
    for (std::size_t c = 0; c < kNumChannels; ++c) {
      if (!rows.columns[c].empty()) part.columns[c].push_back(rows.columns[c][i]);
    }
  }
  return part;
}

}  // namespace

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
  if (!summary.above_clear_sky.empty()) {
    line += "; " + std::to_string(summary.above_clear_sky.size()) +
            " irradiance intervals above their clear sky stored clipped (see the warnings)";
  }
  if (summary.capped_poa_minutes > 0) {
    line += "; " + std::to_string(summary.capped_poa_minutes) +
            " minutes of g_poa_w_m2 from GHI/DHI capped at the clear-sky bound (sun near the "
            "horizon)";
  }
  if (summary.outside_limits > 0) {
    line += "; " + std::to_string(summary.outside_limits) +
            " values outside the physical limits made missing";
  }
  return line;
}

std::vector<std::string> WeatherImportResult::Warnings() const {
  std::vector<std::string> lines;
  const std::vector<IrradianceAboveClearSky>& above = summary.above_clear_sky;
  for (std::size_t i = 0; i < above.size() && i < kNamedAboveClearSky; ++i) {
    const IrradianceAboveClearSky& a = above[i];
    const double hours = static_cast<double>(a.to_s - a.from_s) / 3600.0;
    lines.push_back(std::string(ChannelName(a.channel)) + " " + FormatIsoUtc(a.from_s) + " .. " +
                    FormatIsoUtc(a.to_s) + ": " + Rounded(a.value_w_m2) + " W/m² (" +
                    Rounded(a.value_w_m2 * hours) +
                    " Wh/m²) is more than its clear sky gives (clear sky " +
                    Rounded(a.clear_sky_w_m2) + " W/m², at most " + Rounded(a.bound_w_m2) +
                    " W/m² with cloud enhancement); stored clipped to that (time stamps in local "
                    "time labelled UTC?)");
  }
  if (above.size() > kNamedAboveClearSky) {
    lines.push_back("and " + std::to_string(above.size() - kNamedAboveClearSky) +
                    " more irradiance intervals above their clear sky, stored clipped");
  }
  return lines;
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
  const std::string written = source + " (" + result.file.format + ")";
  const std::vector<std::uint8_t>& flags = result.summary.above_clear_sky_rows;
  if (!store.WriteWeatherForecast(RowsFlagged(rows, flags, false), written, &result.store_error) ||
      (!flags.empty() && !store.WriteWeatherForecast(RowsFlagged(rows, flags, true),
                                                     written + std::string(kAboveClearSkyMark),
                                                     &result.store_error))) {
    result.status = WeatherImportResult::Status::kStoreFailed;
  }
  return result;
}

}  // namespace pvtwin::cli
