#include <algorithm>
#include <cmath>

#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

namespace {

// The q-quantile of the finite values (nearest rank); NaN when there are none.
double Quantile(std::vector<double> v, double q) {
  std::erase_if(v, [](double x) { return !std::isfinite(x); });
  if (v.empty()) return kNaN;
  const auto k = static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// A driver's value on the objective rows of one part.
std::vector<double> OnRows(const Part& part, double (*value)(const Drivers&, std::size_t)) {
  std::vector<double> out;
  out.reserve(part.meas.rows.size());
  for (std::uint32_t i : part.meas.rows) out.push_back(value(part.drivers, i));
  return out;
}

struct DriverOfModel {
  const char* name;
  double (*value)(const Drivers&, std::size_t);
};

const DriverOfModel kDrivers[] = {
    {"t_in_minus_t_amb_k",
     [](const Drivers& d, std::size_t i) { return d.t_in_c[i] - d.t_amb_c[i]; }},
    {"g_poa_w_m2", [](const Drivers& d, std::size_t i) { return d.g_poa_w_m2[i]; }},
    {"wind_m_s",
     [](const Drivers& d, std::size_t i) {
       return d.wind_m_s.size() == d.size() ? d.wind_m_s[i] : kNaN;
     }},
    {"flow_kg_s", [](const Drivers& d, std::size_t i) { return d.mdot_kg_s[i]; }},
};

// A margin of 10 % of the training span (at least a hundredth of its
// scale) keeps the percentiles' own noise from counting.
double Margin(const Extrapolation& e) {
  return std::max(0.1 * (e.train_high - e.train_low),
                  0.01 * std::max(std::fabs(e.train_low), std::fabs(e.train_high)));
}

bool Outside(const Extrapolation& e, double x) {
  const double margin = Margin(e);
  return x < e.train_low - margin || x > e.train_high + margin;
}

}  // namespace

std::vector<Extrapolation> FindExtrapolation(const BaseFit& base, const DiagnosisOptions& options) {
  std::vector<Extrapolation> out;
  for (const DriverOfModel& driver : kDrivers) {
    const std::vector<double> train = OnRows(base.train, driver.value);
    const std::vector<double> heldout = OnRows(base.heldout, driver.value);
    Extrapolation e;
    e.driver = driver.name;
    e.train_low = Quantile(train, 0.01);
    e.train_high = Quantile(train, 0.99);
    e.heldout_low = Quantile(heldout, 0.01);
    e.heldout_high = Quantile(heldout, 0.99);
    if (!std::isfinite(e.train_low) || !std::isfinite(e.heldout_low)) continue;
    std::size_t outside = 0, n = 0;
    for (const double x : heldout) {
      if (!std::isfinite(x)) continue;
      ++n;
      if (Outside(e, x)) ++outside;
    }
    if (n == 0) continue;
    e.share_outside = static_cast<double>(outside) / static_cast<double>(n);
    if (e.share_outside > options.extrapolation_share) out.push_back(e);
  }
  return out;
}

std::vector<std::uint8_t> RowsInsideTrainingRange(const Drivers& d,
                                                  const std::vector<Extrapolation>& extrapolation) {
  std::vector<std::uint8_t> inside(d.size(), 1);
  for (const Extrapolation& e : extrapolation) {
    const auto driver = std::find_if(std::begin(kDrivers), std::end(kDrivers),
                                     [&e](const DriverOfModel& k) { return e.driver == k.name; });
    if (driver == std::end(kDrivers)) continue;
    for (std::size_t i = 0; i < d.size(); ++i) {
      const double x = driver->value(d, i);
      if (std::isfinite(x) && Outside(e, x)) inside[i] = 0;
    }
  }
  return inside;
}

}  // namespace pvtwin::diagnosis_stages
