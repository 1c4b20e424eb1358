// Effect "wind": forced convection on the uncovered front. Two forms: the
// paper's printed form, the letter 'w' (paper 2.8, core/physics/wind.h),
// and the physical form "+wind", U_front + c_wind·v^n_wind (ISO 9806 style),
// a ModelExtension that sets the front conductance per row.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

// --- Other-form truth: another convection correlation ---

// Forced convection on a flat plate in the natural wind, Test, Lessmann &
// Johary 1981 (J. Heat Transfer 103, 262–267):
//   h_w = 8.55 + 2.56·v   (W/m²K, v in m/s).
inline double ConvectionTestEtAlWM2K(double wind_m_s) { return 8.55 + 2.56 * wind_m_s; }

// The truth's front conductance: the still-air U_front plus the wind's part
// of Test et al.'s correlation, U_front(v) = U_front + h_w(v) − h_w(0), which
// rises with v (the candidate, the paper's printed 'w', falls with v).
inline double FrontConductanceTestWM2K(double u_front_w_m2k, double wind_m_s) {
  return u_front_w_m2k + ConvectionTestEtAlWM2K(wind_m_s) - ConvectionTestEtAlWM2K(0.0);
}

const EffectModule& WindEffect();

}  // namespace pvtwin
