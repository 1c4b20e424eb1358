// What the twin watches day by day, on the plant's own 1-min measurements:
// the performance index of a day (measured over expected energy), a drift
// of identified parameters across calibrations, and sensor faults. Pure
// computation; the daemon stores the results (performance_daily,
// monitor_event, qc_event in io/store/store.h).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/common/units.h"
#include "core/model/variant.h"

namespace pvtwin {

// ---------------------------------------------------------------------------
// Performance index of a day.
//
// The accepted model, run on the day's measured inputs (weather, inlet
// temperature, flow), gives the energies the plant should have delivered;
// pi = measured / expected over the minutes where both are known (valid
// rows with model inputs and measured outputs, as the calibration's
// objective). The band [pi_low, pi_high] is the 10–90 % band of the daily
// error of the model (index_band.h), set apart from the day's own score.

struct PerformanceOptions {
  // A day is scored when it has this many minutes and its expected energy
  // reaches the minimum per m² of collector; otherwise its row is written
  // with the energies and pi left NaN (marked, not scored).
  int min_valid_minutes = 120;
  double min_el_wh_m2 = 10.0;  // about an hour of weak sun on a 15 % module
  double min_th_wh_m2 = 50.0;
};

struct DayPerformance {
  std::int64_t day_start_s = 0;  // 00:00 UTC, as forecast_skill's day
  int valid_minutes = 0;
  double e_el_meas_wh = 0.0, e_el_model_wh = 0.0;
  double e_th_meas_wh = 0.0, e_th_model_wh = 0.0;
  // NaN when the day is not scored for that output; the band NaN until
  // SetIndexBands (index_band.h) gives it one.
  double pi_el = 0.0, pi_el_low = 0.0, pi_el_high = 0.0;
  double pi_th = 0.0, pi_th_low = 0.0, pi_th_high = 0.0;
  bool scored_el = false, scored_th = false;
};

// Scores the day [day_start_s, day_start_s + 86400) of 1-min rows (rows
// outside the day are ignored): energies and pi, the band NaN. False and
// *error when the model cannot run on the rows (a channel the variant needs
// is missing).
bool ScoreDay(const Series& minutes, std::int64_t day_start_s, const Plant& plant,
              const ModelSpec& spec, const ParamVector& params, const PerformanceOptions& options,
              DayPerformance* out, std::string* error);

// ---------------------------------------------------------------------------
// Drift of an identified parameter across accepted calibrations.
//
// Nightly fits of a window of W days share W − 1 of their days, so their
// estimates are strongly correlated: a monotone run over three or four fits
// is common by chance, and a fit's Hessian standard error leaves out the
// structural gap between model and plant (which days the window holds moves
// a parameter more than its standard error says). The rule therefore
// compares two fits whose windows do not overlap, and reads the scale of
// their difference from the plant's own history of the parameter.
//
// Model of a healthy plant: a fit over days [n − W, n) is μ + (1/W)·Σ u_d,
// the mean of the days' own preferences u_d (independent, variance σ_u²).
// Two fits whose windows are L days apart then differ with variance
//   Var(x_{n+L} − x_n) = 2σ_u²·min(L, W)/W² = v·min(L, W),  v = 2σ_u²/W²,
// a random walk for L < W that saturates at v·W once the windows no longer
// overlap. v comes from the steps between consecutive fits (L < W):
//   v̂ = Σ (step − m·L)²/L / (steps − 1),   m = Σ step / Σ L,
// the steps' spread around their mean rate m, so that a steady drift does
// not inflate its own yardstick. The scale of a change between windows that
// do not overlap is the larger of sqrt(v̂·W) (the wobble of the plant's
// own fits) and sqrt(se_first² + se_last²) (the fits' errors).
//
// The rule: the newest fit (last) against the oldest fit of the history
// whose window ended at or before the newest window's start (first): the
// longest span of independent windows in drift_days, where a steady drift
// has moved furthest. A drift when |last − first| > kDriftSigmas·scale,
// kDriftSigmas = 3 (Shewhart's control limit, fixed before any seed was
// run). False-alarm rate it implies for a Gaussian wobble of known scale:
// 0.27 % of independent comparisons of a parameter; nightly comparisons
// share their windows, so about one independent comparison per W days:
// with the six identified parameters of 2N1Ccolwr and W = 14, about 0.4
// false warnings a year (with the scale estimated from ~27 steps, Student's
// t with ~26 degrees of freedom, about 0.6 % and 0.9 a year).
//
// Not judged (judged false, no drift) when the history holds no fit whose
// window ended before the newest one's start, or fewer than two steps
// between overlapping windows: drift_days shorter than W + 2 days of
// accepted nightly fits, or a daemon younger than that.

struct ParameterPoint {
  std::int64_t run_at_s = 0;
  double value = 0.0;
  double std_error = 0.0;  // NaN when unknown
  // The fit's window [window_start_s, window_end_s); a point without one
  // (end not after start) does not count.
  std::int64_t window_start_s = 0, window_end_s = 0;
};

// Shewhart's control limit, in units of the scale.
inline constexpr double kDriftSigmas = 3.0;

struct ParameterDrift {
  bool judged = false;             // two fits whose windows do not overlap, and two steps
  bool drift = false;              // judged and |change| > kDriftSigmas · scale
  double first = 0.0, last = 0.0;  // the oldest fit of a window apart, and the newest
  std::int64_t first_window_end_s = 0, last_window_start_s = 0;
  double change = 0.0;       // last − first
  double combined_se = 0.0;  // sqrt(se_first² + se_last²)
  double wobble_sd = 0.0;    // sqrt(v̂·W): the plant's own fits, windows apart
  double scale = 0.0;        // max(combined_se, wobble_sd)
  int calibrations = 0;      // points with a value, standard error and window
  int steps = 0;             // steps between overlapping consecutive fits
};

// points in time order (of their windows).
ParameterDrift DetectDrift(std::span<const ParameterPoint> points);

// ---------------------------------------------------------------------------
// Power check of the thermal output against the collector's datasheet, in
// the manner of ISO 24194:2022 (the performance check of collector fields):
// hourly means, the standard's filters (in-plane irradiance ≥ 800 W/m²,
// ambient ≥ 5 °C, wind ≤ 10 m/s, |dT_m/dt| ≤ 5 K/h; an angle of incidence ≤
// 80° as SunPeek adds), the pump running the whole hour, and the datasheet's
// estimate of the power per m² (ISO 9806 quasi-dynamic form):
//   q_est = η0·K_hem·G − c6·u·G − (c1 + c3·u)·ΔT − c2·ΔT² + c4·(E_L − σ·T_a⁴)
//           − c5·dT_m/dt,        ΔT = T_m − T_a, T_m = (T_in + T_out)/2,
//   K_hem = 0.85·K_b(θ) + 0.15·K_d (ISO 9806 annex B with η0,b = η0,hem),
//   K_b from the plant's IAM (b0).
// ISO 24194 covers glazed collectors (formula 1: c3 = c4 = c6 = 0); the wind
// and long-wave terms of an uncovered PVT collector's datasheet make the same
// check meaningful for it. The check passes when the measured power over the
// valid hours is at least safety_factor times the estimate.

struct CollectorDatasheet {
  double eta0 = 0.0;       // η0,hem; 0: no datasheet, no check
  double c1_w_m2k = 0.0;   // a1
  double c2_w_m2k2 = 0.0;  // a2
  double c3_j_m3k = 0.0;   // wind dependence of the heat loss
  double c4 = 0.0;         // long-wave irradiance dependence
  double c5_j_m2k = 0.0;   // effective heat capacity (a5)
  double c6_s_m = 0.0;     // wind dependence of η0
  double kd = 1.0;         // diffuse incidence angle modifier
};

struct PowerCheckOptions {
  double safety_factor = 0.9;  // the guarantee's allowance (pipes, measurement, other)
  int min_intervals = 20;      // ISO 24194 6.2: at least 20 valid hours
  int min_minutes = 50;        // minutes of an hour with the pump on and every input
  double min_g_w_m2 = 800.0;
  double min_t_amb_c = 5.0;
  double max_wind_m_s = 10.0;
  double max_dtm_dt_k_h = 5.0;
  double max_aoi_rad = DegToRad(80.0);  // the hour's largest angle of incidence (SunPeek)
};

struct PowerCheckResult {
  int intervals = 0;            // valid hours
  double measured_w_m2 = 0.0;   // mean over them
  double estimated_w_m2 = 0.0;  // mean over them
  double ratio = 0.0;           // measured / estimated (NaN without intervals)
  bool enough = false;          // intervals >= min_intervals
  bool pass = false;            // enough and measured >= safety_factor · estimated
};

PowerCheckResult CheckPowerAgainstDatasheet(const Series& minutes, const Plant& plant,
                                            const CollectorDatasheet& datasheet,
                                            const PowerCheckOptions& options = {});

// ---------------------------------------------------------------------------
// Sensor faults in 1-min rows, as intervals [start_s, end_s).

struct SensorFault {
  std::string channel;  // canonical name (core/channels.h)
  std::int64_t start_s = 0, end_s = 0;
  // missing | frozen | heat_without_flow | sky_warmer_than_air |
  // above_clear_sky | poa_disagrees_with_ghi_dhi | clock_shift (channel "time")
  std::string kind;
  std::string detail;
};

struct SensorFaultOptions {
  int min_missing_minutes = 10;  // a gap shorter than this is a dropout, not a fault
  int min_frozen_minutes = 60;   // identical 1-min means of a noisy sensor for an hour
  int min_run_minutes = 10;      // heat without flow, sky warmer than air
  double heat_without_flow_w = 50.0;
  double sky_warmer_k = 2.0;    // sky temperature above air by more than this ...
  double sunny_g_w_m2 = 600.0;  // ... while the sun shines (no overcast explains it)
  // Irradiance above the clear sky of a very clean atmosphere (Ineichen–
  // Perez, Linke turbidity 2) by this factor plus 50 W/m² for
  // min_run_minutes: cloud enhancement lasts seconds to minutes, a wrong
  // calibration factor or a tilted sensor hours.
  double clear_sky_factor = 1.25;
  // In-plane irradiance against GHI/DHI transposed to the plane (isotropic
  // sky, paper 2.5), with the sun at least 15° high: a relative difference
  // above this (plus 50 W/m²) for min_disagree_minutes.
  double poa_disagreement = 0.25;
  int min_disagree_minutes = 30;
  // A clear day whose irradiance peaks this much earlier or later than the
  // clear sky of the plane (a logger clock that is off, or on local time).
  double max_clock_offset_min = 10.0;
};

// The faults in rows (step 60 s, increasing times).
// The plant gives the site and plane of the irradiance checks.
std::vector<SensorFault> FindSensorFaults(const Series& minutes, const Plant& plant,
                                          const SensorFaultOptions& options = {});

}  // namespace pvtwin
