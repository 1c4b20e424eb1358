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

double CubicAt(const std::vector<std::int64_t>& time_s, const std::vector<double>& v, double t_s) {
  const std::size_t n = time_s.size();
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  if (t_s <= static_cast<double>(time_s.front())) return v.front();
  if (t_s >= static_cast<double>(time_s.back())) return v.back();
  const auto it = std::upper_bound(time_s.begin(), time_s.end(), t_s, [](double t, std::int64_t x) {
    return t < static_cast<double>(x);
  });
  const std::size_t k = static_cast<std::size_t>(it - time_s.begin()) - 1;
  const double t0 = static_cast<double>(time_s[k]), t1 = static_cast<double>(time_s[k + 1]);
  const double h = t1 - t0, u = (t_s - t0) / h;
  const double v0 = v[k], v1 = v[k + 1];
  const double linear = v0 + u * (v1 - v0);
  if (k == 0 || k + 2 >= n) return linear;
  const double vm = v[k - 1], vp = v[k + 2];
  if (!std::isfinite(vm) || !std::isfinite(vp) || !std::isfinite(linear)) return linear;
  const double m0 = (v1 - vm) / static_cast<double>(time_s[k + 1] - time_s[k - 1]) * h;
  const double m1 = (vp - v0) / static_cast<double>(time_s[k + 2] - time_s[k]) * h;
  const double u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * v0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * v1 +
         (u3 - u2) * m1;
}

namespace {

// Other-form truth: the collector saw at t the weather the logger stamped
// t + Δt(t), cubic between rows; irradiance and wind stay ≥ 0. Sun geometry
// (and a logged angle of incidence) follows the collector clock.
void DriftingWeatherClock(const OtherTruthContext&, Series* physics) {
  const std::vector<std::int64_t>& t = physics->time_s;
  if (t.empty()) return;
  const DriftingClock& clock = kOtherTruthClock;
  for (Channel c : {Channel::kGPoaWM2, Channel::kGPoaDiffuseWM2, Channel::kGhiWM2, Channel::kDhiWM2,
                    Channel::kTAmbC, Channel::kWindMS, Channel::kTSkyC, Channel::kLwDownWM2,
                    Channel::kTBackC}) {
    if (!physics->Has(c)) continue;
    const std::vector<double> logged = (*physics)[c];
    const bool non_negative = c != Channel::kTAmbC && c != Channel::kTSkyC && c != Channel::kTBackC;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double days = static_cast<double>(t[i] - t.front()) / 86400.0;
      const double offset_s = clock.offset_s + clock.drift_s_per_day * days;
      const double v = CubicAt(t, logged, static_cast<double>(t[i]) + offset_s);
      (*physics)[c][i] = non_negative ? std::max(0.0, v) : v;
    }
  }
}

const OtherFormTruth& OtherTruth() {
  static const OtherFormTruth kTruth = [] {
    OtherFormTruth t;
    t.form =
        "The weather logger runs Δt(t) = 97 s + 2 s/day·(t − t_first) ahead (no whole number "
        "of 60-s rows, drifting 23 ppm); the plant's weather at t is the logged weather at "
        "t + Δt(t), cubic (Catmull–Rom) between rows. The candidate is a constant offset, "
        "linear between rows.";
    t.source = "IEC 61724-1 (time-stamp accuracy of monitoring loggers); Catmull & Rom 1974";
    t.weather = DriftingWeatherClock;
    return t;
  }();
  return kTruth;
}

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

// "The weather logger's clock is 97 s off: …".
std::string OffsetAdvice(const ModelSpec&, const ParamVector& p, const Plant&) {
  return "The weather logger's clock is " +
         FixedDecimals(std::fabs(ParamOf(p, Param::kClockOffsetS)), 0) +
         " s off the collector logger's: synchronise both (NTP) and check their time zones.";
}
}  // namespace

const EffectModule& ClockOffsetEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = EffectName(Effect::kClockOffset);
    m.physics =
        "The weather station's logger clock differs from the collector logger's: the "
        "weather the collector saw at time t is the weather row stamped t + Δt. The "
        "model interpolates the weather drivers (irradiance, ambient and back "
        "temperature, wind, sky) linearly at t + Δt; sun geometry follows the "
        "collector clock. Residuals follow the rate of change of irradiance with a sign "
        "that flips between morning and afternoon.";
    m.source = "IEC 61724-1 (PV performance monitoring: synchronised time stamps of all channels)";
    m.params = EffectParams(Effect::kClockOffset);
    m.typical_truth = {{Param::kClockOffsetS, 300.0}};
    // A logger restarted without time synchronisation, a time zone changed.
    m.begins_in_operation = true;
    m.signature = "rate of change of the absorbed irradiance, W/m² per minute";
    m.advice =
        "Synchronise the loggers' clocks (NTP) and check their time zones; until then "
        "model the offset with +clock_offset.";
    m.extension = &Extension();
    m.advice_for = OffsetAdvice;
    m.signature_values = Signature;
    m.shows_signature = ElectricityLeadsOrLags;
    m.other_truth = &OtherTruth();
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
