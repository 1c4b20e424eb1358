// Effect "transport_delay": the outlet sensor sits behind a pipe. A
// ModelExtension that transforms the outputs: the delayed, cooled outlet
// temperature and the heat measured with it.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

// --- Other-form truth: a pipe with axial mixing, dead time ∝ 1/flow ---

// One well-mixed tank of fluid mass M (kg) over a row of dt_s with inflow ṁ
// (kg/s) at T_in (held over the row) and a loss UA (W/K) to T_amb; exact
// solution of M·c_p·dT/dt = ṁ·c_p·(T_in − T) − UA·(T − T_amb):
//   T_eq = (ṁ·c_p·T_in + UA·T_amb)/(ṁ·c_p + UA),  a = (ṁ·c_p + UA)/(M·c_p),
//   T(dt) = T_eq + (T0 − T_eq)·e^(−a·dt),
//   mean over the row = T_eq + (T0 − T_eq)·(1 − e^(−a·dt))/(a·dt).
// With ṁ = 0 and UA = 0 the tank holds T0.
struct TankStep {
  double t_end_c = 0.0;
  double t_mean_c = 0.0;
};
TankStep MixedTankStep(double t0_c, double t_in_c, double t_amb_c, double mdot_kg_s,
                       double cp_j_kgk, double mass_kg, double ua_w_k, double dt_s);

// The pipe to the outlet sensor as plug flow of mass M_plug (a dead time
// M_plug/ṁ, not a fixed number of seconds) followed by N tanks in series of
// mass M_tank each (axial dispersion, Levenspiel 1999, Chemical Reaction
// Engineering ch. 14: the tanks-in-series model), with the loss UA shared by
// the tanks. Residence time M/ṁ: 111 s at the nominal 0.036 kg/s.
struct MixedPipe {
  double plug_mass_kg = 1.6;
  double tank_mass_kg = 0.8;
  int tanks = 3;
  double loss_w_k = 1.8;
};

inline constexpr MixedPipe kOtherTruthPipe{};

const EffectModule& TransportDelayEffect();

}  // namespace pvtwin
