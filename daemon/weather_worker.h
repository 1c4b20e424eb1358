// The daemon's fetch of a weather forecast ([forecast] weather_url, issue 15)
// as a thread of its own: every weather_refresh_min it GETs the URL
// (io/http_client.h: connect and total time limits), reads the body as
// import-weather reads a file (daemon/weather_import.h) and writes 1-min
// rows to weather_forecast with the source "fetch <url>", on its own store
// connection. The daemon's loop never waits for it: polling goes on while
// the server is slow or down. A failed fetch (unreachable, timed out,
// HTTP error, a body that is not a forecast) is retried with exponential
// backoff (10 s doubling up to clamp(refresh / 4, 10 s, 300 s)); the log gets
// one line per change of state (the first failure with its reason, the
// recovery), not one per retry. Stop() aborts a transfer in progress.
#pragma once

#include <atomic>
#include <string>
#include <thread>

#include "core/common/plant.h"
#include "daemon/worker_thread.h"
#include "io/log.h"

namespace pvtwin {

struct WeatherFetchSettings {
  std::string store_path;
  std::string url;  // expanded (ExpandWeatherUrl)
  Plant plant;
  double refresh_s = 3600.0;
  double timeout_s = 30.0;
  double first_retry_s = 10.0;
};

class WeatherWorker {
 public:
  WeatherWorker(const WeatherFetchSettings& settings, LogFn log);
  ~WeatherWorker();  // stops and joins
  WeatherWorker(const WeatherWorker&) = delete;
  WeatherWorker& operator=(const WeatherWorker&) = delete;

  void Start();
  void Stop();
  const WeatherFetchSettings& settings() const { return settings_; }
  // True once after each fetch that wrote rows: the loop issues a forecast.
  bool TakeFresh() { return fresh_.exchange(false); }

 private:
  enum class State { kStarting, kOk, kFailing };
  void Loop();
  // One fetch; false with a one-line reason.
  bool FetchOnce(std::string* reason);

  WeatherFetchSettings settings_;
  LogFn log_;
  std::thread thread_;
  StopRequest stop_;
  std::atomic<bool> fresh_{false};
  State state_ = State::kStarting;
  std::string last_reason_;
  double failing_since_s_ = 0.0;
};

}  // namespace pvtwin
