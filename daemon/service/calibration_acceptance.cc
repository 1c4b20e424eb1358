#include "daemon/service/calibration_acceptance.h"

#include <cmath>
#include <cstdio>
#include <map>

#include "core/fit/identification.h"
#include "core/model/thermal_model.h"

namespace pvtwin::cli {

namespace {

// The collector's and the per-m² figure side by side, unrounded (six
// significant digits), so that a reason never reads "12.00 W exceeds 12.00 W".
std::string Watts(double w_m2, double area_m2) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.6g W (%.6g W/m²)", w_m2 * area_m2, w_m2);
  return buf;
}

}  // namespace

AcceptanceDecision DecideCalibration(double fresh_w_m2, std::optional<double> current_w_m2,
                                     const std::vector<std::string>& at_bounds, double area_m2,
                                     double tolerance_w_m2) {
  std::string bounds;
  for (const std::string& name : at_bounds) bounds += (bounds.empty() ? "" : ", ") + name;
  const std::string bounds_note = at_bounds.empty()
                                      ? ""
                                      : "; " + std::to_string(at_bounds.size()) +
                                            (at_bounds.size() == 1 ? " parameter" : " parameters") +
                                            " at bounds (" + bounds + ")";
  AcceptanceDecision d;
  if (!current_w_m2) {
    d.accept = true;
    d.reason = "first parameters of this database" + bounds_note;
    return d;
  }
  const bool tolerate = tolerance_w_m2 > 0.0;
  const double limit_w_m2 = *current_w_m2 + (tolerate ? tolerance_w_m2 : 0.0);
  d.accept = fresh_w_m2 <= limit_w_m2;
  const std::string comparison = "held-out MAE (P_el + Q_u) " + Watts(fresh_w_m2, area_m2) +
                                 (d.accept ? " ≤ " : " exceeds ") + "the current " +
                                 Watts(*current_w_m2, area_m2) +
                                 (tolerate ? " + " + Watts(tolerance_w_m2, area_m2) +
                                                 " (the standard error of the hourly differences)"
                                           : "");
  d.reason = comparison + bounds_note + (d.accept ? "" : "; parameters kept");
  return d;
}

bool IsInformativeRow(const Series& s, std::size_t i) {
  auto value = [&s, i](Channel c) { return s.Has(c) ? s[c][i] : std::nan(""); };
  if (value(Channel::kValid) == 0.0) return false;
  if (!(value(Channel::kMdotKgS) > 1e-4)) return false;
  const double g = s.Has(Channel::kGPoaWM2) ? value(Channel::kGPoaWM2) : value(Channel::kGhiWM2);
  if (!(g >= 200.0)) return false;
  const bool heat = std::isfinite(value(Channel::kQThW)) ||
                    (std::isfinite(value(Channel::kTOutC)) && std::isfinite(value(Channel::kTInC)));
  return std::isfinite(value(Channel::kPElW)) && heat;
}

HeldOutChoice ChooseHeldOutDays(const Series& window, std::int64_t end_s, int max_days,
                                std::size_t min_rows, int min_train_days) {
  constexpr std::int64_t kDayS = 86400;
  const std::int64_t first = window.size() ? window.time_s.front() : end_s;
  const int room = static_cast<int>((end_s - first) / kDayS) - min_train_days;
  const int most = std::max(1, std::min(max_days, room));
  HeldOutChoice choice;
  for (int days = 1; days <= most; ++days) {
    choice.days = days;
    choice.informative_rows = 0;
    const std::int64_t from = end_s - days * kDayS;
    for (std::size_t i = 0; i < window.size(); ++i) {
      if (window.time_s[i] >= from && window.time_s[i] < end_s && IsInformativeRow(window, i)) {
        ++choice.informative_rows;
      }
    }
    if (choice.informative_rows >= min_rows) break;
  }
  return choice;
}

double HeldOutDifferenceSe(const Series& test, const Plant& plant, const ModelSpec& spec,
                           const ParamVector& fresh, const ParamVector& current) {
  Drivers drivers;
  std::string error;
  if (!PrepareDrivers(test, plant, spec, &drivers, &error)) return 0.0;
  SimOutputs a, b;
  Simulate(drivers, fresh, &a);
  Simulate(drivers, current, &b);
  const Measurements meas = MakeMeasurements(test, drivers);
  // Per hour: sums of |error| of both outputs for each parameter set.
  struct Hour {
    double fresh = 0.0, current = 0.0;
    int rows = 0;
  };
  std::map<std::int64_t, Hour> hours;
  for (const std::uint32_t i : meas.rows) {
    if (!IsInformativeRow(test, i)) continue;
    Hour& h = hours[test.time_s[i] / 3600];
    h.fresh += std::fabs(a.p_el_w[i] - meas.p_el_w[i]) + std::fabs(a.q_th_w[i] - meas.q_th_w[i]);
    h.current += std::fabs(b.p_el_w[i] - meas.p_el_w[i]) + std::fabs(b.q_th_w[i] - meas.q_th_w[i]);
    ++h.rows;
  }
  std::vector<double> diffs;
  for (const auto& [hour, h] : hours) {
    if (h.rows > 0) diffs.push_back((h.fresh - h.current) / h.rows / plant.area_m2);
  }
  if (diffs.size() < 3) return 0.0;
  double mean = 0.0;
  for (const double d : diffs) mean += d;
  mean /= static_cast<double>(diffs.size());
  double ss = 0.0;
  for (const double d : diffs) ss += (d - mean) * (d - mean);
  const double n = static_cast<double>(diffs.size());
  return std::sqrt(ss / (n - 1.0) / n);
}

}  // namespace pvtwin::cli
