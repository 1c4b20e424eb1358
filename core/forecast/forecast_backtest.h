// Backtest of the forecast itself (issue 15, `pvtwin backtest --forecast`):
// the daily forecast run as the daemon runs it, scored as forecast_skill
// scores it, over test days of recorded data.
//
// For each issue time I (one a day, at a set local time):
//   1. window   the measured rows of [I − window_days, I);
//   2. fit      the variant identified on the window (as the nightly
//               calibration), or fixed parameters when given;
//   3. window   ReplayWindow (forecast_bands.h): the operation forecast that
//      stats   predicted the window's days better, and the replayed errors
//               of the bands (with the weather forecast's rows of those
//               days, when a weather forecast is given);
//   4. issue    MakeBandedForecast over [I, I + horizon) with the weather
//               forecast's rows of the horizon (else persistence);
//   5. score    against the measured rows of the horizon with valid != 0:
//               MAE per output, the reference's MAE on the same minutes and
//               skill = 1 − MAE / MAE_ref, the band's coverage over the
//               minutes whose band has a width.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/fit/identification.h"
#include "core/model/variant.h"

namespace pvtwin {

struct ForecastBacktestOptions {
  ModelSpec spec;
  int window_days = 14;                     // [2, 365]
  double horizon_s = 86400.0;               // forecast length
  std::vector<std::int64_t> issue_times_s;  // whole minutes, increasing
  IdentOptions ident;                       // the daily identification
  bool fixed_params = false;                // use `params` instead of identifying
  ParamVector params{};
};

struct ForecastScore {
  std::size_t minutes = 0;  // scored minutes (measured and forecast)
  double mae_w = 0.0, mae_ref_w = 0.0;
  double skill = 0.0;      // 1 − mae / mae_ref; NaN when mae_ref is 0
  std::size_t banded = 0;  // minutes with a band of width
  double coverage = 0.0;   // share of banded minutes inside the band; NaN if none
};

struct ForecastBacktestDay {
  std::int64_t issued_at_s = 0;
  bool ok = false;
  std::string failure;  // when !ok
  ForecastScore p_el, q_th;
  std::string operation;                  // "typical day" or "learned rule"
  std::size_t weather_forecast_rows = 0;  // horizon rows whose irradiance came from the file
  double sum_abs_err[2] = {0, 0}, sum_abs_err_ref[2] = {0, 0};  // for the totals
  std::size_t covered[2] = {0, 0};
};

struct ForecastBacktestResult {
  std::vector<ForecastBacktestDay> days;
  ForecastScore total_p_el, total_q_th;  // over all scored minutes of all days
  int days_ok = 0;
};

// data: measured 1-min rows (valid, p_el_w, q_th_w and the model's inputs);
// weather_forecast: 1-min rows of a weather forecast (may be empty). False
// with *error only on a caller error (options out of range); a day that
// cannot be forecast is a day with ok = false and its reason.
bool RunForecastBacktest(
    const Series& data, const Series& weather_forecast, const Plant& plant,
    const ForecastBacktestOptions& options, ForecastBacktestResult* result, std::string* error,
    const std::function<void(int, int, const ForecastBacktestDay&)>& progress = {});

// The per-day table and the totals (W), for people.
std::string FormatForecastBacktest(const ForecastBacktestResult& result);

}  // namespace pvtwin
