#include "daemon/weather_worker.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "core/common/clock.h"
#include "daemon/weather_import.h"
#include "io/http_client.h"
#include "io/store.h"

namespace pvtwin {

namespace {

std::string Seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f s", s);
  return buf;
}

// Open-Meteo answers a bad request with {"error": true, "reason": "..."}.
std::string ServerReason(const std::string& body) {
  const nlohmann::json j = nlohmann::json::parse(body, nullptr, false);
  if (j.is_object() && j.contains("reason") && j["reason"].is_string()) {
    return ": " + j["reason"].get<std::string>();
  }
  return "";
}

}  // namespace

WeatherWorker::WeatherWorker(const WeatherFetchSettings& settings, LogFn log)
    : settings_(settings), log_(std::move(log)) {}

WeatherWorker::~WeatherWorker() { Stop(); }

void WeatherWorker::Start() {
  thread_ = std::thread([this] { Loop(); });
}

void WeatherWorker::Stop() {
  stop_.Set();
  if (thread_.joinable()) thread_.join();
}

bool WeatherWorker::FetchOnce(std::string* reason) {
  HttpOptions options;
  options.total_timeout_s = settings_.timeout_s;
  options.connect_timeout_s = std::min(10.0, settings_.timeout_s);
  const HttpResponse response = HttpGet(settings_.url, options, stop_.Flag());
  if (response.outcome == HttpResponse::Outcome::kAborted) {
    *reason = "stopped";
    return false;
  }
  if (response.outcome != HttpResponse::Outcome::kOk) {
    *reason =
        std::string(OutcomeName(response.outcome)) + " (" + response.error +
        (response.outcome == HttpResponse::Outcome::kHttpError ? ServerReason(response.body) : "") +
        ")";
    return false;
  }
  std::string error;
  std::unique_ptr<Store> store = Store::Open(settings_.store_path, &error);
  if (!store) {
    *reason = "the store cannot be opened: " + error;
    return false;
  }
  const std::string source = "fetch " + settings_.url;
  const cli::WeatherImportResult r =
      cli::ImportWeatherText(*store, settings_.plant, response.body, settings_.url, source);
  switch (r.status) {
    case cli::WeatherImportResult::Status::kBadInput:
      *reason = "the answer is not a usable forecast: " +
                (r.errors.empty() ? std::string("?") : r.errors.front().ToString());
      return false;
    case cli::WeatherImportResult::Status::kStoreFailed:
      *reason = "writing weather_forecast failed: " + r.store_error;
      return false;
    case cli::WeatherImportResult::Status::kOk:
      break;
  }
  for (const std::string& note : r.file.notes) log_(kWarning, "weather: " + note);
  *reason = r.SummaryLine(source);
  return true;
}

void WeatherWorker::Loop() {
  Backoff backoff(settings_.first_retry_s,
                  std::clamp(settings_.refresh_s / 4.0, settings_.first_retry_s, 300.0));
  while (!stop_.IsSet()) {
    std::string reason;
    const bool ok = FetchOnce(&reason);
    if (stop_.IsSet()) break;
    if (ok) {
      if (state_ == State::kFailing) {
        log_(kNotice, "weather: " + settings_.url + " answers again after " +
                          Seconds(WallNowS() - failing_since_s_) + " of failures; " + reason);
      } else {
        log_(kInfo, "weather: " + reason);
      }
      state_ = State::kOk;
      fresh_ = true;
      backoff.Reset();
      stop_.WaitFor(settings_.refresh_s);
      continue;
    }
    if (state_ != State::kFailing || reason.substr(0, 12) != last_reason_.substr(0, 12)) {
      log_(kWarning, "weather: fetching " + settings_.url + " failed: " + reason +
                         "; forecasts use the weather_forecast rows they have, else persistence; "
                         "retried with backoff");
      if (state_ != State::kFailing) failing_since_s_ = WallNowS();
    }
    state_ = State::kFailing;
    last_reason_ = reason;
    stop_.WaitFor(backoff.Next());
  }
}

}  // namespace pvtwin
