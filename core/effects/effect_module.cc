#include "core/effects/effect_module.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pvtwin {

std::vector<double> RatePerMinute(const Drivers& d, const std::vector<double>& v) {
  const std::size_t n = d.size();
  std::vector<double> out(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (d.restart[i] || d.restart[i + 1]) continue;
    const double dt_s = static_cast<double>(d.time_s[i + 1] - d.time_s[i - 1]);
    if (dt_s > 0.0) out[i] = (v[i + 1] - v[i - 1]) / dt_s * 60.0;
  }
  return out;
}

double RowStepS(const Drivers& d) {
  std::vector<std::int64_t> steps;
  for (std::size_t i = 1; i < d.size(); ++i) {
    if (d.time_s[i] > d.time_s[i - 1]) steps.push_back(d.time_s[i] - d.time_s[i - 1]);
  }
  if (steps.empty()) return 60.0;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return static_cast<double>(steps[steps.size() / 2]);
}

LagFit BestLag(const Drivers& d, const std::vector<std::uint32_t>& rows,
               const std::vector<double>& meas, const std::vector<double>& pred, int min_lag,
               int max_lag) {
  const std::size_t n = d.size();
  const auto step = static_cast<std::int64_t>(RowStepS(d));
  // run[i]: rows i−run[i] … i are one unbroken stretch.
  std::vector<int> run(n, 0);
  for (std::size_t i = 1; i < n; ++i) {
    const bool joined =
        !d.restart[i] && d.usable[i] && d.usable[i - 1] && d.time_s[i] - d.time_s[i - 1] == step;
    run[i] = joined ? run[i - 1] + 1 : 0;
  }
  auto correlation = [&](int k, std::size_t* pairs) {
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    std::size_t m = 0;
    for (std::uint32_t i : rows) {
      const int reach = std::max(k, 0) + 1;
      if (run[i] < reach || (k < 0 && (i + static_cast<std::size_t>(-k) >= n ||
                                       run[i + static_cast<std::size_t>(-k)] < -k + 1))) {
        continue;
      }
      const std::size_t j = static_cast<std::size_t>(static_cast<std::int64_t>(i) - k);
      const double x = meas[i] - meas[i - 1], y = pred[j] - pred[j - 1];
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y;
      ++m;
    }
    *pairs = m;
    if (m < 30) return 0.0;
    const double cov = sxy - sx * sy / m, vx = sxx - sx * sx / m, vy = syy - sy * sy / m;
    return vx > 0.0 && vy > 0.0 ? cov / std::sqrt(vx * vy) : 0.0;
  };
  LagFit fit;
  fit.corr_at_zero = correlation(0, &fit.pairs);
  if (fit.pairs == 0) return fit;
  fit.corr_at_lag = fit.corr_at_zero;
  for (int k = min_lag; k <= max_lag; ++k) {
    std::size_t pairs = 0;
    const double c = correlation(k, &pairs);
    if (pairs >= 30 && c > fit.corr_at_lag) {
      fit.corr_at_lag = c;
      fit.lag_rows = k;
    }
  }
  return fit;
}

double UnitDraw(std::uint64_t seed, std::int64_t key) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (static_cast<std::uint64_t>(key) + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

}  // namespace pvtwin
