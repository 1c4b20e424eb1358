#include "core/monitor/monitoring.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/common/units.h"
#include "core/fit/identification.h"
#include "core/model/irradiance_drivers.h"
#include "core/model/thermal_model.h"
#include "core/physics/iam.h"
#include "core/physics/irradiance.h"
#include "core/physics/sky_radiation.h"
#include "core/physics/solar_position.h"
#include "core/synth/weather_generator.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::int64_t kDayS = 86400;

// Day of the year (1 … 366) of a unix time, UTC.
double DayOfYear(std::int64_t t_s) {
  const std::chrono::sys_days day{std::chrono::days{t_s / kDayS}};
  const std::chrono::year_month_day ymd{day};
  const std::chrono::sys_days jan1{ymd.year() / std::chrono::January / 1};
  return static_cast<double>((day - jan1).count() + 1);
}

}  // namespace

bool ScoreDay(const Series& minutes, std::int64_t day_start_s, const Plant& plant,
              const ModelSpec& spec, const ParamVector& params, const PerformanceOptions& options,
              DayPerformance* out, std::string* error) {
  const Series day = minutes.Between(day_start_s, day_start_s + kDayS);
  DayPerformance p;
  p.day_start_s = day_start_s;
  if (day.size() > 0) {
    Drivers drivers;
    if (!PrepareDrivers(day, plant, spec, &drivers, error)) return false;
    SimOutputs sim;
    Simulate(drivers, params, &sim);
    const Measurements meas = MakeMeasurements(day, drivers);
    const double h = day.step_s / 3600.0;  // hours per row
    double valid_s = 0.0;                  // rows of 2-, 10- or 15-min data count their minutes
    for (const std::uint32_t i : meas.rows) {
      if (!std::isfinite(sim.p_el_w[i]) || !std::isfinite(sim.q_th_w[i])) continue;
      valid_s += day.step_s;
      p.e_el_meas_wh += meas.p_el_w[i] * h;
      p.e_el_model_wh += sim.p_el_w[i] * h;
      p.e_th_meas_wh += meas.q_th_w[i] * h;
      p.e_th_model_wh += sim.q_th_w[i] * h;
    }
    p.valid_minutes = static_cast<int>(std::floor(valid_s / 60.0 + 1e-9));
  }
  const bool enough = p.valid_minutes >= options.min_valid_minutes;
  p.scored_el = enough && p.e_el_model_wh >= options.min_el_wh_m2 * plant.area_m2;
  p.scored_th = enough && p.e_th_model_wh >= options.min_th_wh_m2 * plant.area_m2;
  p.pi_el = p.scored_el ? p.e_el_meas_wh / p.e_el_model_wh : kNaN;
  p.pi_th = p.scored_th ? p.e_th_meas_wh / p.e_th_model_wh : kNaN;
  p.pi_el_low = p.pi_el_high = p.pi_th_low = p.pi_th_high = kNaN;
  *out = p;
  return true;
}

namespace {

// The steps' variance per day of window shift (DetectDrift's v̂) over the
// consecutive fits whose windows overlap; *steps how many there were.
double WobbleVariancePerDay(const std::vector<ParameterPoint>& known, int* steps) {
  std::vector<std::pair<double, double>> step_lag;  // (step, lag in days)
  for (std::size_t k = 1; k < known.size(); ++k) {
    const double lag_d =
        static_cast<double>(known[k].window_end_s - known[k - 1].window_end_s) / kDayS;
    const double window_d =
        static_cast<double>(known[k].window_end_s - known[k].window_start_s) / kDayS;
    if (!(lag_d > 0.0) || lag_d >= window_d) continue;  // same window, or no overlap
    step_lag.emplace_back(known[k].value - known[k - 1].value, lag_d);
  }
  *steps = static_cast<int>(step_lag.size());
  if (step_lag.size() < 2) return kNaN;
  double sum_step = 0.0, sum_lag = 0.0;
  for (const auto& [step, lag] : step_lag) sum_step += step, sum_lag += lag;
  const double rate = sum_step / sum_lag;  // the mean change per day (a steady drift)
  double sum_sq = 0.0;
  for (const auto& [step, lag] : step_lag) {
    const double off = step - rate * lag;  // the step beside the mean rate
    sum_sq += off * off / lag;
  }
  return sum_sq / static_cast<double>(step_lag.size() - 1);
}

}  // namespace

ParameterDrift DetectDrift(std::span<const ParameterPoint> points) {
  std::vector<ParameterPoint> known;
  for (const ParameterPoint& p : points) {
    if (std::isfinite(p.value) && std::isfinite(p.std_error) && p.std_error >= 0.0 &&
        p.window_end_s > p.window_start_s) {
      known.push_back(p);
    }
  }
  ParameterDrift d;
  d.calibrations = static_cast<int>(known.size());
  if (known.empty()) return d;
  const ParameterPoint& last = known.back();
  const auto first = std::find_if(known.begin(), known.end(), [&last](const ParameterPoint& p) {
    return p.window_end_s <= last.window_start_s;
  });
  const double v = WobbleVariancePerDay(known, &d.steps);
  if (first == known.end() || !std::isfinite(v)) return d;  // not judged
  d.judged = true;
  d.first = first->value;
  d.last = last.value;
  d.first_window_end_s = first->window_end_s;
  d.last_window_start_s = last.window_start_s;
  d.change = d.last - d.first;
  d.combined_se = std::hypot(first->std_error, last.std_error);
  d.wobble_sd = std::sqrt(v * static_cast<double>(last.window_end_s - last.window_start_s) / kDayS);
  d.scale = std::max(d.combined_se, d.wobble_sd);
  d.drift = std::fabs(d.change) > kDriftSigmas * d.scale;
  return d;
}

namespace {

// Means of one clock hour's usable rows.
struct HourMeans {
  int rows = 0;
  double g = 0, t_amb = 0, t_m = 0, wind = 0, lw = 0, q_w = 0, k_b = 0;
  double t_m_first = 0, t_m_last = 0;  // means of the first and last 10 rows
  double max_aoi_rad = 0;
  bool has_wind = false, has_lw = false;
};

}  // namespace

PowerCheckResult CheckPowerAgainstDatasheet(const Series& s, const Plant& plant,
                                            const CollectorDatasheet& d,
                                            const PowerCheckOptions& o) {
  PowerCheckResult r;
  r.ratio = kNaN;
  if (!(d.eta0 > 0.0) || s.size() == 0 || !s.Has(Channel::kGPoaWM2) || !s.Has(Channel::kTAmbC) ||
      !s.Has(Channel::kTInC) || !s.Has(Channel::kTOutC) || !s.Has(Channel::kMdotKgS)) {
    return r;
  }
  const std::vector<SolarPosition> sun = SunAtRowMiddles(s, plant);
  const bool has_q = s.Has(Channel::kQThW);
  const bool has_wind = s.Has(Channel::kWindMS);
  const bool has_lw = s.Has(Channel::kLwDownWM2);
  double sum_meas = 0.0, sum_est = 0.0;
  std::size_t i = 0;
  while (i < s.size()) {
    const std::int64_t hour = s.time_s[i] / 3600;
    std::vector<std::size_t> rows;
    std::size_t j = i;
    for (; j < s.size() && s.time_s[j] / 3600 == hour; ++j) {
      const double q = has_q ? s[Channel::kQThW][j] : kNaN;
      const bool ok = s.At(Channel::kValid, j) != 0.0 && s[Channel::kMdotKgS][j] > 1e-4 &&
                      std::isfinite(s[Channel::kGPoaWM2][j]) &&
                      std::isfinite(s[Channel::kTAmbC][j]) && std::isfinite(s[Channel::kTInC][j]) &&
                      std::isfinite(s[Channel::kTOutC][j]) && (!has_q || std::isfinite(q)) &&
                      (!has_wind || std::isfinite(s[Channel::kWindMS][j])) &&
                      (!has_lw || std::isfinite(s[Channel::kLwDownWM2][j]));
      if (ok) rows.push_back(j);
    }
    i = j;
    const int minutes = static_cast<int>(static_cast<double>(rows.size()) * s.step_s / 60.0);
    if (minutes < o.min_minutes || rows.size() < 4) continue;
    HourMeans h;
    const std::size_t edge = std::max<std::size_t>(1, std::min<std::size_t>(10, rows.size() / 4));
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const std::size_t row = rows[k];
      const double t_m = 0.5 * (s[Channel::kTInC][row] + s[Channel::kTOutC][row]);
      const double q = has_q ? s[Channel::kQThW][row]
                             : s[Channel::kMdotKgS][row] * plant.fluid_cp_j_kgk *
                                   (s[Channel::kTOutC][row] - s[Channel::kTInC][row]);
      const double aoi = AngleOfIncidenceRad(sun[row].zenith_rad, sun[row].azimuth_rad,
                                             plant.tilt_rad, plant.azimuth_rad);
      h.g += s[Channel::kGPoaWM2][row];
      h.t_amb += s[Channel::kTAmbC][row];
      h.t_m += t_m;
      h.q_w += q;
      h.k_b += aoi < 0.5 * kPi ? IamSoukaSafwat(aoi, plant.iam_b0) : 0.0;
      h.max_aoi_rad = std::max(h.max_aoi_rad, aoi);
      if (has_wind) h.wind += s[Channel::kWindMS][row];
      if (has_lw) h.lw += s[Channel::kLwDownWM2][row];
      if (k < edge) h.t_m_first += t_m / static_cast<double>(edge);
      if (k >= rows.size() - edge) h.t_m_last += t_m / static_cast<double>(edge);
    }
    const double n = static_cast<double>(rows.size());
    h.g /= n, h.t_amb /= n, h.t_m /= n, h.q_w /= n, h.k_b /= n, h.wind /= n, h.lw /= n;
    const double span_h =
        static_cast<double>(s.time_s[rows.back()] - s.time_s[rows.front()]) / 3600.0;
    const double dtm_dt_k_h = span_h > 0.0 ? (h.t_m_last - h.t_m_first) / span_h : 0.0;
    if (h.g < o.min_g_w_m2 || h.t_amb < o.min_t_amb_c || (has_wind && h.wind > o.max_wind_m_s) ||
        std::fabs(dtm_dt_k_h) > o.max_dtm_dt_k_h || h.max_aoi_rad > o.max_aoi_rad) {
      continue;
    }
    const double dt = h.t_m - h.t_amb;
    const double u = has_wind ? h.wind : 0.0;
    const double sky = has_lw ? h.lw - kStefanBoltzmannW_m2k4 * std::pow(CToK(h.t_amb), 4) : 0.0;
    const double k_hem = 0.85 * h.k_b + 0.15 * d.kd;
    const double est = d.eta0 * k_hem * h.g - d.c6_s_m * u * h.g -
                       (d.c1_w_m2k + d.c3_j_m3k * u) * dt - d.c2_w_m2k2 * dt * dt + d.c4 * sky -
                       d.c5_j_m2k * dtm_dt_k_h / 3600.0;
    sum_meas += h.q_w / plant.area_m2;
    sum_est += est;
    ++r.intervals;
  }
  if (r.intervals == 0) return r;
  r.measured_w_m2 = sum_meas / r.intervals;
  r.estimated_w_m2 = sum_est / r.intervals;
  r.ratio = r.measured_w_m2 / r.estimated_w_m2;
  r.enough = r.intervals >= o.min_intervals;
  r.pass = r.enough && r.measured_w_m2 >= o.safety_factor * r.estimated_w_m2;
  return r;
}

namespace {

// Runs of consecutive rows (at most one row step apart) where `bad(i)`
// holds, lasting at least min_minutes, as faults. Rows are 1-min means in
// the store; an imported or diagnosed file may hold coarser steps.
template <typename Pred>
void AddRuns(const Series& s, const std::string& channel, const std::string& kind, int min_minutes,
             Pred bad, const std::string& detail, std::vector<SensorFault>* out) {
  const std::size_t n = s.size();
  const auto step = static_cast<std::int64_t>(s.step_s >= 60.0 ? s.step_s : 60.0);
  std::size_t i = 0;
  while (i < n) {
    if (!bad(i)) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < n && bad(j) && (j == i || s.time_s[j] - s.time_s[j - 1] <= step)) ++j;
    const std::int64_t minutes = (s.time_s[j - 1] + step - s.time_s[i]) / 60;
    if (minutes >= min_minutes) {
      out->push_back({channel, s.time_s[i], s.time_s[j - 1] + step, kind,
                      detail + " for " + std::to_string(minutes) + " min"});
    }
    i = j;
  }
}

// A logger clock that is off: on a clear day the in-plane irradiance follows
// the clear-sky model of the plane, shifted by the clock's error; the lag
// (within ±90 min) that best lines the two up is that error, and one beyond
// max_clock_offset_min is a fault. A day counts as clear when its energy is
// 80–110 % of the clean clear sky's and 90 % of its daylight rows reach 60 %
// of it.
void FindClockShift(const Series& s, const std::vector<double>& clear_poa,
                    const std::vector<SolarPosition>& sun, const SensorFaultOptions& o,
                    std::vector<SensorFault>* faults) {
  const std::vector<double>& g = s[Channel::kGPoaWM2];
  const double rows_per_min = 60.0 / s.step_s;
  const int max_lag = static_cast<int>(std::lround(90.0 * rows_per_min));
  std::size_t i = 0;
  while (i < s.size()) {
    const std::int64_t day = s.time_s[i] / kDayS;
    std::size_t j = i;
    while (j < s.size() && s.time_s[j] / kDayS == day) ++j;
    const std::size_t first = i, end = j;
    i = j;
    double sum_g = 0, sum_c = 0;
    int daylight = 0, bright = 0;
    for (std::size_t k = first; k < end; ++k) {
      if (sun[k].elevation_rad < DegToRad(5.0) || !std::isfinite(g[k])) continue;
      sum_g += g[k];
      sum_c += clear_poa[k];
      ++daylight;
      bright += g[k] >= 0.6 * clear_poa[k];
    }
    if (daylight < 4 * 60 * rows_per_min || sum_c <= 0.0) continue;
    if (sum_g < 0.8 * sum_c || sum_g > 1.1 * sum_c || bright < 0.9 * daylight) continue;
    int best_lag = 0;
    double best = -1.0;
    for (int lag = -max_lag; lag <= max_lag; ++lag) {
      double dot = 0.0;
      for (std::size_t k = first; k < end; ++k) {
        const auto shifted = static_cast<std::ptrdiff_t>(k) - lag;
        if (shifted < 0 || shifted >= static_cast<std::ptrdiff_t>(s.size()) ||
            !std::isfinite(g[k])) {
          continue;
        }
        dot += g[k] * clear_poa[static_cast<std::size_t>(shifted)];
      }
      if (dot > best) {
        best = dot;
        best_lag = lag;
      }
    }
    const double offset_min = best_lag / rows_per_min;
    if (std::fabs(offset_min) <= o.max_clock_offset_min) continue;
    char detail[160];
    std::snprintf(detail, sizeof detail,
                  "on a clear day the irradiance peaks %.0f min %s than the sun: the logger clock "
                  "is off by about that much",
                  std::fabs(offset_min), offset_min > 0 ? "later" : "earlier");
    faults->push_back({"time", s.time_s[first],
                       s.time_s[end - 1] + static_cast<std::int64_t>(s.step_s), "clock_shift",
                       detail});
  }
}

// The irradiance checks: above the clear sky, and the plane's sensor against
// the horizontal pair.
void FindIrradianceFaults(const Series& s, const Plant& plant, const SensorFaultOptions& o,
                          std::vector<SensorFault>* faults) {
  const bool poa = s.Has(Channel::kGPoaWM2);
  const bool pair = s.Has(Channel::kGhiWM2) && s.Has(Channel::kDhiWM2);
  if (!poa && !s.Has(Channel::kGhiWM2)) return;
  const std::vector<SolarPosition> sun = SunAtRowMiddles(s, plant);
  const std::size_t n = s.size();
  std::vector<double> clear_poa(n, 0.0), clear_ghi(n, 0.0), transposed(n, kNaN);
  for (std::size_t i = 0; i < n; ++i) {
    const double aoi = AngleOfIncidenceRad(sun[i].zenith_rad, sun[i].azimuth_rad, plant.tilt_rad,
                                           plant.azimuth_rad);
    ClearSkyInput in;
    in.zenith_rad = sun[i].zenith_rad;
    in.day_of_year = DayOfYear(s.time_s[i]);
    in.elevation_m = plant.elevation_m;
    in.linke_turbidity = 2.0;
    const ClearSkyIrradiance c = ClearSkyIneichenPerez(in);
    clear_ghi[i] = c.ghi_w_m2;
    clear_poa[i] = TransposeIsotropicSky({c.ghi_w_m2, c.dhi_w_m2, sun[i].zenith_rad, aoi,
                                          plant.tilt_rad, plant.ground_albedo})
                       .global_w_m2();
    if (pair && sun[i].elevation_rad >= DegToRad(15.0)) {
      transposed[i] =
          TransposeIsotropicSky({s[Channel::kGhiWM2][i], s[Channel::kDhiWM2][i], sun[i].zenith_rad,
                                 aoi, plant.tilt_rad, plant.ground_albedo})
              .global_w_m2();
    }
  }
  const double f = o.clear_sky_factor;
  char factor[16];
  std::snprintf(factor, sizeof factor, "%.2f", f);
  const std::string above =
      std::string("above ") + factor + " × the clear sky of a clean atmosphere + 50 W/m²";
  if (poa) {
    const std::vector<double>& g = s[Channel::kGPoaWM2];
    AddRuns(
        s, "g_poa_w_m2", "above_clear_sky", o.min_run_minutes,
        [&](std::size_t i) { return g[i] > f * clear_poa[i] + 50.0; }, above, faults);
  }
  if (s.Has(Channel::kGhiWM2)) {
    const std::vector<double>& g = s[Channel::kGhiWM2];
    AddRuns(
        s, "ghi_w_m2", "above_clear_sky", o.min_run_minutes,
        [&](std::size_t i) { return g[i] > f * clear_ghi[i] + 50.0; }, above, faults);
  }
  if (poa) FindClockShift(s, clear_poa, sun, o, faults);
  if (poa && pair) {
    const std::vector<double>& g = s[Channel::kGPoaWM2];
    AddRuns(
        s, "g_poa_w_m2", "poa_disagrees_with_ghi_dhi", o.min_disagree_minutes,
        [&](std::size_t i) {
          return std::isfinite(transposed[i]) && std::isfinite(g[i]) &&
                 std::fabs(g[i] - transposed[i]) > o.poa_disagreement * transposed[i] + 50.0;
        },
        "differs from GHI/DHI transposed to the plane by more than " +
            std::to_string(static_cast<int>(100 * o.poa_disagreement)) + " % + 50 W/m²",
        faults);
  }
}

}  // namespace

std::vector<SensorFault> FindSensorFaults(const Series& s, const Plant& plant,
                                          const SensorFaultOptions& o) {
  std::vector<SensorFault> faults;
  FindIrradianceFaults(s, plant, o, &faults);
  // Missing: a channel the plant has (some value in the rows) without a
  // value for a while.
  for (const ChannelInfo& info : kChannels) {
    const Channel c = info.channel;
    if (c == Channel::kValid || c == Channel::kAoiRad || !s.Has(c)) continue;
    const std::vector<double>& v = s[c];
    AddRuns(
        s, std::string(info.name), "missing", o.min_missing_minutes,
        [&v](std::size_t i) { return std::isnan(v[i]); }, "no value", &faults);
  }
  // Frozen: the same 1-min mean again and again. A sensor's noise makes
  // successive means differ; zero irradiance, power or wind at night is no
  // fault, so those count only when not zero.
  const Channel frozen_checked[] = {Channel::kTInC,   Channel::kTOutC,  Channel::kTAmbC,
                                    Channel::kTPvC,   Channel::kTBackC, Channel::kGPoaWM2,
                                    Channel::kGhiWM2, Channel::kDhiWM2, Channel::kLwDownWM2,
                                    Channel::kPElW,   Channel::kWindMS};
  for (const Channel c : frozen_checked) {
    if (!s.Has(c)) continue;
    const std::vector<double>& v = s[c];
    const bool zero_ok = c == Channel::kGPoaWM2 || c == Channel::kGhiWM2 || c == Channel::kDhiWM2 ||
                         c == Channel::kPElW || c == Channel::kWindMS;
    AddRuns(
        s, std::string(ChannelName(c)), "frozen", o.min_frozen_minutes,
        [&v, zero_ok](std::size_t i) {
          return i > 0 && std::isfinite(v[i]) && v[i] == v[i - 1] && !(zero_ok && v[i] == 0.0);
        },
        "the same value", &faults);
  }
  // Heat without flow: a heat meter that reports Q_u while the flow is zero.
  if (s.Has(Channel::kQThW) && s.Has(Channel::kMdotKgS)) {
    const std::vector<double>& q = s[Channel::kQThW];
    const std::vector<double>& f = s[Channel::kMdotKgS];
    const double limit = o.heat_without_flow_w;
    AddRuns(
        s, "q_th_w", "heat_without_flow", o.min_run_minutes,
        [&q, &f, limit](std::size_t i) { return f[i] == 0.0 && std::fabs(q[i]) > limit; },
        "|Q_u| above " + std::to_string(static_cast<int>(limit)) + " W at zero flow", &faults);
  }
  // Sky warmer than air in sunshine: a clear sky is colder than the air, and
  // strong sun means a mostly clear sky; a long-wave sensor (or its
  // temperature correction) that reads otherwise is wrong.
  const bool sky = s.Has(Channel::kLwDownWM2) || s.Has(Channel::kTSkyC);
  const Channel sun = s.Has(Channel::kGhiWM2) ? Channel::kGhiWM2 : Channel::kGPoaWM2;
  if (sky && s.Has(Channel::kTAmbC) && s.Has(sun)) {
    const std::vector<double>& g = s[sun];
    const std::vector<double>& t_amb = s[Channel::kTAmbC];
    auto t_sky_c = [&s](std::size_t i) { return MeasuredSkyTemperatureC(s, i); };
    AddRuns(
        s, s.Has(Channel::kLwDownWM2) ? "lw_down_w_m2" : "t_sky_c", "sky_warmer_than_air",
        o.min_run_minutes,
        [&](std::size_t i) {
          return g[i] >= o.sunny_g_w_m2 && t_sky_c(i) > t_amb[i] + o.sky_warmer_k;
        },
        "sky temperature above the air's by more than " +
            std::to_string(static_cast<int>(o.sky_warmer_k)) + " K in sunshine",
        &faults);
  }
  return faults;
}

}  // namespace pvtwin
