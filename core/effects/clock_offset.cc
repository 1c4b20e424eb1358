#include "core/effects/clock_offset.h"

#include <cmath>
#include <limits>

namespace pvtwin {

void ShiftInTime(const Drivers& d, const double* v, double offset_s, std::vector<double>* out) {
  const std::size_t n = d.size();
  out->resize(n);
  std::size_t j = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(d.time_s[i]) + offset_s;
    while (j + 1 < n && static_cast<double>(d.time_s[j + 1]) <= t) ++j;
    while (j > 0 && static_cast<double>(d.time_s[j]) > t) --j;
    const double tj = static_cast<double>(d.time_s[j]);
    if (t <= tj || j + 1 >= n) {
      (*out)[i] = v[j];
      continue;
    }
    const double w = (t - tj) / static_cast<double>(d.time_s[j + 1] - d.time_s[j]);
    (*out)[i] = v[j] + w * (v[j + 1] - v[j]);
  }
}

namespace {

// The weather the collector saw at t is the weather row stamped t + Δt:
// irradiance, ambient, back and sky temperature and wind interpolated at
// t + Δt; sun geometry follows the collector clock.
void ShiftTheWeather(const Drivers& d, const ParamVector& p, RunInputs* run) {
  const double offset_s = ParamOf(p, Param::kClockOffsetS);
  for (const double** field : {&run->g_abs_w_m2, &run->g_beam_w_m2, &run->g_poa_w_m2, &run->t_amb_c,
                               &run->t_back_c, &run->t_sky_k4}) {
    std::vector<double>& shifted = run->Scratch();
    ShiftInTime(d, *field, offset_s, &shifted);
    *field = shifted.data();
  }
  // ln v is −inf in calm: interpolate v itself.
  const std::size_t n = run->n;
  std::vector<double>& v = run->Scratch();
  std::vector<double>& shifted = run->Scratch();
  v.resize(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = std::exp(run->ln_wind[i]);
  ShiftInTime(d, v.data(), offset_s, &shifted);
  const bool reads_wind = d.spec.ReadsWind();
  for (std::size_t i = 0; i < n; ++i) {
    v[i] =
        run->ln_wind[i] == 0.0 && !reads_wind
            ? 0.0
            : (shifted[i] > 0.0 ? std::log(shifted[i]) : -std::numeric_limits<double>::infinity());
  }
  run->ln_wind = v.data();
}

const ModelExtension& Extension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "clock_offset";
    e.variant_order = 6;
    e.params = {Param::kClockOffsetS};
    e.driver_stage = 0;
    e.transform_drivers = ShiftTheWeather;
    return e;
  }();
  return kExtension;
}

std::vector<double> Signature(const Drivers& d, const SimOutputs&) {
  return RatePerMinute(d, d.g_abs_w_m2);
}

}  // namespace

const EffectModule& ClockOffsetEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = "clock_offset";
    m.physics =
        "The weather station's logger clock differs from the collector logger's: the "
        "weather the collector saw at time t is the weather row stamped t + Δt. The "
        "model interpolates the weather drivers (irradiance, ambient and back "
        "temperature, wind, sky) linearly at t + Δt; sun geometry follows the "
        "collector clock. Residuals follow the rate of change of irradiance with a sign "
        "that flips between morning and afternoon.";
    m.source = "IEC 61724-1 (PV performance monitoring: synchronised time stamps of all channels)";
    m.params = {Param::kClockOffsetS};
    m.typical_truth = {{Param::kClockOffsetS, 300.0}};
    m.signature = "rate of change of the absorbed irradiance, W/m² per minute";
    m.advice =
        "Synchronise the loggers' clocks (NTP) and check their time zones; until then "
        "model the offset with +clock_offset.";
    m.extension = &Extension();
    m.signature_values = Signature;
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
