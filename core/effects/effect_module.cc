#include "core/effects/effect_module.h"

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

double UnitDraw(std::uint64_t seed, std::int64_t key) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (static_cast<std::uint64_t>(key) + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

}  // namespace pvtwin
