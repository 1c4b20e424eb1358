#include "core/effects/transport_delay.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/common/text.h"

namespace pvtwin {

namespace {

// The outlet sensor sees the fluid that left the collector τ earlier,
// T_out(t − τ) (linear interpolation between row means), cooled on the way by
// the pipe's loss U_pipe·A to ambient (plug flow through a pipe with uniform
// loss, Duffie & Beckman 10.3):
//   T_out,sensor = T_amb + (T_out(t − τ) − T_amb)·exp(−U_pipe·A/(ṁ·c_p)),
// and the measured heat is ṁ·c_p·(T_out,sensor − T_in).
void SensorBehindPipe(const Drivers& d, const ParamVector& p, RunInputs* run, SimOutputs* out) {
  const double delay_s = ParamOf(p, Param::kTransportDelayS);
  const double pipe_w_k = ParamOf(p, Param::kUPipeWM2K) * ParamOf(p, Param::kAreaM2);
  const double cp = d.plant.fluid_cp_j_kgk;
  const std::size_t n = d.size();
  if (n == 0 || !(delay_s > 0.0 || pipe_w_k > 0.0)) return;
  std::vector<double>& t_out = run->Scratch();
  t_out = out->t_out_c;  // undelayed copy
  for (std::size_t i = 0; i < n; ++i) {
    if (!d.usable[i]) continue;
    const double t_seen = static_cast<double>(d.time_s[i]) - delay_s;
    std::size_t j = i;
    while (j > 0 && d.time_s[j] > t_seen && d.usable[j - 1] && !d.restart[j]) --j;
    double t_sensor = t_out[j];
    if (j < i && static_cast<double>(d.time_s[j]) < t_seen) {
      const double w = (t_seen - static_cast<double>(d.time_s[j])) /
                       static_cast<double>(d.time_s[j + 1] - d.time_s[j]);
      t_sensor = t_out[j] + w * (t_out[j + 1] - t_out[j]);
    }
    if (d.mdot_kg_s[i] > 0.0) {
      t_sensor = run->t_amb_c[i] +
                 (t_sensor - run->t_amb_c[i]) * std::exp(-pipe_w_k / (d.mdot_kg_s[i] * cp));
      out->q_th_w[i] = d.mdot_kg_s[i] * cp * (t_sensor - d.t_in_c[i]);
    }
    out->t_out_c[i] = t_sensor;
  }
}

const ModelExtension& Extension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "transport_delay";
    e.variant_order = 1;
    e.params = {Param::kTransportDelayS, Param::kUPipeWM2K};
    e.transform_outputs = SensorBehindPipe;
    return e;
  }();
  return kExtension;
}

// Rate of change of the base model's outlet temperature, K per minute.
std::vector<double> Signature(const Drivers& d, const SimOutputs& base) {
  if (base.t_out_c.size() == d.size()) return RatePerMinute(d, base.t_out_c);
  return std::vector<double>(d.size(), std::numeric_limits<double>::quiet_NaN());
}

// A dead time shows as a lag: the measured heat follows the changes of the
// model without the delay some rows later, at about the fitted τ (within
// one row or half of it). A pipe loss alone (or a fit that shifts a bias)
// leaves the changes in step. A τ below half the row step cannot show as a
// lag: the check then has nothing to say.
SignatureCheck MeasuredHeatLags(const SignatureData& d) {
  const double step_s = RowStepS(*d.drivers);
  const double tau_s = ParamOf(*d.params, Param::kTransportDelayS);
  const double expected = tau_s / step_s;
  const int max_lag = std::max(3, static_cast<int>(std::ceil(2.0 * expected)) + 1);
  const LagFit lag = BestLag(*d.drivers, *d.rows, *d.q_th_meas_w, d.before->q_th_w, 0, max_lag);
  SignatureCheck c;
  if (expected < 0.5) {
    c.sentence = "the fitted τ = " + FixedDecimals(tau_s, 0) + " s is below half the " +
                 FixedDecimals(step_s, 0) + " s row step: no lag the data can show";
    return c;
  }
  if (lag.pairs == 0) {
    c.shown = false;
    c.sentence = "too few unbroken held-out rows to see a lag of the measured heat";
    return c;
  }
  c.shown =
      lag.lag_rows >= 1 && std::fabs(lag.lag_rows - expected) <= std::max(1.0, 0.5 * expected);
  c.sentence = "the measured Q_u's changes follow the model's " +
               FixedDecimals(lag.lag_rows * step_s, 0) + " s later (correlation " +
               FixedDecimals(lag.corr_at_lag, 2) + ", in step " +
               FixedDecimals(lag.corr_at_zero, 2) + "), fitted τ = " + FixedDecimals(tau_s, 0) +
               " s" + (c.shown ? "" : ": no lag that matches the dead time");
  return c;
}

}  // namespace

const EffectModule& TransportDelayEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = "transport_delay";
    m.physics =
        "The outlet sensor sits behind a pipe: it sees the fluid that left the collector "
        "τ earlier (plug flow dead time), cooled towards ambient on the way, "
        "T_sensor = T_amb + (T_out(t − τ) − T_amb)·exp(−U_pipe·A/(ṁ·c_p)) "
        "(exponential decay of a plug in a pipe of loss UA, Duffie & Beckman 10.3). "
        "Q_u is then ṁ·c_p·(T_sensor − T_in): lagging at pump starts and irradiance "
        "steps, lower than the collector's output at low flow.";
    m.source = "Duffie & Beckman, Solar Engineering of Thermal Processes, 10.3 (pipe losses)";
    m.params = {Param::kTransportDelayS, Param::kUPipeWM2K};
    m.typical_truth = {{Param::kTransportDelayS, 120.0}, {Param::kUPipeWM2K, 1.0}};
    m.signature = "rate of change of the base model's outlet temperature, K per minute";
    m.advice =
        "Model the pipe to the outlet sensor (+transport_delay), or move the sensor to "
        "the collector outlet and insulate the pipe.";
    m.extension = &Extension();
    m.signature_values = Signature;
    m.shows_signature = MeasuredHeatLags;
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
