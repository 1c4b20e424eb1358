// Uncertainty bands of a forecast (issue 15, issue 53; doc/contracts.md
// `forecast` columns p_el_w_p10, p_el_w_p50, p_el_w_p90, q_th_w_p10, …):
// split-conformal bands from the same model's held-out day-ahead errors over
// the recent window, by lead time and regime and by weather source.
//
// Replay: for each day D of the history with a full day of history before
// it, a forecast is issued at D + the issue's own time of day (so that the
// replayed errors have the lead times of the forecast they band) from the
// history before it (MakeForecast, as the daemon does it) and scored against
// the measured rows of the 24 h after: error = measured − forecast, per
// output, on every minute with a valid measurement. Two replays per day,
// kept apart because a weather forecast errs differently from persistence:
// without the weather forecast table (source `persistence`), and with the
// rows the table holds for the day (source `weather_forecast`, as earlier
// imports and fetches left them; a minute counts there only when all of its
// irradiance came from the table). The operation is forecast as in the
// daemon (plan, else the typical day).
//
// Regime of a row, from the forecast's own inputs (known at issue time):
//   irradiance  in-plane (else horizontal) < 20, 20–200, 200–600, ≥ 600 W/m²
//   sky         clear when the irradiance is ≥ 0.6 of the clear sky
//               (core/forecast/weather_resample.h), else cloudy
//   time        local solar hour < 10, 10–14, ≥ 14
//   pump        flow > 0 or not
//   lead        time since the issue < 1 h, 1–6 h, ≥ 6 h
// A row takes the quantiles of the finest regime that holds at least
// min_samples errors from min_days days, coarsening in the order: all five
// → irradiance, sky, pump, lead → irradiance, pump → irradiance → every row
// of the source (which needs min_samples only).
//
// Band of a row with forecast f and regime quantiles q10 ≤ q50 ≤ q90 of the
// errors: p10 = f + λ_lo·min(0, q10), p90 = f + λ_hi·max(0, q90), so the
// forecast lies inside its band by construction; p50 = f + q50 (the median,
// where the forecast f is the model's run on the expected inputs), within
// the band. λ_lo and λ_hi (per source and output) are the split-conformal
// calibration on held-out days: each replayed day's errors are scored
// against the quantiles of the other days (leave one day out; a day's
// minutes err together, so days are the units), s = e / max(0, q90) above
// and e / min(0, q10) below, and λ_hi is the upper_quantile of the scores
// above (λ_lo the 1 − lower_quantile of those below): on days the quantiles
// were not taken from, 10 % of the minutes lie above p90 and 10 % below p10.
// P_el's edges are not below 0. Minutes where the model's output is exact
// (P_el at night) get a band of zero width.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/forecast/forecast.h"
#include "core/model/variant.h"

namespace pvtwin {

enum class WeatherSource : std::uint8_t { kPersistence = 0, kWeatherForecast = 1 };
constexpr std::size_t kWeatherSources = 2;
const char* WeatherSourceName(WeatherSource source);  // "persistence", "weather_forecast"

struct BandOptions {
  double lower_quantile = 0.1;   // p10
  double upper_quantile = 0.9;   // p90
  std::size_t min_samples = 30;  // errors a regime needs to give its own quantiles
  // … from at least this many days: a day's errors move together (a cloud
  // front misplaced), so a regime seen on one or two days would give bands
  // as narrow as its luck.
  std::size_t min_days = 5;
};

// A forecast row's regime (see the header), one small code per feature.
struct ForecastRegime {
  std::uint8_t irradiance = 0;  // 0 … 3
  std::uint8_t sky = 0;         // 0 clear, 1 cloudy
  std::uint8_t time = 0;        // 0 … 2
  std::uint8_t pump = 0;        // 0 off, 1 on
  std::uint8_t lead = 0;        // 0 < 1 h, 1 1–6 h, 2 ≥ 6 h after the first row
};

// The regimes of a forecast's horizon rows from its inputs_used (whose first
// row is the issue).
std::vector<ForecastRegime> RegimesOf(const Plant& plant, const Series& inputs);

struct ForecastError {
  ForecastRegime regime;
  std::int64_t time_s = 0;
  std::int64_t issued_at_s = 0;  // of the replayed forecast: the unit of the calibration
  double p_el_w = 0.0;           // measured − forecast; NaN where one was missing
  double q_th_w = 0.0;
};

struct ForecastErrors {
  std::array<std::vector<ForecastError>, kWeatherSources> by_source;
  std::array<std::size_t, kWeatherSources> days{};  // replayed days per source
};

// Replays the day-ahead forecasts over `history` (measured rows at
// request.step_s: 1-min rows, or interval rows whose errors are those of
// interval means; typically the calibration window) with `params`; past_weather_forecast:
// the weather_forecast rows over the same span (may be empty). request
// gives step and warm-up (issued_at and horizon are set per day). Returns
// false with *error only when the model cannot run on the history.
bool ReplayForecastErrors(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                          const Series& history, const Series& past_weather_forecast,
                          const ForecastRequest& request, ForecastErrors* out, std::string* error);

struct ForecastBands {
  // Per horizon row, NaN: none. p10 ≤ forecast ≤ p90 and p10 ≤ p50 ≤ p90.
  std::vector<double> p_el_p10, p_el_p50, p_el_p90, q_th_p10, q_th_p50, q_th_p90;
  std::array<std::size_t, kWeatherSources> rows_from{};  // rows banded from each source
  // For the forecast row's `inputs`: e.g. "bands: persistence errors of 13
  // days (1440 rows, conformal scale P_el 1.21/1.35, Q_u 1.10/1.42);
  // weather_forecast errors of 4 days (0 rows)".
  std::string note;
};

// The bands of `forecast` (its rows, inputs_used and weather_from_forecast)
// from the replayed errors. A row whose weather came from the forecast
// table takes that source's errors; when that source has fewer than
// min_samples errors in all, persistence's (the larger, as a rule), and the
// note says so.
ForecastBands BandsFor(const Plant& plant, const Forecast& forecast, const ForecastErrors& errors,
                       const BandOptions& options = {});

// Which operation forecast (forecast.h) predicted the heat of the
// history's replayed days better, with persisted weather and no plan: the
// typical day or the learned rule (operation_forecast.h); ties keep the
// typical day.
struct OperationChoice {
  OperationForecast chosen = OperationForecast::kTypicalDay;
  std::size_t days = 0;
  double mae_q_th_typical_w = 0.0, mae_q_th_learned_w = 0.0;
  std::string Describe() const;  // for the forecast's `inputs` and the logs
};
bool ChooseOperation(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                     const Series& history, const ForecastRequest& request, OperationChoice* out,
                     std::string* error);

// What a forecast learns from its window before it is issued: the
// operation forecast that predicted the replayed days better, and the
// replayed errors (with that operation) its bands come from. Depends only on
// the window and the parameters: a daemon computes it once a day and per
// calibration.
struct ForecastWindowStats {
  OperationChoice operation;
  ForecastErrors errors;
};
bool ReplayWindow(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                  const Series& history, const Series& past_weather_forecast,
                  const ForecastRequest& request, ForecastWindowStats* out, std::string* error);

// A forecast as the daemon issues it: MakeForecast with the window's
// operation choice, then its bands.
struct BandedForecast {
  Forecast forecast;
  ForecastBands bands;
  // The forecast rows' `inputs`: Describe(), the operation choice, the bands' note.
  std::string Inputs() const;
};
bool MakeBandedForecast(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                        const Series& history, const Series& weather_forecast,
                        const Series& operation_plan, ForecastRequest request,
                        const ForecastWindowStats& stats, BandedForecast* out, std::string* error);

// The sample quantile q (0 … 1) of values, linear between order statistics
// (Hyndman & Fan type 7); NaN for no values. Reorders values.
double SampleQuantile(std::vector<double>* values, double q);

}  // namespace pvtwin
