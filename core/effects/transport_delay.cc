#include "core/effects/transport_delay.h"

#include <cmath>
#include <limits>

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
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
