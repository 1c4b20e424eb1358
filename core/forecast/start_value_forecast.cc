#include "core/forecast/start_value_forecast.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "core/common/params.h"
#include "core/forecast/operation_forecast.h"
#include "core/forecast/weather_resample.h"
#include "core/model/thermal_model.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr Channel kIrradiance[] = {Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2};
constexpr Channel kOtherWeather[] = {Channel::kTAmbC, Channel::kWindMS, Channel::kTSkyC,
                                     Channel::kLwDownWM2, Channel::kTBackC};

// The value of channel c in the row at exactly t, NaN without one.
double At(const Series& s, Channel c, std::int64_t t) {
  if (!s.Has(c)) return kNaN;
  const std::size_t i = s.RowAtOrAfter(t);
  return i < s.size() && s.time_s[i] == t ? s[c][i] : kNaN;
}

// The latest finite value at or before t, if at most max_gap_s old.
double HeldAt(const Series& s, Channel c, std::int64_t t, double max_gap_s) {
  if (!s.Has(c)) return kNaN;
  for (std::size_t i = s.RowAtOrAfter(t + 1); i-- > 0;) {
    if (static_cast<double>(t - s.time_s[i]) > max_gap_s) break;
    if (std::isfinite(s[c][i])) return s[c][i];
  }
  return kNaN;
}

// Mean of the finite values of c over the history's last span_s.
double RecentMean(const Series& history, Channel c, double span_s) {
  if (!history.Has(c) || history.size() == 0) return kNaN;
  const double from = static_cast<double>(history.time_s.back()) - span_s;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = history.size(); i-- > 0 && static_cast<double>(history.time_s[i]) > from;) {
    if (std::isfinite(history[c][i])) {
      sum += history[c][i];
      ++n;
    }
  }
  return n > 0 ? sum / static_cast<double>(n) : kNaN;
}

// Clear-sky index of the history's daylight minutes over its last day (in
// the plane when it has g_poa_w_m2, else horizontal).
struct MeasuredIndex {
  double index = kNaN;
  std::size_t minutes = 0;
};
MeasuredIndex ClearSkyIndexOf(const Plant& plant, const Series& history, double linke) {
  MeasuredIndex out;
  const Channel c = history.Has(Channel::kGPoaWM2) ? Channel::kGPoaWM2 : Channel::kGhiWM2;
  if (history.size() == 0 || !history.Has(c)) return out;
  const std::int64_t end = history.time_s.back() / 60 * 60 + 60;
  const std::int64_t begin = end - 86400;
  const ClearSkyGrid grid = MakeClearSkyGrid(plant, begin, end, linke);
  const std::vector<double>& clear =
      c == Channel::kGPoaWM2 ? grid.clear_poa_w_m2 : grid.clear_ghi_w_m2;
  double sum = 0.0, sum_clear = 0.0;
  for (std::size_t i = history.RowAtOrAfter(begin); i < history.size(); ++i) {
    const auto k = static_cast<std::size_t>((history.time_s[i] - begin) / 60);
    if (k >= clear.size() || clear[k] < kMinDaylightClearWM2 || !std::isfinite(history[c][i])) {
      continue;
    }
    sum += history[c][i];
    sum_clear += clear[k];
    ++out.minutes;
  }
  if (out.minutes > 0) out.index = sum / sum_clear;
  return out;
}

// The rows of the run: the history's rows of the warm-up span, on the
// step's grid ending at the issue, then the horizon.
Series MakeFrame(const Series& history, const ForecastRequest& request, std::size_t* n_warm) {
  const std::int64_t step = std::llround(request.step_s);
  std::size_t warm = static_cast<std::size_t>(request.warmup_s / request.step_s);
  const std::size_t first =
      history.RowAtOrAfter(request.issued_at_s - static_cast<std::int64_t>(warm) * step);
  if (first >= history.size() || history.time_s[first] >= request.issued_at_s) {
    warm = 0;
  } else {
    warm = static_cast<std::size_t>((request.issued_at_s - history.time_s[first]) / step);
  }
  *n_warm = warm;
  const std::size_t n = warm + static_cast<std::size_t>(request.horizon_s / request.step_s);
  Series in;
  in.step_s = request.step_s;
  in.time_s.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    in.time_s[k] = request.issued_at_s - static_cast<std::int64_t>(warm) * step +
                   static_cast<std::int64_t>(k) * step;
  }
  in[Channel::kValid].assign(n, 1.0);
  return in;
}

// The warm-up rows of channel c from the history, holding its last value
// across up to kWarmupHoldRows missing rows.
void FillWarmup(const Series& history, Channel c, std::size_t n_warm, Series* in) {
  std::vector<double>& col = in->Ensure(c);
  double last = kNaN;
  std::size_t held = 0;
  for (std::size_t k = 0; k < n_warm; ++k) {
    const double v = At(history, c, in->time_s[k]);
    if (std::isfinite(v)) {
      last = v;
      held = 0;
    } else if (++held > kWarmupHoldRows) {
      last = kNaN;
    }
    col[k] = last;
  }
}

// Row k of the horizon's clear sky (the grid starts at the first horizon row).
double ClearAt(const std::vector<double>& clear, std::int64_t begin, std::int64_t t) {
  const std::int64_t k = (t - begin) / 60;
  return k >= 0 && static_cast<std::size_t>(k) < clear.size() ? clear[static_cast<std::size_t>(k)]
                                                              : 0.0;
}

// The irradiance of the horizon rows at clear-sky index k (see the header),
// where keep_table says so only where the table has no value.
void SetIrradiance(const ClearSkyGrid& grid, std::size_t n_warm, double k,
                   const std::vector<std::vector<std::uint8_t>>* keep_table, Series* in) {
  const std::int64_t begin = grid.time_s.empty() ? 0 : grid.time_s.front();
  for (std::size_t ci = 0; ci < std::size(kIrradiance); ++ci) {
    const Channel c = kIrradiance[ci];
    std::vector<double>& col = in->Ensure(c);
    for (std::size_t r = n_warm; r < in->size(); ++r) {
      if (keep_table != nullptr && (*keep_table)[ci][r - n_warm]) continue;
      const std::int64_t t = in->time_s[r];
      const double ghi = k * ClearAt(grid.clear_ghi_w_m2, begin, t);
      const double clear_ghi = ClearAt(grid.clear_ghi_w_m2, begin, t);
      const double clear_share =
          clear_ghi > 0.0 ? ClearAt(grid.clear_dhi_w_m2, begin, t) / clear_ghi : 1.0;
      switch (c) {
        case Channel::kGPoaWM2:
          col[r] = k * ClearAt(grid.clear_poa_w_m2, begin, t);
          break;
        case Channel::kGhiWM2:
          col[r] = ghi;
          break;
        default:
          col[r] = ghi * (1.0 - std::min(k, 1.0) * (1.0 - clear_share));
          break;
      }
    }
  }
}

struct RunOutputs {
  std::vector<double> p_el_w, q_th_w, t_pv_c, t_out_c;  // horizon rows
};

bool Run(const Plant& plant, const ModelSpec& spec, const ParamVector& params, const Series& in,
         std::size_t n_warm, RunOutputs* out, std::string* error) {
  Drivers drivers;
  if (!PrepareDrivers(in, plant, spec, &drivers, error)) return false;
  SimOutputs sim;
  Simulate(drivers, params, &sim);
  const auto tail = [n_warm](const std::vector<double>& v) {
    return std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(n_warm), v.end());
  };
  out->p_el_w = tail(sim.p_el_w);
  out->q_th_w = tail(sim.q_th_w);
  out->t_pv_c = tail(sim.t_pv_c);
  out->t_out_c = tail(sim.t_out_c);
  return true;
}

// Weather and operation channels other than the irradiance: table (or
// plan), else the learned pump rule (flow), else the last hour's mean.
struct Counts {
  std::size_t table_irradiance = 0, table_weather = 0, held_weather = 0;
  std::size_t plan = 0, learned = 0, held_operation = 0;  // flow: plan, rule or daylight, held
};

void FillOtherWeather(const Series& history, const Series& weather_forecast,
                      const StartValueOptions& options, std::size_t n_warm, Series* in,
                      Counts* counts) {
  for (Channel c : kOtherWeather) {
    const double recent = RecentMean(history, c, options.hold_s);
    if (std::isnan(recent) && !weather_forecast.Has(c)) continue;
    FillWarmup(history, c, n_warm, in);
    std::vector<double>& col = (*in)[c];
    for (std::size_t r = n_warm; r < in->size(); ++r) {
      const double v = At(weather_forecast, c, in->time_s[r]);
      col[r] = std::isfinite(v) ? v : recent;
      if (c == Channel::kTAmbC) ++(std::isfinite(v) ? counts->table_weather : counts->held_weather);
    }
  }
}

// The median of the history's positive flows: the pump's flow when on
// (NaN when it never ran).
double OnFlow(const Series& history) {
  std::vector<double> on;
  if (history.Has(Channel::kMdotKgS)) {
    for (double f : history[Channel::kMdotKgS]) {
      if (std::isfinite(f) && f > 0.0) on.push_back(f);
    }
  }
  return SampleQuantile(&on, 0.5);
}

// Flow of the horizon rows without a plan: the learned rule, else (less
// than a day of history) the on-flow while the sun is up; empty when
// neither is known (the last hour's mean is held then).
std::vector<double> FlowWithoutPlan(const Plant& plant, const Series& history,
                                    const ClearSkyGrid& grid, const Series& horizon,
                                    PumpRule* rule) {
  *rule = LearnPumpRule(plant, history);
  if (rule->valid) {
    const double last_flow = RecentMean(history, Channel::kMdotKgS, 60.0 * 5);
    return PumpFlow(plant, *rule, horizon, std::isfinite(last_flow) && last_flow > 0.0);
  }
  const double on_flow = OnFlow(history);
  if (std::isnan(on_flow)) return {};
  std::vector<double> flow(horizon.size());
  const std::int64_t begin = grid.time_s.empty() ? 0 : grid.time_s.front();
  for (std::size_t h = 0; h < horizon.size(); ++h) {
    const bool daylight =
        ClearAt(grid.clear_poa_w_m2, begin, horizon.time_s[h]) >= kMinDaylightClearWM2;
    flow[h] = daylight ? on_flow : 0.0;
  }
  return flow;
}

std::string FillOperation(const Plant& plant, const Series& history, const Series& plan,
                          const ForecastRequest& request, const StartValueOptions& options,
                          const ClearSkyGrid& grid, std::size_t n_warm, Series* in,
                          Counts* counts) {
  PumpRule rule;
  const std::vector<double> learned =
      FlowWithoutPlan(plant, history, grid, in->Slice(n_warm, in->size()), &rule);
  for (Channel c : {Channel::kTInC, Channel::kMdotKgS}) {
    const double recent = RecentMean(history, c, options.hold_s);
    FillWarmup(history, c, n_warm, in);
    std::vector<double>& col = (*in)[c];
    for (std::size_t r = n_warm; r < in->size(); ++r) {
      const double planned = HeldAt(plan, c, in->time_s[r], request.max_interp_gap_s);
      const bool by_rule = c == Channel::kMdotKgS && !learned.empty();
      col[r] = std::isfinite(planned) ? planned : by_rule ? learned[r - n_warm] : recent;
      if (c != Channel::kMdotKgS) continue;
      ++(std::isfinite(planned) ? counts->plan
         : by_rule              ? counts->learned
                                : counts->held_operation);
    }
  }
  if (rule.valid) return rule.Describe();
  return learned.empty() ? std::string()
                         : "pump on while the sun is up (less than a day to learn a rule from)";
}

std::string Describe(const StartValueForecast& f, const Counts& counts, std::size_t rows,
                     const StartValueOptions& options, const ParamInfo& eta, const ParamInfo& f_th,
                     const ParamInfo& r0, const std::string& pump_rule) {
  char buf[900];
  const std::string source =
      f.daylight_minutes > 0 ? "from " + std::to_string(f.daylight_minutes) + " daylight minutes"
                             : std::string("no daylight minute yet: the middle of the range");
  std::snprintf(buf, sizeof buf,
                "start values (Table 3; no calibration yet); irradiance: weather_forecast %zu/%zu, "
                "clear sky x %.2f (%s) %zu/%zu; weather: weather_forecast %zu/%zu, last hour's "
                "mean %zu/%zu; operation: plan %zu/%zu, pump rule %zu/%zu, last hour's mean "
                "%zu/%zu",
                counts.table_irradiance, rows, f.clear_sky_index, source.c_str(),
                rows - counts.table_irradiance, rows, counts.table_weather, rows,
                counts.held_weather, rows, counts.plan, rows, counts.learned, rows,
                counts.held_operation, rows);
  std::string text = buf;
  if (!pump_rule.empty()) text += "; " + pump_rule;
  std::snprintf(buf, sizeof buf,
                "; bands: start-value envelope (clear-sky index %.2f-%.2f, pump off/on, eta_pv_ref "
                "%.3g-%.3g, f_th %.3g-%.3g, r0_fluid_m2k_w %.3g-%.3g; not a calibrated 10-90 %% "
                "band)",
                options.index_low, options.index_high, eta.lower, eta.upper, f_th.lower, f_th.upper,
                r0.lower, r0.upper);
  return text + buf;
}

}  // namespace

bool MakeStartValueForecast(const Plant& plant, const ModelSpec& spec, const Series& history,
                            const Series& weather_forecast, const Series& operation_plan,
                            const ForecastRequest& request, const StartValueOptions& options,
                            StartValueForecast* out, std::string* error) {
  if (request.step_s <= 0 || request.horizon_s < request.step_s || request.warmup_s < 0 ||
      !(options.index_low >= 0.0 && options.index_low <= options.index_high)) {
    *error = "start-value forecast: step, horizon, warm-up or clear-sky indices out of range";
    return false;
  }
  const Series past =
      history.Between(history.size() ? history.time_s.front() : 0, request.issued_at_s);
  std::size_t n_warm = 0;
  Series in = MakeFrame(past, request, &n_warm);
  const std::size_t rows = in.size() - n_warm;
  const ClearSkyGrid grid =
      MakeClearSkyGrid(plant, in.time_s[n_warm], in.time_s.back() + 60, options.linke_turbidity);

  const MeasuredIndex measured = ClearSkyIndexOf(plant, past, options.linke_turbidity);
  out->daylight_minutes = measured.minutes;
  out->clear_sky_index = measured.minutes > 0
                             ? std::clamp(measured.index, options.index_low, options.index_high)
                             : 0.5 * (options.index_low + options.index_high);

  // Point irradiance: the table's per channel, else k · clear sky.
  Counts counts;
  std::vector<std::vector<std::uint8_t>> from_table(std::size(kIrradiance),
                                                    std::vector<std::uint8_t>(rows, 0));
  for (std::size_t ci = 0; ci < std::size(kIrradiance); ++ci) {
    const Channel c = kIrradiance[ci];
    FillWarmup(past, c, n_warm, &in);
    for (std::size_t r = n_warm; r < in.size(); ++r) {
      const double v = At(weather_forecast, c, in.time_s[r]);
      if (!std::isfinite(v)) continue;
      in[c][r] = v;
      from_table[ci][r - n_warm] = 1;
    }
  }
  SetIrradiance(grid, n_warm, out->clear_sky_index, &from_table, &in);
  out->banded.forecast.weather_from_forecast = from_table[0];
  for (std::uint8_t t : from_table[0]) counts.table_irradiance += t;
  FillOtherWeather(past, weather_forecast, options, n_warm, &in, &counts);
  const std::string pump_rule =
      FillOperation(plant, past, operation_plan, request, options, grid, n_warm, &in, &counts);

  // The point, then the envelope's runs.
  const ParamVector start = StartParams(plant);
  const ParamInfo eta = ResolvedInfo(Param::kEtaPvRef, plant);
  const ParamInfo f_th = ResolvedInfo(Param::kFTh, plant);
  RunOutputs point;
  if (!Run(plant, spec, start, in, n_warm, &point, error)) return false;
  std::vector<double> p_lo = point.p_el_w, p_hi = point.p_el_w;
  std::vector<double> q_lo = point.q_th_w, q_hi = point.q_th_w;
  // The yields' ends of Table 3: η_PVref and F_th low, the absorber-fluid
  // resistance r0_fluid high (no heat reaches the fluid, a hot PV), and the
  // reverse.
  const ParamInfo r0 = ResolvedInfo(Param::kR0FluidM2KW, plant);
  ParamVector low = start, high = start;
  low[static_cast<std::size_t>(Param::kEtaPvRef)] = eta.lower;
  low[static_cast<std::size_t>(Param::kFTh)] = f_th.lower;
  low[static_cast<std::size_t>(Param::kR0FluidM2KW)] = r0.upper;
  high[static_cast<std::size_t>(Param::kEtaPvRef)] = eta.upper;
  high[static_cast<std::size_t>(Param::kFTh)] = f_th.upper;
  high[static_cast<std::size_t>(Param::kR0FluidM2KW)] = r0.lower;
  // The pump off, and on at its measured flow on every row: the operation
  // is not known yet either.
  const double on_flow = OnFlow(past);
  const std::vector<double> point_flow = in[Channel::kMdotKgS];
  Series member = in;
  for (int weather = 0; weather < 3; ++weather) {
    if (weather > 0) {
      SetIrradiance(grid, n_warm, weather == 1 ? options.index_low : options.index_high, nullptr,
                    &member);
    }
    for (int pump = 0; pump < 3; ++pump) {
      if (pump == 2 && std::isnan(on_flow)) continue;
      std::vector<double>& flow = member[Channel::kMdotKgS];
      for (std::size_t r = n_warm; r < flow.size(); ++r) {
        flow[r] = pump == 0 ? point_flow[r] : pump == 1 ? 0.0 : on_flow;
      }
      const ParamVector* const members[] = {&start, &low, &high};
      for (const ParamVector* params : members) {
        if (weather == 0 && pump == 0 && params == &start) continue;  // the point
        RunOutputs run;
        if (!Run(plant, spec, *params, weather == 0 && pump == 0 ? in : member, n_warm, &run,
                 error)) {
          return false;
        }
        for (std::size_t h = 0; h < rows; ++h) {
          if (std::isnan(point.p_el_w[h]) || std::isnan(point.q_th_w[h])) continue;
          p_lo[h] = std::fmin(p_lo[h], run.p_el_w[h]);
          p_hi[h] = std::fmax(p_hi[h], run.p_el_w[h]);
          q_lo[h] = std::fmin(q_lo[h], run.q_th_w[h]);
          q_hi[h] = std::fmax(q_hi[h], run.q_th_w[h]);
        }
      }
    }
  }

  Forecast& f = out->banded.forecast;
  f.rows = Series{};
  f.rows.step_s = request.step_s;
  f.rows.time_s.assign(in.time_s.begin() + static_cast<std::ptrdiff_t>(n_warm), in.time_s.end());
  f.rows[Channel::kPElW] = point.p_el_w;
  f.rows[Channel::kQThW] = point.q_th_w;
  f.rows[Channel::kTPvC] = point.t_pv_c;
  f.rows[Channel::kTOutC] = point.t_out_c;
  f.reference = Series{};
  f.reference.step_s = request.step_s;
  f.reference.time_s = f.rows.time_s;
  f.reference[Channel::kPElW].assign(rows, kNaN);
  f.reference[Channel::kQThW].assign(rows, kNaN);
  f.inputs = ForecastInputUse{};
  f.inputs.rows = rows;
  f.inputs_used = in.Slice(n_warm, in.size());

  ForecastBands& b = out->banded.bands;
  b = ForecastBands{};
  b.p_el_p10 = std::move(p_lo);
  b.p_el_p90 = std::move(p_hi);
  b.q_th_p10 = std::move(q_lo);
  b.q_th_p90 = std::move(q_hi);
  b.p_el_p50 = point.p_el_w;
  b.q_th_p50 = point.q_th_w;
  for (std::size_t h = 0; h < rows; ++h) {
    if (std::isnan(point.p_el_w[h]) || std::isnan(point.q_th_w[h])) {
      b.p_el_p10[h] = b.p_el_p90[h] = b.q_th_p10[h] = b.q_th_p90[h] = kNaN;
    }
  }
  out->inputs = Describe(*out, counts, rows, options, eta, f_th, r0, pump_rule);
  b.note = out->inputs.substr(out->inputs.find("bands: "));
  return true;
}

}  // namespace pvtwin
