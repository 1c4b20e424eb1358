// Day one (issue 53): the forecast of a plant that has no calibration yet,
// from the start values (paper Table 3 through StartParams; the plant
// config's area and PV coefficients), with a band as wide as what is not
// yet known. The daemon issues it until two days of history allow the first
// calibration; forecast rows then carry basis = 'start_values'
// (doc/forecast.md, doc/contracts.md).
//
// Inputs of a horizon row at time t (there is no day to persist yet):
//   irradiance  the weather_forecast row at t where the table has the
//               channel; else k · the clear sky of Ineichen & Perez (T_L = 3,
//               core/forecast/weather_resample.h MakeClearSkyGrid) of the
//               channel's kind (in-plane or horizontal), k the clear-sky
//               index of the history's daylight minutes (clear-sky in-plane
//               ≥ kMinDaylightClearWM2) over its last 24 h, clamped to
//               [index_low, index_high]; without such a minute, the middle
//               of that range. DHI = GHI · (1 − k·(1 − DHI_clear/GHI_clear)):
//               the clear sky's diffuse share at k = 1, all diffuse at k = 0.
//   other       the weather_forecast row where the table has the channel,
//   weather     else the mean of the history's last hour, held.
//   operation   the operation plan (held up to max_interp_gap_s); else the
//               flow of the pump rule learned from the history
//               (operation_forecast.h) when it holds a day; else, when the
//               pump ran, its median measured flow while the sun is up (clear
//               sky in the plane ≥ kMinDaylightClearWM2) and 0 otherwise;
//               else, and for t_in_c, the mean of the history's last hour.
// The history's rows of the warm-up span (up to request.warmup_s before the
// issue) are simulated first, holding a channel's last value across a
// missing minute for up to kWarmupHoldRows rows; without history the model
// starts at the first horizon row.
//
// Band (no held-out residuals exist yet): the envelope of 27 runs, every
// combination of
//   irradiance  the point's (table or k), index_low · clear sky (overcast),
//               index_high · clear sky (clear);
//   operation   the point's flow, the pump off, the pump on at its median
//               measured flow on every row (left out when it never ran);
//   parameters  the start values; the yields' low end of Table 3 (η_PVref
//               and F_th at their lower bounds, r0_fluid at its upper: no
//               heat reaches the fluid); their high end (the reverse).
// p10 = the runs' minimum, p90 = their maximum, p50 = the point (the run on
// the point's inputs with the start values), so p10 ≤ p50 ≤ p90 holds by
// construction. It is not a calibrated 10–90 % band: it spans the weather
// from overcast to clear, the pump off and on, and the yields over Table
// 3's range, so it is wider.
// The reference forecast (smart persistence) needs a day of history: NaN.
//
// Timestamp convention as in forecast.h: a row's time is the start of its
// interval, outputs are interval means.
#pragma once

#include <string>

#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/forecast/forecast.h"
#include "core/forecast/forecast_bands.h"
#include "core/model/variant.h"

namespace pvtwin {

// Daylight minutes for the clear-sky index of the history: the clear sky in
// the plane at least this (dawn and dusk minutes give erratic ratios).
inline constexpr double kMinDaylightClearWM2 = 50.0;
// A missing warm-up minute (the one not yet aggregated) holds the previous
// row's value this many rows.
inline constexpr std::size_t kWarmupHoldRows = 10;

struct StartValueOptions {
  double index_low = 0.1;  // clear-sky index of an overcast sky (band's low edge)
  // of a clear sky (band's high edge): the cleanest air (Linke turbidity 2)
  // gives about 1.08 times the T_L = 3 clear sky at air mass 2 (Ineichen &
  // Perez, core/forecast/weather_resample.h), and a clear day's measured
  // minutes exceed T_L = 3 by a few per cent.
  double index_high = 1.1;
  double linke_turbidity = 3.0;  // of the clear sky (a typical rural value)
  double hold_s = 3600.0;        // the history's last span whose mean is held
};

struct StartValueForecast {
  // rows (p_el_w, q_th_w, t_pv_c, t_out_c), reference (NaN), inputs_used,
  // weather_from_forecast; bands p10/p50/p90 of both outputs.
  BandedForecast banded;
  double clear_sky_index = 0.0;      // k of the point forecast
  std::size_t daylight_minutes = 0;  // history minutes k came from (0: the default)
  // For the forecast rows' `inputs`: "start values (Table 3); irradiance:
  // weather_forecast 0/1440, clear sky × 0.62 (from 45 daylight minutes)
  // 1440/1440; …; bands: start-value envelope …".
  std::string inputs;
};

// False with *error when the model cannot run (a weather channel the
// variant needs has neither a forecast nor a measured value yet) or the
// request is out of range.
bool MakeStartValueForecast(const Plant& plant, const ModelSpec& spec, const Series& history,
                            const Series& weather_forecast, const Series& operation_plan,
                            const ForecastRequest& request, const StartValueOptions& options,
                            StartValueForecast* out, std::string* error);

}  // namespace pvtwin
