// libFuzzer harness for the weather-forecast reader (io/weather/weather_file.h),
// which reads what a user hands to import-weather and what a weather server
// answers the daemon: Open-Meteo JSON or a canonical CSV. It must never
// crash, every diagnostic must be printable, and what it accepts must be
// brought to 1 min (core/forecast/weather_resample.h) without a crash, with
// every interval's irradiance energy kept, except an interval above what its
// clear sky can give, which is clipped (never raised) and flagged, and no
// minute above the physical limit. Seeds: tests/fuzz/corpus/weather/
// and the recorded answers in tests/weather/data/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/forecast/weather_resample.h"
#include "io/weather/weather_file.h"

namespace {

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  pvtwin::WeatherFile file;
  pvtwin::Diagnostics errors;
  const bool ok = pvtwin::ParseWeatherFile(text, "fuzz.json", &file, &errors);
  Require(ok == errors.empty());
  for (const pvtwin::Diagnostic& d : errors) {
    for (const char c : d.ToString()) Require(static_cast<unsigned char>(c) >= 0x20 || c == '\t');
  }
  if (!ok) return 0;
  pvtwin::Plant plant;
  plant.latitude_rad = 0.8;
  plant.longitude_rad = 0.28;
  plant.tilt_rad = 0.35;
  plant.azimuth_rad = 3.14159;
  pvtwin::Series rows;
  pvtwin::WeatherResampleSummary summary;
  std::string error;
  Require(pvtwin::ResampleWeatherTo1Min(plant, file.weather, {}, &rows, &summary, &error));
  const pvtwin::ProviderWeather& w = file.weather;
  if (w.ghi_w_m2.empty()) return 0;
  const auto step = static_cast<std::int64_t>(w.step_s);
  const auto offset = static_cast<std::int64_t>(w.irradiance_offset_s);
  for (std::size_t i = 0; i < w.time_s.size(); ++i) {
    if (std::isnan(w.ghi_w_m2[i])) continue;
    const auto first = static_cast<std::size_t>((w.time_s[i] + offset - rows.time_s[0]) / 60);
    double sum = 0.0;
    bool clipped = false;
    for (std::int64_t k = 0; k < step / 60; ++k) {
      const std::size_t row = first + static_cast<std::size_t>(k);
      const double ghi = rows[pvtwin::Channel::kGhiWM2][row];
      Require(!(ghi > 2500.0));  // never above the physical limit
      sum += ghi;
      clipped = clipped || (!summary.above_clear_sky_rows.empty() &&
                            summary.above_clear_sky_rows[row] != 0);
    }
    const double mean = sum / static_cast<double>(step / 60);
    const double tolerance = 1e-6 * (1.0 + std::abs(w.ghi_w_m2[i]));
    if (clipped) {
      // An interval above what its clear sky can give keeps at most its energy.
      Require(mean <= w.ghi_w_m2[i] + tolerance);
    } else {
      Require(std::abs(mean - w.ghi_w_m2[i]) <= tolerance);
    }
  }
  return 0;
}
