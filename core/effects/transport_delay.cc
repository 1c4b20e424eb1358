#include "core/effects/transport_delay.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "core/common/text.h"

namespace pvtwin {

TankStep MixedTankStep(double t0_c, double t_in_c, double t_amb_c, double mdot_kg_s,
                       double cp_j_kgk, double mass_kg, double ua_w_k, double dt_s) {
  const double flow_w_k = std::max(0.0, mdot_kg_s) * cp_j_kgk;
  const double g_w_k = flow_w_k + ua_w_k;
  if (!(g_w_k > 0.0) || !(dt_s > 0.0)) return {t0_c, t0_c};
  const double t_eq_c = (flow_w_k * t_in_c + ua_w_k * t_amb_c) / g_w_k;
  const double a_dt = g_w_k / (mass_kg * cp_j_kgk) * dt_s;
  const double decay = std::exp(-a_dt);
  return {t_eq_c + (t0_c - t_eq_c) * decay, t_eq_c + (t0_c - t_eq_c) * (1.0 - decay) / a_dt};
}

namespace {

// The sensor behind a MixedPipe: it sees the collector's outlet after the
// plug (the fluid that left when the cumulative mass was M_plug less, taken
// at the row's middle) and the tanks; where the pump runs, the measured heat
// is ṁ·c_p·(T_sensor − T_in). A restart (gap) refills the pipe with the
// row's outlet temperature; a standing pump leaves the pipe's fluid where it
// is (it only loses heat). t_out is the collector's outlet (a copy: out's is
// overwritten), mass_end work space of n rows. With `interpolate` the plug's
// exit takes the outlet linearly between the rows' middles (by cumulative
// mass), so that the output moves smoothly with M_plug (a fit needs its
// slope); without, the row the exit falls in.
void PipeToSensor(const Drivers& d, const MixedPipe& pipe, const double* t_amb_c,
                  const std::vector<double>& t_out, std::vector<double>* mass_end, bool interpolate,
                  SimOutputs* out) {
  constexpr int kMaxTanks = 8;
  const int tanks = std::clamp(pipe.tanks, 1, kMaxTanks);
  const double cp = d.plant.fluid_cp_j_kgk;
  const std::size_t n = d.size();
  mass_end->assign(n, 0.0);
  std::array<double, kMaxTanks> tank{};
  std::size_t first = 0, j = 0;  // this segment's first row; the plug's exit row
  for (std::size_t i = 0; i < n; ++i) {
    const double mdot = d.usable[i] && d.mdot_kg_s[i] > 0.0 ? d.mdot_kg_s[i] : 0.0;
    if (i == 0 || d.restart[i]) {
      first = j = i;
      tank.fill(t_out[i]);
    }
    const double mass_start = i > first ? (*mass_end)[i - 1] : 0.0;
    (*mass_end)[i] = mass_start + mdot * d.dt_s[i];
    if (!d.usable[i] || !std::isfinite(t_out[i])) continue;
    const double exit_mass = 0.5 * (mass_start + (*mass_end)[i]) - pipe.plug_mass_kg;
    while (j < i && (*mass_end)[j] <= exit_mass) ++j;
    double t_c = exit_mass < 0.0 ? t_out[first] : t_out[j];
    if (interpolate && exit_mass >= 0.0) {
      // Cumulative mass at the middle of row k.
      auto middle = [&](std::size_t k) {
        return 0.5 * ((k > first ? (*mass_end)[k - 1] : 0.0) + (*mass_end)[k]);
      };
      const double m_j = middle(j);
      const std::size_t k = exit_mass >= m_j ? (j < i ? j + 1 : j) : (j > first ? j - 1 : j);
      const double m_k = middle(k);
      if (k != j && m_k != m_j && std::isfinite(t_out[k]) && std::isfinite(t_c)) {
        t_c += (exit_mass - m_j) / (m_k - m_j) * (t_out[k] - t_c);
      }
    }
    if (!std::isfinite(t_c)) t_c = t_out[i];
    for (int k = 0; k < tanks; ++k) {
      double& t_tank = tank[static_cast<std::size_t>(k)];
      if (!std::isfinite(t_tank)) t_tank = t_c;
      const TankStep step = MixedTankStep(t_tank, t_c, t_amb_c[i], mdot, cp, pipe.tank_mass_kg,
                                          pipe.loss_w_k / tanks, d.dt_s[i]);
      t_tank = step.t_end_c;
      t_c = step.t_mean_c;
    }
    out->t_out_c[i] = t_c;
    if (mdot > 0.0) out->q_th_w[i] = mdot * cp * (t_c - d.t_in_c[i]);
  }
}

// Other-form truth: the sensor sees the outlet through kOtherTruthPipe.
void MixedPipeToSensor(const OtherTruthContext&, const Drivers& d, SimOutputs* out) {
  const std::vector<double> t_out = out->t_out_c;  // at the collector
  std::vector<double> mass_end;
  PipeToSensor(d, kOtherTruthPipe, d.t_amb_c.data(), t_out, &mass_end, false, out);
}

const OtherFormTruth& OtherTruth() {
  static const OtherFormTruth kTruth = [] {
    OtherFormTruth t;
    t.form =
        "The pipe to the outlet sensor is plug flow of 1.6 kg (a dead time 1.6 kg/ṁ: 44 s at "
        "0.036 kg/s, 148 s at 0.3 of it) followed by 3 mixed tanks of 0.8 kg each (axial "
        "mixing, a first-order lag per tank) losing 1.8 W/K to ambient; the candidate is "
        "a fixed dead time with a plug-flow loss.";
    t.source = "Levenspiel 1999, Chemical Reaction Engineering ch. 14 (tanks in series)";
    t.outputs = MixedPipeToSensor;
    return t;
  }();
  return kTruth;
}

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
    e.reads_base_params = {Param::kAreaM2};
    e.transform_outputs = SensorBehindPipe;
    e.outputs_affine = true;  // interpolation and the pipe's loss towards T_amb
    return e;
  }();
  return kExtension;
}

// The broader form "+pipe_volume": the pipe as a volume, not a number of
// seconds. Plug flow of M_plug·A then one mixed tank of M_mix·A losing
// U_pipe·A to ambient (PipeToSensor with one tank): the dead time M_plug·A/ṁ
// and the lag M_mix·A/ṁ both scale with 1/flow, as a pipe's do, where the
// fixed τ of "+transport_delay" fits one flow only.
void SensorBehindPipeVolume(const Drivers& d, const ParamVector& p, RunInputs* run,
                            SimOutputs* out) {
  const double area_m2 = ParamOf(p, Param::kAreaM2);
  MixedPipe pipe;
  pipe.plug_mass_kg = ParamOf(p, Param::kPipePlugKgM2) * area_m2;
  pipe.tank_mass_kg = ParamOf(p, Param::kPipeMixKgM2) * area_m2;
  pipe.tanks = 1;
  pipe.loss_w_k = ParamOf(p, Param::kUPipeWM2K) * area_m2;
  if (d.size() == 0) return;
  std::vector<double>& t_out = run->Scratch();
  t_out = out->t_out_c;
  PipeToSensor(d, pipe, run->t_amb_c, t_out, &run->Scratch(), true, out);
}

const ModelExtension& VolumeExtension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "pipe_volume";
    e.variant_order = 1;  // transport_delay's place
    e.params = {Param::kPipePlugKgM2, Param::kPipeMixKgM2, Param::kUPipeWM2K};
    e.reads_base_params = {Param::kAreaM2};
    e.transform_outputs = SensorBehindPipeVolume;
    e.outputs_affine = true;  // plug flow and mixed tanks losing to T_amb
    return e;
  }();
  return kExtension;
}

bool InSpec(const ModelSpec& spec) { return spec.Has(Extension()) || spec.Has(VolumeExtension()); }

void AddVolumeForm(ModelSpec* spec) { spec->Add(VolumeExtension()); }

// The median flow of the rows where the pump runs, kg/s (0: it never runs).
double MedianRunningFlow(const Drivers& d, const std::vector<std::uint32_t>& rows) {
  std::vector<double> flows;
  for (std::uint32_t r : rows) {
    if (d.mdot_kg_s[r] > 0.0) flows.push_back(d.mdot_kg_s[r]);
  }
  if (flows.empty()) return 0.0;
  std::nth_element(flows.begin(), flows.begin() + flows.size() / 2, flows.end());
  return flows[flows.size() / 2];
}

// Rate of change of the base model's outlet temperature, K per minute.
std::vector<double> Signature(const Drivers& d, const SimOutputs& base) {
  if (base.t_out_c.size() == d.size()) return RatePerMinute(d, base.t_out_c);
  return std::vector<double>(d.size(), std::numeric_limits<double>::quiet_NaN());
}

// A dead time shows in the timing of the changes: the changes of the
// measured heat follow the model with the fitted delay more closely than
// the model without it (the correlation r of the row-to-row changes rises
// by at least 0.1 in Fisher's z = atanh r, the scale on which a rise means
// as much near r = 1 as at r = 0.5: 0.02 in r at r = 0.9, 0.009 at r =
// 0.965, 0.027 at r = 0.5; a dispersed delay, plug flow with mixing, shows
// this as well as a pure one), or the measured changes follow those of the
// model without the effect best k ≥ 1 rows late (a lag that maximises the
// cross-correlation, by the same rise in z). A pipe loss alone, or a fit
// that shifts a bias, leaves the changes as they were. A τ below half the
// row step cannot show in the timing: the effect is then not shown (a τ of a
// few seconds only smooths the outlet between rows, and a pipe loss alone
// acts like one more thermal loss of the collector).
constexpr double kMinFisherZRise = 0.1;

SignatureCheck ChangesFollowTheDelay(const SignatureData& d) {
  const double step_s = RowStepS(*d.drivers);
  double tau_s = ParamOf(*d.params, Param::kTransportDelayS);
  if (d.drivers->spec.Has(VolumeExtension())) {  // the residence time at the median flow
    const double flow = MedianRunningFlow(*d.drivers, *d.rows);
    const double mass_kg =
        (ParamOf(*d.params, Param::kPipePlugKgM2) + ParamOf(*d.params, Param::kPipeMixKgM2)) *
        ParamOf(*d.params, Param::kAreaM2);
    tau_s = flow > 0.0 ? mass_kg / flow : 0.0;
  }
  SignatureCheck c;
  if (tau_s / step_s < 0.5) {
    // No lag the data can show: what is left is a loss of the pipe, which
    // the data cannot tell from the collector's own losses.
    c.shown = false;
    c.sentence = "the fitted τ = " + FixedDecimals(tau_s, 0) + " s is below half the " +
                 FixedDecimals(step_s, 0) +
                 " s row step: no lag the data can show, and a pipe loss alone (U_pipe = " +
                 FixedDecimals(ParamOf(*d.params, Param::kUPipeWM2K), 2) +
                 " W/(m²K)) is not told from the collector's own losses";
    return c;
  }
  const LagFit before = BestLag(*d.drivers, *d.rows, *d.q_th_meas_w, d.before->q_th_w, 0, 0);
  const LagFit after = BestLag(*d.drivers, *d.rows, *d.q_th_meas_w, d.after->q_th_w, 0, 0);
  if (before.pairs == 0 || after.pairs == 0) {
    c.shown = false;
    c.sentence = "too few unbroken held-out rows to see the timing of the measured heat";
    return c;
  }
  const auto fisher_z = [](double r) { return std::atanh(std::clamp(r, -0.999999, 0.999999)); };
  c.shown = fisher_z(after.corr_at_zero) - fisher_z(before.corr_at_zero) >= kMinFisherZRise;
  // A pipe with mixing smooths the changes that the fitted form delays
  // sharply; the lag shows then in the model without the effect: the
  // measured changes follow its changes best k ≥ 1 rows later (up to twice
  // the fitted residence time), by the same rise in z.
  const int max_lag = std::max(1, static_cast<int>(std::lround(2.0 * tau_s / step_s)));
  const LagFit lag = BestLag(*d.drivers, *d.rows, *d.q_th_meas_w, d.before->q_th_w, 1, max_lag);
  const bool lag_shown = lag.lag_rows >= 1 &&
                         fisher_z(lag.corr_at_lag) - fisher_z(lag.corr_at_zero) >= kMinFisherZRise;
  if (!c.shown && lag_shown) {
    c.shown = true;
    c.sentence = "the measured Q_u's row-to-row changes follow the model without the effect " +
                 std::to_string(lag.lag_rows) + " row(s) late (correlation " +
                 FixedDecimals(lag.corr_at_lag, 3) + ", " + FixedDecimals(lag.corr_at_zero, 3) +
                 " unshifted; fitted τ = " + FixedDecimals(tau_s, 0) + " s" +
                 (d.drivers->spec.Has(VolumeExtension()) ? " at the median flow" : "") + ")";
    return c;
  }
  c.sentence = "the measured Q_u's row-to-row changes correlate " +
               FixedDecimals(after.corr_at_zero, 3) +
               " with the model with τ = " + FixedDecimals(tau_s, 0) + " s" +
               (d.drivers->spec.Has(VolumeExtension()) ? " at the median flow" : "") + ", " +
               FixedDecimals(before.corr_at_zero, 3) + " without it" +
               (c.shown ? "" : ": the delay does not improve the timing");
  return c;
}

// "The outlet sensor sees the fluid 146 s late …", or for the pipe volume
// "… 3.2 L of fluid between the collector and the outlet sensor …".
std::string DelayAdvice(const ModelSpec& spec, const ParamVector& p, const Plant& plant) {
  const std::string loss =
      "pipe loss U_pipe = " + FixedDecimals(ParamOf(p, Param::kUPipeWM2K), 2) + " W/(m²K)";
  if (spec.Has(VolumeExtension())) {
    const double area_m2 = ParamOf(p, Param::kAreaM2);
    const double plug_kg = ParamOf(p, Param::kPipePlugKgM2) * area_m2;
    const double mix_kg = ParamOf(p, Param::kPipeMixKgM2) * area_m2;
    const double litres = (plug_kg + mix_kg) / plant.fluid_density_kg_m3 * 1000.0;
    return "The outlet sensor sees the fluid through " + FixedDecimals(litres, 1) + " L of pipe (" +
           FixedDecimals(plug_kg, 1) + " kg in plug flow, " + FixedDecimals(mix_kg, 1) +
           " kg mixed; " + loss + "): it lags the collector by " +
           FixedDecimals(plug_kg + mix_kg, 1) +
           " kg over the flow, longer the slower the pump; move the sensor to the collector "
           "outlet or model the pipe.";
  }
  return "The outlet sensor sees the fluid " +
         FixedDecimals(ParamOf(p, Param::kTransportDelayS), 0) + " s late (" + loss +
         "): move the sensor to the collector outlet or model the pipe.";
}
}  // namespace

const EffectModule& TransportDelayEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = EffectName(Effect::kTransportDelay);
    m.physics =
        "The outlet sensor sits behind a pipe: it sees the fluid that left the collector "
        "τ earlier (plug flow dead time), cooled towards ambient on the way, "
        "T_sensor = T_amb + (T_out(t − τ) − T_amb)·exp(−U_pipe·A/(ṁ·c_p)) "
        "(exponential decay of a plug in a pipe of loss UA, Duffie & Beckman 10.3). "
        "Q_u is then ṁ·c_p·(T_sensor − T_in): lagging at pump starts and irradiance "
        "steps, lower than the collector's output at low flow. The diagnosis also fits "
        "the pipe as a volume ('+pipe_volume'): plug flow of M_plug then one mixed tank "
        "of M_mix losing U_pipe·A, so that the dead time M_plug/ṁ and the lag M_mix/ṁ "
        "scale with 1/flow as a pipe's do.";
    m.source = "Duffie & Beckman, Solar Engineering of Thermal Processes, 10.3 (pipe losses)";
    m.params = EffectParams(Effect::kTransportDelay);
    m.typical_truth = {{Param::kTransportDelayS, 120.0}, {Param::kUPipeWM2K, 1.0}};
    m.signature = "rate of change of the base model's outlet temperature, K per minute";
    m.advice =
        "Model the pipe to the outlet sensor (+transport_delay), or move the sensor to "
        "the collector outlet and insulate the pipe.";
    m.extension = &Extension();
    m.form_extensions = {&VolumeExtension()};
    m.in_spec = InSpec;
    m.form = "pure_delay";
    m.diagnosis_forms = {{"pipe_with_mixing", AddVolumeForm}};
    m.advice_for = DelayAdvice;
    m.signature_values = Signature;
    m.shows_signature = ChangesFollowTheDelay;
    m.other_truth = &OtherTruth();
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
