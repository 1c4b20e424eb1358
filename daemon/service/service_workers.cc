// The upload and weather jobs of the Service (service_internal.h): each
// runs on its own thread (upload_worker.h, weather_worker.h); the loop only
// starts, restarts and stops them.
#include "daemon/service/service_internal.h"
#include "io/platform/log.h"
#include "io/weather/http_client.h"

namespace pvtwin::service_detail {

void Service::StartUpload() {
  upload_ = std::make_unique<UploadWorker>(
      UploadSettingsFor(config_), config_.upload.interval_s,
      [](int priority, const std::string& line) { LogToStderr(priority, line); });
  upload_->Start();
}

void Service::UpdateWeatherFetch() {
  WeatherFetchSettings settings;
  settings.store_path = config_.storage.path;
  settings.plant = config_.plant;
  settings.url = config_.forecast.weather_url.empty()
                     ? ""
                     : ExpandWeatherUrl(config_.forecast.weather_url, config_.plant);
  settings.refresh_s = config_.forecast.weather_refresh_min * 60.0;
  settings.timeout_s = config_.forecast.weather_timeout_s;
  if (weather_ && weather_->settings().url == settings.url &&
      weather_->settings().refresh_s == settings.refresh_s &&
      weather_->settings().timeout_s == settings.timeout_s &&
      PlantKeyValues(weather_->settings().plant) == PlantKeyValues(settings.plant)) {
    return;
  }
  weather_.reset();  // stops and joins the old thread
  if (settings.url.empty()) return;
  LogToStderr(kInfo, "weather: fetching " + UrlForLogs(settings.url) + " every " +
                         Format("%.0f", config_.forecast.weather_refresh_min) + " min");
  weather_ = std::make_unique<WeatherWorker>(
      settings, [](int priority, const std::string& line) { LogToStderr(priority, line); });
  weather_->Start();
}

}  // namespace pvtwin::service_detail
