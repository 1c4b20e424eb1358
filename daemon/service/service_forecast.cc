// The forecast job of the Service (service_internal.h): a banded forecast
// issued every [forecast] refresh_min and after each accepted calibration,
// with what the window teaches replayed once per day and calibration. Its
// history is the window's 1-min rows, else its interval rows at their own
// step (window_data.h, as the calibration reads it): the forecast then runs
// at that step on their grid.
#include <cmath>
#include <initializer_list>
#include <utility>

#include "core/forecast/forecast.h"
#include "core/forecast/forecast_bands.h"
#include "core/forecast/start_value_forecast.h"
#include "daemon/service/service_internal.h"
#include "io/platform/log.h"
#include "io/platform/time_format.h"

namespace pvtwin::service_detail {

namespace {

// "weather forecast 1200, persisted 240; operation typical 1440": where
// the rows' inputs came from, the sources with rows only. The whole account
// (channels, weather sources, the operation choice, the bands) is the
// forecast rows' `inputs` column.
std::string InputsInBrief(const ForecastInputUse& use) {
  const auto list = [](std::initializer_list<std::pair<const char*, std::size_t>> counts) {
    std::string text;
    for (const auto& count : counts) {
      if (count.second == 0) continue;
      text += (text.empty() ? " " : ", ") + std::string(count.first) + " " +
              std::to_string(count.second);
    }
    return text.empty() ? std::string(" none") : text;
  };
  return "weather" +
         list({{"forecast", use.weather_forecast},
               {"persisted", use.weather_persistence},
               {"missing", use.weather_missing}}) +
         "; operation" +
         list({{"plan", use.operation_plan},
               {"typical", use.operation_typical},
               {"learned", use.operation_learned}});
}

// The request of an issue now on the history's grid: whole minutes for
// 1-min rows; interval rows (window_data.h) at their own step and phase (a
// 10-min logger's rows at :05, :15, … give issues at :05, :15, …), so that
// every forecast row, its persisted inputs and its replayed errors fall on
// measured rows. The horizon is the configured one.
ForecastRequest RequestAt(double now_s, double horizon_h, const cli::WindowData& history) {
  ForecastRequest request;
  const std::int64_t minute = static_cast<std::int64_t>(std::floor(now_s / 60.0)) * 60;
  request.issued_at_s = minute;
  request.horizon_s = horizon_h * 3600.0;
  if (history.source != cli::WindowSource::kIntervals) return request;
  const std::int64_t step = std::llround(history.rows.step_s);
  if (step <= 60) return request;
  const std::int64_t phase = ((history.rows.time_s.back() % step) + step) % step;
  request.step_s = static_cast<double>(step);
  request.issued_at_s = minute - (((minute - phase) % step) + step) % step;
  return request;
}

// The forecast's `inputs` part naming its history (doc/contracts.md).
std::string HistoryPart(const cli::WindowData& history) {
  if (history.source == cli::WindowSource::kNone) return "history: none";
  return "history: " + history.Describe() +
         (history.source == cli::WindowSource::kMinutes ? " of measurement_1min" : "");
}

}  // namespace

bool Service::ReadForecastInputs(double now_s, std::int64_t history_s, ForecastRequest* request,
                                 cli::WindowData* history, Series* weather, Series* plan) {
  const std::int64_t minute = static_cast<std::int64_t>(std::floor(now_s / 60.0)) * 60;
  std::string error;
  if (!cli::ReadWindowData(*store_, minute - history_s, minute, history, &error)) {
    LogToStderr(kErr, "forecast inputs could not be read: " + error);
    return false;
  }
  *request = RequestAt(now_s, config_.forecast.horizon_h, *history);
  // An interval row starting at the issue (set back onto the rows' grid)
  // is the forecast's first row, not its history.
  Series& rows = history->rows;
  rows = rows.Slice(0, rows.RowAtOrAfter(request->issued_at_s));
  const std::int64_t horizon_end =
      request->issued_at_s + static_cast<std::int64_t>(request->horizon_s);
  Store::TextCells weather_text, plan_text;
  if (!store_->ReadWeatherForecast(request->issued_at_s, horizon_end, weather, &error,
                                   &weather_text) ||
      !store_->ReadOperationPlan(request->issued_at_s, horizon_end, plan, &error, &plan_text)) {
    LogToStderr(kErr, "forecast inputs could not be read: " + error);
    return false;
  }
  // Text where a number belongs (an `sqlite3 .import` of empty cells): read
  // as missing, said once for as long as it stays the same.
  const std::string text_warning = weather_text.Warning("weather_forecast") +
                                   (weather_text.Total() && plan_text.Total() ? "; " : "") +
                                   plan_text.Warning("operation_plan");
  if (text_warning != text_cells_warned_ && !text_warning.empty()) {
    LogToStderr(kWarning, "forecast inputs: " + text_warning);
  }
  text_cells_warned_ = text_warning;
  return true;
}

void Service::IssueForecast() {
  if (!have_params_) {
    IssueStartValueForecast();
    return;
  }
  const double now = Now();
  next_forecast_s_ = now + config_.forecast.refresh_min * 60.0;
  ForecastRequest request;
  cli::WindowData measured;
  Series weather, plan;
  if (!ReadForecastInputs(now, config_.calibration.window_days * kDayS, &request, &measured,
                          &weather, &plan)) {
    return;
  }
  const Series& history = measured.rows;
  UpdateForecastStats(history, request);
  BandedForecast banded;
  std::string error;
  if (!MakeBandedForecast(config_.plant, spec_, params_, history, weather, plan, request,
                          forecast_stats_, &banded, &error)) {
    LogToStderr(kWarning, "no forecast issued: " + error);
    return;
  }
  Forecast& forecast = banded.forecast;
  const std::int64_t horizon_end =
      request.issued_at_s + static_cast<std::int64_t>(request.horizon_s);
  if (weather.size() > 0 && !store_->ReadWeatherSources(request.issued_at_s, horizon_end,
                                                        &forecast.inputs.weather_sources, &error)) {
    LogToStderr(kWarning, "the weather_forecast sources could not be read: " + error);
  }
  WriteForecast(request, ForecastBasis::kCalibrated, banded,
                banded.Inputs() + "; " + HistoryPart(measured),
                InputsInBrief(forecast.inputs) + "; " + HistoryPart(measured));
}

// No calibration yet: the start values, retried soon while the model cannot
// run (no measured minute yet); deferred while a first fit runs, whose
// parameters forecast as soon as they are accepted.
void Service::IssueStartValueForecast() {
  if (child_.running()) return;
  const double now = Now();
  ForecastRequest request;
  cli::WindowData measured;
  Series weather, plan;
  if (!ReadForecastInputs(now, kDayS, &request, &measured, &weather, &plan)) {
    next_forecast_s_ = now + kStartValueRetryS;
    return;
  }
  StartValueForecast start;
  std::string error;
  if (!MakeStartValueForecast(config_.plant, spec_, measured.rows, weather, plan, request,
                              StartValueOptions{}, &start, &error)) {
    next_forecast_s_ = now + kStartValueRetryS;
    if (error != start_value_error_) {
      LogToStderr(kInfo, "no forecast from the start values yet (retried every " +
                             Format("%.0f", kStartValueRetryS / 60.0) + " min): " + error);
    }
    start_value_error_ = error;
    return;
  }
  start_value_error_.clear();
  next_forecast_s_ = now + config_.forecast.refresh_min * 60.0;
  WriteForecast(request, ForecastBasis::kStartValues, start.banded,
                start.inputs + "; " + HistoryPart(measured),
                "start values, clear-sky index " + Format("%.2f", start.clear_sky_index) + "; " +
                    HistoryPart(measured));
}

bool Service::WriteForecast(const ForecastRequest& request, ForecastBasis basis,
                            const BandedForecast& banded, const std::string& inputs,
                            const std::string& brief) {
  const Forecast& forecast = banded.forecast;
  std::vector<Store::ForecastRow> rows(forecast.rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    Store::ForecastRow& r = rows[i];
    r.ts = forecast.rows.time_s[i];
    r.p_el_w = forecast.rows[Channel::kPElW][i];
    r.q_th_w = forecast.rows[Channel::kQThW][i];
    r.t_pv_c = forecast.rows[Channel::kTPvC][i];
    r.t_out_c = forecast.rows[Channel::kTOutC][i];
    r.p_el_w_p10 = banded.bands.p_el_p10[i];
    r.p_el_w_p90 = banded.bands.p_el_p90[i];
    r.q_th_w_p10 = banded.bands.q_th_p10[i];
    r.q_th_w_p90 = banded.bands.q_th_p90[i];
    r.p_el_w_p50 = banded.bands.p_el_p50[i];
    r.q_th_w_p50 = banded.bands.q_th_p50[i];
    r.p_el_w_ref = forecast.reference[Channel::kPElW][i];
    r.q_th_w_ref = forecast.reference[Channel::kQThW][i];
  }
  const bool calibrated = basis == ForecastBasis::kCalibrated;
  std::string error;
  if (!store_->InsertForecast(request.issued_at_s, calibrated ? params_id_ : 0, basis, inputs, rows,
                              &error)) {
    LogToStderr(kErr, "writing the forecast failed: " + error);
    return false;
  }
  ++status_.forecasts;
  status_.last_forecast_rows = rows.size();
  last_forecast_issued_at_ = request.issued_at_s;
  LogToStderr(kInfo, "forecast issued at " + FormatIsoUtc(request.issued_at_s) + ": " +
                         std::to_string(rows.size()) + " rows, " +
                         (calibrated ? "calibration " + std::to_string(params_id_)
                                     : std::string("start values")) +
                         "; " + brief);
  return true;
}

void Service::UpdateForecastStats(const Series& history, const ForecastRequest& request) {
  const std::int64_t day = request.issued_at_s - ((request.issued_at_s % kDayS) + kDayS) % kDayS;
  if (request.issued_at_s == forecast_stats_issued_at_ && params_id_ == forecast_stats_params_id_) {
    return;
  }
  forecast_stats_issued_at_ = request.issued_at_s;
  forecast_stats_params_id_ = params_id_;
  Series past_weather;
  std::string error;
  if (!store_->ReadWeatherForecast(history.size() ? history.time_s.front() : day, day + kDayS,
                                   &past_weather, &error) ||
      !ReplayWindow(config_.plant, spec_, params_, history, past_weather, request, &forecast_stats_,
                    &error)) {
    // Forecasts go on without bands and with the typical day until the
    // next day or calibration tries again.
    forecast_stats_ = ForecastWindowStats{};
    LogToStderr(kWarning,
                "the forecast's window could not be replayed (forecasts without bands until the "
                "next day or calibration): " +
                    error);
    return;
  }
  LogToStderr(kInfo, forecast_stats_.operation.Describe());
}

}  // namespace pvtwin::service_detail
