// Effect "pv_clipping": the inverter limits the AC power. A ModelExtension
// that sets the model's electrical limit.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/effects/effect_module.h"

namespace pvtwin {

// --- Other-form truth: a soft knee with temperature derating ---

// The inverter's limit derated with the air around it, linearly above T_d as
// data sheets give it ("temperature derating", e.g. SMA's technical
// information on derating):
//   P_lim(T) = P_lim·max(0, 1 − d·max(0, T − T_d)),  W; T, T_d in °C, d in 1/K.
inline double DeratedLimitW(double limit_w, double t_c, double derate_from_c, double derate_per_k) {
  return limit_w * std::max(0.0, 1.0 - derate_per_k * std::max(0.0, t_c - derate_from_c));
}

// A soft knee instead of min(P_dc, P_lim): the p-norm smooth minimum
//   P_ac = P_dc / (1 + (P_dc/P_lim)^m)^(1/m),
// which bends below P_lim as the MPPT walks off the maximum power point
// gradually (P_ac = P_lim/2^(1/m) at P_dc = P_lim; → P_lim for P_dc ≫ P_lim;
// → P_dc for P_dc ≪ P_lim). m > 0 is the knee's sharpness (∞: the hard clip).
inline double SoftKneeAcPowerW(double p_dc_w, double limit_w, double sharpness) {
  if (!(p_dc_w > 0.0)) return p_dc_w;
  if (!(limit_w > 0.0)) return 0.0;
  return p_dc_w / std::pow(1.0 + std::pow(p_dc_w / limit_w, sharpness), 1.0 / sharpness);
}

struct SoftInverter {
  double limit_w_m2 = 120.0;    // P_lim per m² of collector at T ≤ T_d
  double sharpness = 8.0;       // m
  double derate_from_c = 25.0;  // T_d, on the ambient temperature
  double derate_per_k = 0.01;   // d
};

inline constexpr SoftInverter kOtherTruthInverter{};

const EffectModule& PvClippingEffect();

}  // namespace pvtwin
