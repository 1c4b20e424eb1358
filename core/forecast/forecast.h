// 24 h forecasts of a calibrated model (issue 5, doc/contracts.md table `forecast`).
//
// A forecast runs the calibrated variant over the horizon on the best inputs
// available for each row, after a warm-up on measured data so that the
// thermal states start where the plant is:
//
//   rows        [issued_at − warmup_s, issued_at)   measured 1-min history
//               [issued_at, issued_at + horizon_s)  forecast inputs, per channel:
//   weather     1. the weather forecast (table weather_forecast), where it has
//                  the channel at that minute (linear interpolation across gaps
//                  up to max_interp_gap_s);
//               2. persistence: the measured value 24 h earlier (48 h, … up to
//                  the window), the usual baseline of day-ahead PV forecasting;
//                  the irradiance channels as smart persistence (below): the
//                  clear-sky index of the hour around that minute 24 h (48 h)
//                  earlier times the forecast minute's clear sky. Yesterday's
//                  clouds passing minute by minute would be counted twice
//                  against any day but yesterday (once where they were, once
//                  where they are not); the hour's index keeps the day's
//                  energy and weather class and costs 2–8 % less MAE of P_el
//                  (doc/forecast.md);
//   operation   1. the operation plan (table operation_plan: t_in_c, flow_kg_s);
//   (t_in_c,    2. the typical day of the window: the median, over the window's
//    flow_kg_s)    days, of the value at the same minute of the (UTC) day; or,
//                  with request.operation = kLearned, the controller learned
//                  from the window (core/forecast/operation_forecast.h).
//
// Beside it, the same model runs a reference forecast, the baseline that
// forecast_skill scores against (issue 15): smart persistence of the
// weather — each irradiance channel's clear-sky index of 24 h earlier (over
// the hour around that minute) times the clear sky of the forecast minute
// (core/forecast/weather_resample.h), the other weather channels persisted —
// with the typical day's operation. A forecast that only persists the
// weather has the reference's weather and scores about zero for P_el; its
// operation forecast, a weather forecast or an operation plan worth having
// score above.
//
// Timestamp convention as everywhere: a row's time is the start of its
// interval; outputs are interval means (core/model/thermal_model.h). Forecast rows
// are whole minutes when issued_at is.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/model/variant.h"

namespace pvtwin {

// The operation over the horizon where no plan covers it.
enum class OperationForecast {
  kTypicalDay,  // the window's median day
  kLearned,     // the controller learned from the window (operation_forecast.h)
};

// A day of forecast scores (forecast_skill's skill and coverage, `backtest
// --forecast`) needs this many scored minutes, a quarter of a day: fewer
// would score the time of day rather than the forecast.
inline constexpr int kMinScoredMinutes = 360;

struct ForecastRequest {
  std::int64_t issued_at_s = 0;      // first forecast row (unix s UTC)
  double horizon_s = 86400.0;        // forecast length
  double step_s = 60.0;              // row spacing of the forecast and of the inputs
  double warmup_s = 86400.0;         // measured history simulated before the horizon
  double max_interp_gap_s = 3600.0;  // longest gap in a forecast input bridged linearly
  bool with_reference = true;        // also run the reference forecast (Forecast::reference)
  OperationForecast operation = OperationForecast::kTypicalDay;
  // Where the typical day and the learned rule are learned from (null: the
  // history). A replay of a past day passes the window without that day, so
  // that its operation forecast knows as many days as the real one.
  const Series* operation_history = nullptr;
};

// Where one input channel's horizon values came from, counted in rows.
struct ChannelInputUse {
  Channel channel = Channel::kTAmbC;
  std::size_t forecast = 0;  // weather_forecast (or, for operation, operation_plan)
  std::size_t fallback = 0;  // persistence (weather) or the typical day (operation)
  std::size_t missing = 0;
  bool operation = false;  // t_in_c, flow_kg_s
  bool learned = false;    // an operation channel's fallback was the learned rule
};

// Where each forecast row's inputs came from, counted over the horizon rows.
struct ForecastInputUse {
  std::size_t rows = 0;
  std::size_t weather_forecast = 0;     // rows whose weather came (fully) from the forecast table
  std::size_t weather_persistence = 0;  // rows with at least one persisted weather value
  std::size_t weather_missing = 0;      // rows without a value for a needed weather channel
  std::size_t operation_plan = 0;       // rows whose t_in_c and flow came from the plan
  std::size_t operation_typical = 0;    // rows with a typical-day operation value
  std::size_t operation_learned = 0;    // rows with an operation value of the learned rule
  std::string pump_rule;                // the learned rule (PumpRule::Describe), if used
  // Per input channel the model reads, in channel order.
  std::vector<ChannelInputUse> channels;
  // The weather_forecast rows' sources (Store::ReadWeatherSources), named
  // where a channel used the table; set by the caller.
  std::vector<std::string> weather_sources;
  // One line for the forecast row's `inputs` column, e.g.
  // "weather: forecast 1440/1440, persistence 0/1440, missing 0/1440; operation: plan 0/1440,
  // typical day 1440/1440; channels: g_poa_w_m2=weather_forecast 1440, t_sky_c=persistence
  // 1440, t_in_c=typical_day 1440, ...; weather_forecast source: fetch https://... (Open-Meteo
  // JSON, hourly)". When a source carries kAboveClearSkyMark (rows of an
  // interval whose irradiance was above its clear sky, stored clipped; core/
  // forecast/weather_resample.h) the line ends with "; " +
  // kAboveClearSkyInputs ("weather_warning=irradiance_above_clear_sky").
  std::string Describe() const;
};

struct Forecast {
  // time_s and the output channels p_el_w, q_th_w, t_pv_c, t_out_c (NaN
  // where an input was missing); the horizon rows only.
  Series rows;
  // The reference forecast (smart persistence, typical-day operation):
  // p_el_w and q_th_w on the same rows.
  Series reference;
  // Per horizon row: 1 when all its irradiance channels came from the
  // weather forecast table (the irradiance carries most of a forecast's
  // error), 0 when one was persisted or a weather channel is missing. The
  // uncertainty bands take the errors of that source (forecast_bands.h).
  std::vector<std::uint8_t> weather_from_forecast;
  ForecastInputUse inputs;
  // The model inputs of the horizon rows as used (weather and operation
  // channels), for inspection.
  Series inputs_used;
};

// history: measured rows up to issued_at at request.step_s (1-min rows, or
// a coarser logger's interval rows with issued_at on their grid; the
// calibration window or at least the last day plus the warm-up); a warm-up
// row missing in it holds the last value up to 10 min or one step, whichever
// is longer. A weather_forecast finer than the step is averaged over each
// row's interval. weather_forecast and operation_plan:
// rows covering (part of) the horizon, possibly empty. Returns false with
// *error when the history is too short to persist a day or warm up.
bool MakeForecast(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                  const Series& history, const Series& weather_forecast,
                  const Series& operation_plan, const ForecastRequest& request, Forecast* out,
                  std::string* error);

}  // namespace pvtwin
