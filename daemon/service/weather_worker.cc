#include "daemon/service/weather_worker.h"

#include <algorithm>
#include <memory>
#include <nlohmann/json.hpp>

#include "core/common/clock.h"
#include "core/common/text.h"
#include "core/common/diagnostic.h"
#include "daemon/service/weather_import.h"
#include "io/weather/http_client.h"

namespace pvtwin {

namespace {

// Open-Meteo answers a bad request with {"error": true, "reason": "..."}.
std::string ServerReason(const std::string& body) {
  const nlohmann::json j = nlohmann::json::parse(body, nullptr, false);
  if (j.is_object() && j.contains("reason") && j["reason"].is_string()) {
    return ": " + PrintableExcerpt(j["reason"].get<std::string>());
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

WeatherWorker::Outcome WeatherWorker::FetchOnce() {
  HttpOptions options;
  options.total_timeout_s = settings_.timeout_s;
  options.connect_timeout_s = std::min(10.0, settings_.timeout_s);
  const HttpResponse response = HttpGet(settings_.url, options, stop_.Flag());
  if (response.outcome != HttpResponse::Outcome::kOk) {
    const bool http = response.outcome == HttpResponse::Outcome::kHttpError;
    return {false, OutcomeName(response.outcome),
            std::string(OutcomeName(response.outcome)) + " (" + response.error +
                (http ? ServerReason(response.body) : "") + ")"};
  }
  std::string error;
  if (!store_) store_ = Store::Open(settings_.store_path, &error);
  if (!store_) return {false, "store", "the store cannot be opened: " + error};
  const std::string shown_url = UrlForLogs(settings_.url);
  const std::string source = "fetch " + shown_url;
  const cli::WeatherImportResult r =
      cli::ImportWeatherText(*store_, settings_.plant, response.body, shown_url, source);
  switch (r.status) {
    case cli::WeatherImportResult::Status::kBadInput:
      return {false, "bad answer",
              "the answer is not a usable forecast: " +
                  (r.errors.empty() ? std::string("?") : r.errors.front().ToString())};
    case cli::WeatherImportResult::Status::kStoreFailed:
      store_.reset();  // opened again for the next try
      return {false, "store", "writing weather_forecast failed: " + r.store_error};
    case cli::WeatherImportResult::Status::kOk:
      break;
  }
  for (const std::string& note : r.file.notes) log_(kWarning, "weather: " + note);
  for (const std::string& warning : r.Warnings()) log_(kWarning, "weather: " + warning);
  return {true, "", r.SummaryLine(source)};
}

void WeatherWorker::Report(const Outcome& outcome) {
  if (outcome.ok) {
    if (state_ == State::kFailing) {
      log_(kNotice, "weather: " + UrlForLogs(settings_.url) + " answers again after " +
                        FixedDecimals(WallNowS() - failing_since_s_, 0) + " s of failures; " + outcome.text);
    } else {
      log_(kInfo, "weather: " + outcome.text);
    }
    state_ = State::kOk;
    return;
  }
  if (state_ != State::kFailing || outcome.kind != failure_kind_) {
    log_(kWarning, "weather: fetching " + UrlForLogs(settings_.url) + " failed: " + outcome.text +
                       "; forecasts use the weather_forecast rows they have, else persistence; "
                       "retried with backoff");
  }
  if (state_ != State::kFailing) failing_since_s_ = WallNowS();
  state_ = State::kFailing;
  failure_kind_ = outcome.kind;
}

void WeatherWorker::Loop() {
  Backoff backoff(settings_.first_retry_s,
                  std::clamp(settings_.refresh_s / 4.0, settings_.first_retry_s, 300.0));
  while (!stop_.IsSet()) {
    const Outcome outcome = FetchOnce();
    if (stop_.IsSet()) break;  // an aborted transfer is no failure of the server
    Report(outcome);
    if (outcome.ok) {
      fresh_ = true;
      backoff.Reset();
      stop_.WaitFor(settings_.refresh_s);
    } else {
      stop_.WaitFor(backoff.Next());
    }
  }
}

}  // namespace pvtwin
