// The daemon's fetch of a weather forecast ([forecast] weather_url, issue 15)
// as a thread of its own: every weather_refresh_min it GETs the URL
// (io/weather/http_client.h: connect and total time limits), reads the body as
// import-weather reads a file (daemon/service/weather_import.h) and writes 1-min
// rows to weather_forecast with the source "fetch <url>" (credential-like
// query parameters shown as ***, io/weather/http_client.h UrlForLogs), on its own
// store connection. The daemon's loop never waits for it: polling goes on while
// the server is slow or down. A failed fetch (unreachable, timed out,
// HTTP error, a body that is not a forecast) is retried with exponential
// backoff (10 s doubling up to clamp(refresh / 4, 10 s, 300 s)); the log gets
// one line per change of state (the first failure with its reason, the
// recovery), not one per retry. Stop() aborts a transfer in progress.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "core/common/plant.h"
#include "daemon/service/worker_thread.h"
#include "io/platform/log.h"
#include "io/store/store.h"

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
  // What one fetch did: ok with the summary line, or a failure of a kind
  // ("unreachable", "HTTP error", "bad answer", "store", ...) with its reason.
  struct Outcome {
    bool ok = false;
    std::string kind;
    std::string text;
  };
  void Loop();
  Outcome FetchOnce();
  // Logs the outcome when it changes the state (or the kind of failure).
  void Report(const Outcome& outcome);

  WeatherFetchSettings settings_;
  LogFn log_;
  std::thread thread_;
  StopRequest stop_;
  std::atomic<bool> fresh_{false};
  std::unique_ptr<Store> store_;  // this thread's connection, opened at the first answer
  State state_ = State::kStarting;
  std::string failure_kind_;
  double failing_since_s_ = 0.0;
};

}  // namespace pvtwin
