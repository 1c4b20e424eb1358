// A sensor fault that the sensor checks of the monitor cannot see because it
// is plausible on every row: the inlet temperature reading high (or the
// outlet low) by a constant from one day on. The heat meter multiplies flow
// by the logged T_out − T_in, so from that day the measured Q_u is low by
// ṁ·c_p·ΔT while the pump runs, and a model fitted on all the days leaves a
// step in its Q_u residual per unit of capacity flow, (Q_pred − Q_meas) /
// (ṁ·c_p) in K, that stays from that day on.
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
#include <map>

#include "core/common/calendar.h"
#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

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

}  // namespace

std::optional<SensorFinding> FindInletOffsetStep(const Series& data, const Split& split,
                                                 const Plant& plant, const ModelSpec& base,
                                                 const ParamVector& start,
                                                 const DiagnosisOptions& options,
                                                 const Progress& progress) {
  Part all;
  std::string why;
  if (!PreparePart(data, plant, base, split.data_start_s, split.cleanings, &all, &why)) {
    return std::nullopt;
  }
  // The final model's parameters as they are, in the ranges they were found in (no re-fit).
  DiagnosisOptions ranges = options;
  ranges.refit_in_physical_ranges = false;
  const IdentSummary fit = IdentifyInRanges(all.drivers, all.meas, start, ranges).fit;
  if (!fit.ok) return std::nullopt;
  SimOutputs sim;
  Simulate(all.drivers, fit.params, &sim);
  std::map<std::int64_t, std::vector<double>> by_day;
  for (std::uint32_t i : all.meas.rows) {
    const double w = all.drivers.mdot_kg_s[i] * plant.fluid_cp_j_kgk;
    const double r = sim.q_th_w[i] - all.meas.q_th_w[i];
    if (!(w > 0.0) || !std::isfinite(r)) continue;
    by_day[SolarDayStartS(all.drivers.time_s[i], split.offset_s)].push_back(r / w);
  }
  std::vector<std::int64_t> days;
  std::vector<double> y;
  for (auto& [day, x] : by_day) {
    if (x.size() < static_cast<std::size_t>(options.sensor_step_min_rows)) continue;
    days.push_back(day);
    y.push_back(Median(std::move(x)));
  }
  const std::size_t n = y.size();
  const std::size_t min_side = 2;
  if (n < 2 * min_side + 1) return std::nullopt;
  std::size_t best = 0;
  double best_sse = 0.0;
  for (std::size_t s = min_side; s + min_side <= n; ++s) {
    const double m1 = Mean(y, 0, s), m2 = Mean(y, s, n);
    double sse = 0.0;
    for (std::size_t k = 0; k < n; ++k) sse += std::pow(y[k] - (k < s ? m1 : m2), 2);
    if (best == 0 || sse < best_sse) {
      best = s;
      best_sse = sse;
    }
  }
  const std::size_t splits = n - 2 * min_side + 1;
  const double m1 = Mean(y, 0, best), m2 = Mean(y, best, n);
  const double lo1 = *std::min_element(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(best));
  const double hi1 = *std::max_element(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(best));
  const double lo2 = *std::min_element(y.begin() + static_cast<std::ptrdiff_t>(best), y.end());
  const double hi2 = *std::max_element(y.begin() + static_cast<std::ptrdiff_t>(best), y.end());
  const bool separated = m2 > m1 ? lo2 > hi1 : hi2 < lo1;
  const double p = std::min(1.0, SeparationP(best, n - best) * static_cast<double>(splits));
  const double step_k = m2 - m1;
  const bool step_beats_line = best_sse < LineSse(y);
  progress("sensor step test: Q_u residual per capacity flow steps by " + FixedDecimals(step_k, 2) +
           " K on " + SolarDate(days[best], split.offset_s) +
           (separated ? " (days separated" : " (days not separated") + ", p = " + PValue(p) +
           (step_beats_line ? ", better than a drift)" : ", a drift fits as well)"));
  if (!separated || !step_beats_line || p > options.alpha ||
      std::fabs(step_k) < options.min_temperature_offset_k) {
    return std::nullopt;
  }
  SensorFinding f;
  f.channel = step_k > 0.0 ? "t_in_c" : "t_out_c";
  f.kind = "offset_step";
  f.from_s = days[best];
  f.from = SolarDate(days[best], split.offset_s);
  f.size = std::fabs(step_k);
  for (std::size_t i = 0; i < data.size(); ++i) {
    if (data.time_s[i] >= days[best]) ++f.rows;
  }
  f.share = data.size() > 0 ? static_cast<double>(f.rows) / static_cast<double>(data.size()) : 0.0;
  f.detail =
      "from " + f.from + " on the measured Q_u is " + FixedDecimals(std::fabs(step_k), 2) +
      " K × ṁ·c_p " + (step_k > 0.0 ? "below" : "above") +
      " what the model fitted on all days predicts, on every day after and on none before (p = " +
      PValue(p) + " over " + std::to_string(n) + " days): the " +
      (step_k > 0.0 ? "inlet temperature reads high (or the outlet low)"
                    : "outlet temperature reads high (or the inlet low)") +
      " by about that much";
  return f;
}

}  // namespace pvtwin::diagnosis_stages
