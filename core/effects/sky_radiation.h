// Effect "sky_radiation": long-wave exchange of the front with the sky
// (paper 2.9, core/physics/sky_radiation.h), expressed by the letter 'r'.
#pragma once

#include <cmath>

#include "core/common/units.h"
#include "core/effects/effect_module.h"
#include "core/physics/sky_radiation.h"

namespace pvtwin {

// The broader form the diagnosis also fits ("r+sky_radiation"): the sky the
// front exchanges with is cloudier by Δc_sky than the logged long-wave
// channel says (another sky model or cloud correction, a pyrgeometer that
// sees another sky). Crawford & Duchon's cloudy sky, ε = c + (1 − c)·ε_clr,
// applied to the logged sky's emissivity gives ε' = ε + Δc·(1 − ε), i.e. the
// equivalent sky temperature
//   T_sky,eff⁴ = T_sky⁴ + Δc_sky·(T_a⁴ − T_sky⁴)   (K⁴; T_a the air in K),
// floored at 0 (Δc_sky < 0: a clearer sky). Δc_sky = 0 is the paper's 2.9.
inline double SkyK4WithCloudOffset(double t_sky_k4, double t_amb_k, double offset) {
  const double t2 = t_amb_k * t_amb_k;
  const double v = t_sky_k4 + offset * (t2 * t2 - t_sky_k4);
  return v > 0.0 ? v : 0.0;
}

// --- Other-form truth: another sky model than the logged long-wave ---
// (with CloudySkyEmissivity and LongWaveOnPlaneWM2 of core/physics/sky_radiation.h)

// Swinbank 1963 (Q. J. R. Meteorol. Soc. 89) clear-sky long-wave irradiance
// L↓ = 5.31e-13·T_a⁶ (W/m², T_a in K), i.e. the clear-sky emissivity
//   ε_clr = 5.31e-13·T_a²/σ.
inline double SwinbankClearSkyEmissivity(double t_amb_k) {
  return 5.31e-13 * t_amb_k * t_amb_k / kStefanBoltzmannW_m2k4;
}

// Cloud fraction from the daytime diffuse fraction k_d = DHI/GHI (clear ≈
// 0.15, overcast 1): c = clamp((k_d − 0.15)/0.75, 0, 1) — a proxy for Crawford
// & Duchon's 1 − GHI/GHI_clear where no clear-sky model is at hand.
inline double CloudFractionFromDiffuseFraction(double diffuse_fraction) {
  const double c = (diffuse_fraction - 0.15) / 0.75;
  return c < 0.0 ? 0.0 : (c > 1.0 ? 1.0 : c);
}

const EffectModule& SkyRadiationEffect();

}  // namespace pvtwin
