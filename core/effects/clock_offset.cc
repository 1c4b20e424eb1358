#include "core/effects/clock_offset.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/common/text.h"

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

// A clock offset shifts the electricity against the weather: measured
// P_el's changes follow the model's without the offset at k = −Δt/step rows
// (the weather at collector time t is the row stamped t + Δt). Shown when
// the best lag has the fitted offset's sign and size (within one row or
// half of it).
SignatureCheck ElectricityLeadsOrLags(const SignatureData& d) {
  const double step_s = RowStepS(*d.drivers);
  const double offset_s = ParamOf(*d.params, Param::kClockOffsetS);
  const double expected = -offset_s / step_s;
  const int reach = std::max(3, static_cast<int>(std::ceil(2.0 * std::fabs(expected))) + 1);
  const LagFit lag = BestLag(*d.drivers, *d.rows, *d.p_el_meas_w, d.before->p_el_w, -reach, reach);
  SignatureCheck c;
  if (lag.pairs == 0) {
    c.shown = false;
    c.sentence = "too few unbroken held-out rows to see a time shift of P_el";
    return c;
  }
  c.shown = lag.lag_rows != 0 && (lag.lag_rows > 0) == (expected > 0) &&
            std::fabs(lag.lag_rows - expected) <= std::max(1.0, 0.5 * std::fabs(expected));
  c.sentence = "the measured P_el's changes are shifted by " +
               FixedDecimals(-lag.lag_rows * step_s, 0) + " s against the model's (correlation " +
               FixedDecimals(lag.corr_at_lag, 2) + ", unshifted " +
               FixedDecimals(lag.corr_at_zero, 2) + "), fitted Δt = " + FixedDecimals(offset_s, 0) +
               " s" + (c.shown ? "" : ": no shift that matches the offset");
  return c;
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
    m.shows_signature = ElectricityLeadsOrLags;
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
