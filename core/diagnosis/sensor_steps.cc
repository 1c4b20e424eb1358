// The residual sensor checks' common part (sensor_residuals.h): the final
// model fitted on all the days, the day series, the step test, the registry,
// and the first check, offset_step.
//
// offset_step: the inlet temperature reading high (or the outlet low) by a
// constant from one day on. The heat meter multiplies flow by the logged
// T_out − T_in, so from that day the measured Q_u is low by ṁ·c_p·δ while
// the pump runs. The model is driven by the same logged inlet: from a δ
// warmer inlet it predicts δ·∂Q_u/∂T_in less heat (more loss, about
// −F_R·U_L·A·δ). A model fitted on all the days therefore leaves a Q_u
// residual of δ·(ṁ·c_p + ∂Q_u/∂T_in) (SensorResiduals::inlet_offset_w_k),
// and its residual per that sensitivity, (Q_pred − Q_meas) / (ṁ·c_p +
// ∂Q_u/∂T_in) in K, steps by δ from that day on. Under a flow controller
// that holds T_out − T_in, ṁ·c_p alone grows with Q_u and would make an
// offset look like a flow meter scale at low flow.
//
// The test, over the days (DiagnosisOptions, sensor_step_*):
//  * per day the median of that residual over the rows with flow;
//  * the split day that fits the day series best as a step (two means);
//  * a step is found when the days on the two sides are perfectly separated
//    (every day after it beyond every day before it: it stays), the step
//    fits the day series better than a straight line (a drift, as soiling's,
//    is not a step), the two-sided rank probability of that separation,
//    times the number of split days tried, is at most alpha, and the step
//    is at least min_temperature_offset_k.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "core/common/calendar.h"
#include "core/diagnosis/sensor_residuals.h"

namespace pvtwin::diagnosis_stages {

const std::vector<ResidualSensorCheck>& ResidualSensorChecks() {
  static const std::vector<ResidualSensorCheck> checks = {
      CheckOffsetStep,       // t_in_c / t_out_c offset_step (this file)
      CheckNightPairOffset,  // t_in_c,t_out_c pair_offset (sensor_pair_night.cc)
      CheckFlowScale,        // flow_kg_s scale (sensor_flow_scale.cc)
  };
  return checks;
}

namespace {

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

double Mean(const std::vector<double>& v, std::size_t lo, std::size_t hi) {
  double s = 0.0;
  for (std::size_t k = lo; k < hi; ++k) s += v[k];
  return s / static_cast<double>(hi - lo);
}

// Residual sum of squares of the least-squares line through (k, y_k).
double LineSse(const std::vector<double>& y) {
  const double n = static_cast<double>(y.size());
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double x = static_cast<double>(k);
    sx += x;
    sy += y[k];
    sxx += x * x;
    sxy += x * y[k];
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  const double icpt = (sy - slope * sx) / n;
  double sse = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double e = y[k] - icpt - slope * static_cast<double>(k);
    sse += e * e;
  }
  return sse;
}

// 2 · n1! n2! / (n1 + n2)!: the two-sided probability that ranks separate
// perfectly into the first n1 and the last n2.
double SeparationP(std::size_t n1, std::size_t n2) {
  double log_p = std::lgamma(static_cast<double>(n1) + 1.0) +
                 std::lgamma(static_cast<double>(n2) + 1.0) -
                 std::lgamma(static_cast<double>(n1 + n2) + 1.0);
  return std::min(1.0, 2.0 * std::exp(log_p));
}

// The final model per row of all the days, fitted on the rows before
// fit_before_s (nullopt when it cannot be fitted).
std::optional<SensorResiduals> FitAllDays(
    const Series& data, const Split& split, const Plant& plant, const ModelSpec& base,
    const ParamVector& start, const DiagnosisOptions& options,
    std::int64_t fit_before_s = std::numeric_limits<std::int64_t>::max()) {
  Part all;
  std::string why;
  if (!PreparePart(data, plant, base, split.data_start_s, split.cleanings, &all, &why)) {
    return std::nullopt;
  }
  Measurements fitted = all.meas;
  std::erase_if(fitted.rows, [&](std::uint32_t i) { return data.time_s[i] >= fit_before_s; });
  if (fitted.rows.empty()) return std::nullopt;
  // The final model's parameters as they are, in the ranges they were found in (no re-fit).
  DiagnosisOptions ranges = options;
  ranges.refit_in_physical_ranges = false;
  const IdentSummary fit = IdentifyInRanges(all.drivers, fitted, start, ranges).fit;
  if (!fit.ok) return std::nullopt;
  SimOutputs sim;
  Simulate(all.drivers, fit.params, &sim);
  Drivers warmer_inlet = all.drivers;
  for (double& t : warmer_inlet.t_in_c) t += 1.0;
  SimOutputs warmer;
  Simulate(warmer_inlet, fit.params, &warmer);
  SensorResiduals r;
  r.data = &data;
  r.plant = &plant;
  r.options = &options;
  r.offset_s = split.offset_s;
  r.rows = all.meas.rows;
  const std::size_t n = data.size();
  r.day_s.resize(n);
  for (std::size_t i = 0; i < n; ++i) r.day_s[i] = SolarDayStartS(data.time_s[i], split.offset_s);
  r.capacity_flow_w_k.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    r.capacity_flow_w_k[i] = all.drivers.mdot_kg_s[i] * plant.fluid_cp_j_kgk;
  }
  r.inlet_offset_w_k.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    r.inlet_offset_w_k[i] = r.capacity_flow_w_k[i] + (warmer.q_th_w[i] - sim.q_th_w[i]);
  }
  r.g_poa_w_m2 = all.drivers.g_poa_w_m2;
  r.q_meas_w = all.meas.q_th_w;
  r.q_model_w = std::move(sim.q_th_w);
  r.p_meas_w = all.meas.p_el_w;
  r.p_model_w = std::move(sim.p_el_w);
  r.t_in_c = all.drivers.t_in_c;
  r.t_out_meas_c =
      data.Has(Channel::kTOutC) ? data[Channel::kTOutC] : std::vector<double>(n, std::nan(""));
  r.t_out_model_c = std::move(sim.t_out_c);
  return r;
}

// True when every value from `split` on lies beyond every value before it,
// above when `up`, else below (both sides non-empty).
bool SeparatedAt(const std::vector<double>& y, std::size_t split, bool up) {
  const auto mid = y.begin() + static_cast<std::ptrdiff_t>(split);
  const auto [lo1, hi1] = std::minmax_element(y.begin(), mid);
  const auto [lo2, hi2] = std::minmax_element(mid, y.end());
  return up ? *lo2 > *hi1 : *hi2 < *lo1;
}

// Mean of the day values from from_s on minus the mean of those before
// (NaN without a day on either side), and the one-sided probability that
// the two sides separate in that direction when the series has no step.
struct StepAt {
  double step = std::nan("");
  bool separated = false;
  double p = 1.0;
};
StepAt StepAtDay(const DaySeries& s, std::int64_t from_s) {
  // Days ascend: the first day from from_s on splits the series.
  const std::size_t split = static_cast<std::size_t>(
      std::lower_bound(s.days.begin(), s.days.end(), from_s) - s.days.begin());
  const std::size_t n = s.y.size();
  StepAt out;
  if (split == 0 || split == n) return out;
  out.step = Mean(s.y, split, n) - Mean(s.y, 0, split);
  out.separated = SeparatedAt(s.y, split, out.step > 0.0);
  out.p = SeparationP(split, n - split) / 2.0;
  return out;
}

// True when P_el steps with a Q_u finding from its onset (sensor_residuals.h):
// the loss is in the light both outputs share, not in the heat meter. *why
// says what P_el did either way.
bool LightStepsWithIt(const SensorResiduals& r, std::int64_t from_s, std::string* why) {
  const int min_rows = r.options->sensor_step_min_rows;
  auto with_flow = [&r](std::uint32_t i) { return r.capacity_flow_w_k[i] > 0.0; };
  auto with_power = [&r](std::uint32_t i) { return r.p_model_w[i] > 0.0; };
  const StepAt q =
      StepAtDay(DailyLogRatios(r, r.q_meas_w, r.q_model_w, with_flow, min_rows), from_s);
  const StepAt p =
      StepAtDay(DailyLogRatios(r, r.p_meas_w, r.p_model_w, with_power, min_rows), from_s);
  if (!std::isfinite(q.step) || !std::isfinite(p.step)) {
    *why = "no P_el days on both sides of the onset to compare";
    return false;
  }
  const bool with_it = p.separated && (p.step > 0.0) == (q.step > 0.0) && p.p <= r.options->alpha;
  *why = "measured / modelled P_el " + std::string(p.step > 0.0 ? "rises" : "falls") + " by " +
         FixedDecimals(100.0 * std::fabs(std::expm1(p.step)), 1) + " % from that day (Q_u by " +
         FixedDecimals(100.0 * std::fabs(std::expm1(q.step)), 1) + " %, " +
         (q.step > 0.0 ? "up" : "down") + "), " +
         (p.separated ? "days separated, one-sided p = " + PValue(p.p) : "days not separated");
  return with_it;
}

}  // namespace

std::optional<DayStep> TestDayStep(const DaySeries& s, double alpha) {
  const std::vector<double>& y = s.y;
  const std::size_t n = y.size();
  const std::size_t min_side = 2;
  if (n < 2 * min_side + 1) return std::nullopt;
  DayStep d;
  double best_sse = 0.0;
  for (std::size_t k = min_side; k + min_side <= n; ++k) {
    const double m1 = Mean(y, 0, k), m2 = Mean(y, k, n);
    double sse = 0.0;
    for (std::size_t j = 0; j < n; ++j) sse += std::pow(y[j] - (j < k ? m1 : m2), 2);
    if (d.split == 0 || sse < best_sse) {
      d.split = k;
      best_sse = sse;
    }
  }
  const std::size_t splits = n - 2 * min_side + 1;
  d.before = Mean(y, 0, d.split);
  d.after = Mean(y, d.split, n);
  d.separated = SeparatedAt(y, d.split, d.after > d.before);
  d.p = std::min(1.0, SeparationP(d.split, n - d.split) * static_cast<double>(splits));
  d.beats_line = best_sse < LineSse(y);
  d.found = d.separated && d.beats_line && d.p <= alpha;
  return d;
}

DaySeries DailyMedians(const SensorResiduals& r, const std::function<bool(std::uint32_t)>& keep,
                       const std::function<double(std::uint32_t)>& x, int min_rows) {
  std::map<std::int64_t, std::vector<double>> by_day;
  for (std::uint32_t i : r.rows) {
    if (!keep(i)) continue;
    const double v = x(i);
    if (std::isfinite(v)) by_day[r.day_s[i]].push_back(v);
  }
  DaySeries s;
  for (auto& [day, v] : by_day) {
    if (v.size() < static_cast<std::size_t>(min_rows)) continue;
    s.days.push_back(day);
    s.y.push_back(Median(std::move(v)));
  }
  return s;
}

DaySeries DailyLogRatios(const SensorResiduals& r, const std::vector<double>& meas,
                         const std::vector<double>& model,
                         const std::function<bool(std::uint32_t)>& keep, int min_rows) {
  struct Sums {
    double mm = 0.0, pp = 0.0;
    int n = 0;
  };
  std::map<std::int64_t, Sums> by_day;
  for (std::uint32_t i : r.rows) {
    if (!keep(i)) continue;
    const double m = meas[i], p = model[i];
    if (!std::isfinite(m) || !std::isfinite(p)) continue;
    Sums& s = by_day[r.day_s[i]];
    s.mm += m * p;
    s.pp += p * p;
    ++s.n;
  }
  DaySeries out;
  for (const auto& [day, s] : by_day) {
    if (s.n < min_rows || !(s.pp > 0.0) || !(s.mm > 0.0)) continue;
    out.days.push_back(day);
    out.y.push_back(std::log(s.mm / s.pp));
  }
  return out;
}

FaultFit FitFault(const SensorResiduals& r, std::int64_t from_s,
                  const std::function<double(std::uint32_t)>& x,
                  const std::function<double(std::uint32_t)>& y) {
  double xx = 0.0, xy = 0.0, yy = 0.0;
  std::size_t n = 0;
  for (std::uint32_t i : r.rows) {
    if (!(r.capacity_flow_w_k[i] > 0.0) || r.day_s[i] < from_s) continue;
    const double xi = x(i), yi = y(i);
    if (!std::isfinite(xi) || !std::isfinite(yi)) continue;
    xx += xi * xi;
    xy += xi * yi;
    yy += yi * yi;
    ++n;
  }
  FaultFit fit;
  if (n == 0) return fit;
  // Σ (y − g·x)² = Σy² − (Σxy)²/Σx² at g = Σxy/Σx².
  fit.g = xx > 0.0 ? xy / xx : 0.0;
  const double sse = xx > 0.0 ? yy - xy * xy / xx : yy;
  fit.mse = std::max(0.0, sse) / static_cast<double>(n);
  return fit;
}

SensorFinding FindingFrom(const Series& data, std::string channel, std::string kind,
                          std::int64_t from_s, std::string from, double size) {
  SensorFinding f;
  f.channel = std::move(channel);
  f.kind = std::move(kind);
  f.from_s = from_s;
  f.from = std::move(from);
  f.size = size;
  for (std::size_t i = 0; i < data.size(); ++i) {
    if (data.time_s[i] >= from_s) ++f.rows;
  }
  f.share = data.size() > 0 ? static_cast<double>(f.rows) / static_cast<double>(data.size()) : 0.0;
  return f;
}

std::optional<ResidualFinding> CheckOffsetStep(const SensorResiduals& r, const Progress& progress) {
  const DiagnosisOptions& o = *r.options;
  // Rows with flow whose sensitivity is positive (ṁ·c_p above the model's
  // loss per K of inlet: every row but a trickle).
  auto sensitive = [&r](std::uint32_t i) {
    return r.capacity_flow_w_k[i] > 0.0 && r.inlet_offset_w_k[i] > 0.0;
  };
  auto per_kelvin = [&r](std::uint32_t i) {
    return (r.q_model_w[i] - r.q_meas_w[i]) / r.inlet_offset_w_k[i];
  };
  const DaySeries s = DailyMedians(r, sensitive, per_kelvin, o.sensor_step_min_rows);
  const std::optional<DayStep> d = TestDayStep(s, o.alpha);
  if (!d) return std::nullopt;
  const double step_k = d->after - d->before;
  const std::string from = SolarDate(s.days[d->split], r.offset_s);
  progress("sensor step test: Q_u residual per K of inlet offset steps by " +
           FixedDecimals(step_k, 2) + " K on " + from +
           (d->separated ? " (days separated" : " (days not separated") + ", p = " + PValue(d->p) +
           (d->beats_line ? ", better than a drift)" : ", a drift fits as well)"));
  if (!d->found || std::fabs(step_k) < o.min_temperature_offset_k) return std::nullopt;
  ResidualFinding out;
  SensorFinding& f = out.finding;
  f = FindingFrom(*r.data, step_k > 0.0 ? "t_in_c" : "t_out_c", "offset_step", s.days[d->split],
                  from, std::fabs(step_k));
  f.detail =
      "from " + f.from + " on the measured Q_u is " + FixedDecimals(std::fabs(step_k), 2) +
      " K × (ṁ·c_p + ∂Q_u/∂T_in) " + (step_k > 0.0 ? "below" : "above") +
      " what the model fitted on all days predicts, on every day after and on none before (p = " +
      PValue(d->p) + " over " + std::to_string(s.y.size()) + " days): the " +
      (step_k > 0.0 ? "inlet temperature reads high (or the outlet low)"
                    : "outlet temperature reads high (or the inlet low)") +
      " by about that much";
  // Its fault model from the onset: Q_model − Q_meas = (ṁ·c_p + ∂Q_u/∂T_in)·δ.
  out.explains = "q_th_w";
  out.fault_x = [](const SensorResiduals& m, std::uint32_t i) { return m.inlet_offset_w_k[i]; };
  out.fault_y = [](const SensorResiduals& m, std::uint32_t i) {
    return m.q_model_w[i] - m.q_meas_w[i];
  };
  return out;
}

std::vector<SensorFinding> FindResidualSensorFaults(const Series& data, const Split& split,
                                                    const Plant& plant, const ModelSpec& base,
                                                    const ParamVector& start,
                                                    const DiagnosisOptions& options,
                                                    const Progress& progress,
                                                    int* identifications) {
  ++*identifications;
  const std::optional<SensorResiduals> r = FitAllDays(data, split, plant, base, start, options);
  if (!r) return {};
  std::vector<ResidualFinding> found;
  for (const ResidualSensorCheck& check : ResidualSensorChecks()) {
    std::optional<ResidualFinding> f = check(*r, progress);
    if (!f) continue;
    if (f->explains == "q_th_w") {
      std::string why;
      const bool light = LightStepsWithIt(*r, f->finding.from_s, &why);
      progress(
          "sensor checks: " + f->finding.channel + " " + f->finding.kind + " from " +
          f->finding.from + ": " + why +
          (light ? ": dropped, the light both outputs share changed, not the heat meter" : ""));
      if (light) continue;
    }
    found.push_back(std::move(*f));
  }
  // Each fault model fitted on the model of the days before the earliest
  // onset of the findings that explain the same residual: its size, and the
  // mean square by which they compete (NaN: no fault model).
  std::map<std::string, std::vector<std::size_t>> groups;  // by the residual they explain
  for (std::size_t k = 0; k < found.size(); ++k) {
    if (found[k].fault_x) groups[found[k].explains].push_back(k);
  }
  std::vector<double> mse(found.size(), std::nan(""));
  for (const auto& [explains, group] : groups) {
    std::int64_t first_onset = found[group.front()].finding.from_s;
    for (std::size_t j : group) first_onset = std::min(first_onset, found[j].finding.from_s);
    ++*identifications;
    const std::optional<SensorResiduals> before =
        FitAllDays(data, split, plant, base, start, options, first_onset);
    const SensorResiduals& model = before ? *before : *r;
    const std::string on = before ? "the model fitted before " + SolarDate(first_onset, r->offset_s)
                                  : "the model fitted on all the days";
    for (std::size_t j : group) {
      ResidualFinding& f = found[j];
      const FaultFit fit = FitFault(
          model, f.finding.from_s, [&](std::uint32_t i) { return f.fault_x(model, i); },
          [&](std::uint32_t i) { return f.fault_y(model, i); });
      mse[j] = fit.mse;
      if (!std::isfinite(fit.g)) continue;
      f.finding.size = std::fabs(fit.g);
      f.finding.detail += "; its size against " + on + ": " + SensorSizeText(f.finding);
      progress("sensor checks: " + f.finding.channel + " " + f.finding.kind + " against " + on +
               ": size " + SensorSizeText(f.finding) + ", RMS " +
               FixedDecimals(std::sqrt(fit.mse), 1) + " from its onset");
    }
  }
  std::vector<SensorFinding> out;
  for (std::size_t k = 0; k < found.size(); ++k) {
    const ResidualFinding& f = found[k];
    std::size_t better = k;
    for (std::size_t j = 0; j < found.size(); ++j) {
      // (A comparison with NaN, a finding without a fault model, is false.)
      if (j != k && found[j].explains == f.explains && mse[j] < mse[k]) {
        better = j;
      }
    }
    if (better != k) {
      progress("sensor checks: " + f.finding.channel + " " + f.finding.kind + " dropped, " +
               found[better].finding.channel + " " + found[better].finding.kind + " explains the " +
               f.explains + " residual better from its onset (RMS " +
               FixedDecimals(std::sqrt(mse[better]), 1) + " against " +
               FixedDecimals(std::sqrt(mse[k]), 1) + ")");
    } else {
      out.push_back(f.finding);
    }
  }
  return out;
}

}  // namespace pvtwin::diagnosis_stages
