#include "core/forecast/forecast_backtest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>

#include "core/common/calendar.h"
#include "core/forecast/forecast.h"
#include "core/forecast/forecast_bands.h"
#include "core/model/thermal_model.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The parameters of the day: identified on the window, or the fixed ones.
bool DayParams(const Series& window, const Plant& plant, const ForecastBacktestOptions& options,
               ParamVector* params, std::string* failure) {
  if (options.fixed_params) {
    *params = options.params;
    return true;
  }
  Drivers drivers;
  if (!PrepareDrivers(window, plant, options.spec, &drivers, failure)) return false;
  const Measurements meas = MakeMeasurements(window, drivers);
  if (meas.rows.size() < static_cast<std::size_t>(std::max(options.ident.min_rows, 0))) {
    *failure =
        "the window has " + std::to_string(meas.rows.size()) +
        " objective rows, fewer than ident.min_rows = " + std::to_string(options.ident.min_rows);
    return false;
  }
  const IdentSummary summary = Identify(drivers, meas, StartParams(plant), options.ident);
  if (!summary.ok) {
    *failure = "identification failed: " + summary.failure_reason;
    return false;
  }
  *params = summary.params;
  return true;
}

// Scores the forecast's rows against the measured rows of its horizon.
void ScoreDay(const Series& data, const BandedForecast& banded, ForecastBacktestDay* day) {
  const Forecast& f = banded.forecast;
  const Channel outputs[] = {Channel::kPElW, Channel::kQThW};
  const std::vector<double>* lo[] = {&banded.bands.p_el_p10, &banded.bands.q_th_p10};
  const std::vector<double>* hi[] = {&banded.bands.p_el_p90, &banded.bands.q_th_p90};
  ForecastScore* score[] = {&day->p_el, &day->q_th};
  const bool has_valid = data.Has(Channel::kValid);
  for (std::size_t h = 0; h < f.rows.size(); ++h) {
    const std::size_t i = data.RowAtOrAfter(f.rows.time_s[h]);
    if (i >= data.size() || data.time_s[i] != f.rows.time_s[h]) continue;
    if (has_valid && data[Channel::kValid][i] == 0.0) continue;
    for (int o = 0; o < 2; ++o) {
      const double meas = data.Has(outputs[o]) ? data[outputs[o]][i] : kNaN;
      const double fc = f.rows[outputs[o]][h], ref = f.reference[outputs[o]][h];
      if (!std::isfinite(meas) || !std::isfinite(fc) || !std::isfinite(ref)) continue;
      ++score[o]->minutes;
      day->sum_abs_err[o] += std::fabs(meas - fc);
      day->sum_abs_err_ref[o] += std::fabs(meas - ref);
      const double l = (*lo[o])[h], u = (*hi[o])[h];
      if (!(u > l)) continue;
      ++score[o]->banded;
      day->covered[o] += meas >= l && meas <= u ? 1 : 0;
    }
  }
}

void Finish(double sum_err, double sum_ref, std::size_t covered, ForecastScore* s) {
  const double n = static_cast<double>(s->minutes);
  s->mae_w = s->minutes ? sum_err / n : kNaN;
  s->mae_ref_w = s->minutes ? sum_ref / n : kNaN;
  s->skill = sum_ref > 0.0 ? 1.0 - sum_err / sum_ref : kNaN;
  s->coverage = s->banded ? static_cast<double>(covered) / static_cast<double>(s->banded) : kNaN;
}

void RunDay(const Series& data, const Series& weather_forecast, const Plant& plant,
            const ForecastBacktestOptions& options, ForecastBacktestDay* day) {
  const std::int64_t issued = day->issued_at_s;
  const std::int64_t horizon_end = issued + std::llround(options.horizon_s);
  const Series window = data.Between(
      issued - static_cast<std::int64_t>(options.window_days) * kSecondsPerDay, issued);
  if (window.size() == 0) {
    day->failure = "no measured rows in the window before the issue";
    return;
  }
  ParamVector params{};
  if (!DayParams(window, plant, options, &params, &day->failure)) return;
  ForecastRequest request;
  request.issued_at_s = issued;
  request.horizon_s = options.horizon_s;
  ForecastWindowStats stats;
  BandedForecast banded;
  if (!ReplayWindow(plant, options.spec, params, window,
                    weather_forecast.Between(window.time_s.front(), issued), request, &stats,
                    &day->failure) ||
      !MakeBandedForecast(plant, options.spec, params, window,
                          weather_forecast.Between(issued, horizon_end), Series{}, request, stats,
                          &banded, &day->failure)) {
    return;
  }
  day->operation =
      stats.operation.chosen == OperationForecast::kLearned ? "learned rule" : "typical day";
  day->weather_forecast_rows = banded.forecast.inputs.weather_forecast;
  ScoreDay(data, banded, day);
  Finish(day->sum_abs_err[0], day->sum_abs_err_ref[0], day->covered[0], &day->p_el);
  Finish(day->sum_abs_err[1], day->sum_abs_err_ref[1], day->covered[1], &day->q_th);
  const std::size_t minutes = std::max(day->p_el.minutes, day->q_th.minutes);
  day->ok = minutes >= static_cast<std::size_t>(kMinScoredMinutes);
  if (!day->ok) {
    day->failure = std::to_string(minutes) + " measured minutes in the horizon, fewer than " +
                   std::to_string(kMinScoredMinutes);
  }
}

}  // namespace

bool RunForecastBacktest(
    const Series& data, const Series& weather_forecast, const Plant& plant,
    const ForecastBacktestOptions& options, ForecastBacktestResult* result, std::string* error,
    const std::function<void(int, int, const ForecastBacktestDay&)>& progress) {
  if (options.window_days < 2 || options.window_days > 365 || !(options.horizon_s >= 60.0) ||
      options.issue_times_s.empty()) {
    *error =
        "forecast backtest: window_days must be 2 … 365, the horizon at least 60 s, and "
        "there must be an issue time";
    return false;
  }
  *result = ForecastBacktestResult{};
  double sums[2][2] = {{0, 0}, {0, 0}};
  std::size_t covered[2] = {0, 0};
  const int total = static_cast<int>(options.issue_times_s.size());
  for (std::int64_t issued : options.issue_times_s) {
    ForecastBacktestDay day;
    day.issued_at_s = issued;
    RunDay(data, weather_forecast, plant, options, &day);
    if (day.ok) {
      ++result->days_ok;
      ForecastScore* totals[] = {&result->total_p_el, &result->total_q_th};
      const ForecastScore* scores[] = {&day.p_el, &day.q_th};
      for (int o = 0; o < 2; ++o) {
        sums[o][0] += day.sum_abs_err[o];
        sums[o][1] += day.sum_abs_err_ref[o];
        covered[o] += day.covered[o];
        totals[o]->minutes += scores[o]->minutes;
        totals[o]->banded += scores[o]->banded;
      }
    }
    result->days.push_back(day);
    if (progress) progress(static_cast<int>(result->days.size()), total, result->days.back());
  }
  Finish(sums[0][0], sums[0][1], covered[0], &result->total_p_el);
  Finish(sums[1][0], sums[1][1], covered[1], &result->total_q_th);
  return true;
}

std::string FormatForecastBacktest(const ForecastBacktestResult& result) {
  std::string out =
      "Day-ahead forecasts scored against the measurements (skill = 1 - MAE / MAE of smart "
      "persistence;\ncoverage = share of measured minutes inside the 10-90 % band)\n\n"
      "issued (UTC)          operation     wf rows  minutes  MAE P_el  skill  cover  "
      "MAE Q_u  skill  cover\n";
  char buf[512];
  const auto row = [&](const char* label, const char* operation, std::size_t wf,
                       const ForecastScore& p, const ForecastScore& q) {
    std::snprintf(buf, sizeof buf,
                  "%-21s %-13s %7zu %8zu %7.1f W %6.3f %6.3f %6.1f W %6.3f %6.3f\n", label,
                  operation, wf, std::max(p.minutes, q.minutes), p.mae_w, p.skill, p.coverage,
                  q.mae_w, q.skill, q.coverage);
    out += buf;
  };
  for (const ForecastBacktestDay& d : result.days) {
    char label[32];
    const std::time_t t = static_cast<std::time_t>(d.issued_at_s);
    std::tm tm{};
    gmtime_r(&t, &tm);
    std::strftime(label, sizeof label, "%Y-%m-%dT%H:%MZ", &tm);
    if (!d.ok) {
      out += std::string(label) + "  not scored: " + d.failure + "\n";
      continue;
    }
    row(label, d.operation.c_str(), d.weather_forecast_rows, d.p_el, d.q_th);
  }
  char all[32];
  std::snprintf(all, sizeof all, "all %d days", result.days_ok);
  std::size_t wf_rows = 0;
  for (const ForecastBacktestDay& d : result.days) wf_rows += d.ok ? d.weather_forecast_rows : 0;
  row(all, "", wf_rows, result.total_p_el, result.total_q_th);
  return out;
}

}  // namespace pvtwin
