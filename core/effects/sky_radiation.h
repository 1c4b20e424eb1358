// Effect "sky_radiation": long-wave exchange of the front with the sky
// (paper 2.9, core/physics/sky_radiation.h), expressed by the letter 'r'.
#pragma once

#include <cmath>

#include "core/common/units.h"
#include "core/effects/effect_module.h"

namespace pvtwin {

// --- Other-form truth: another sky model than the logged long-wave ---

// Swinbank 1963 (Q. J. R. Meteorol. Soc. 89) clear-sky long-wave irradiance
// L↓ = 5.31e-13·T_a⁶ (W/m², T_a in K), i.e. the clear-sky emissivity
//   ε_clr = 5.31e-13·T_a²/σ.
inline double SwinbankClearSkyEmissivity(double t_amb_k) {
  return 5.31e-13 * t_amb_k * t_amb_k / kStefanBoltzmannW_m2k4;
}

// Crawford & Duchon 1999 (J. Appl. Meteorol. 38) cloud correction,
// ε_sky = c + (1 − c)·ε_clr, c the cloud fraction.
inline double CloudySkyEmissivity(double clear_emissivity, double cloud_fraction) {
  return cloud_fraction + (1.0 - cloud_fraction) * clear_emissivity;
}

// Cloud fraction from the daytime diffuse fraction k_d = DHI/GHI (clear ≈
// 0.15, overcast 1): c = clamp((k_d − 0.15)/0.75, 0, 1) — a proxy for Crawford
// & Duchon's 1 − GHI/GHI_clear where no clear-sky model is at hand.
inline double CloudFractionFromDiffuseFraction(double diffuse_fraction) {
  const double c = (diffuse_fraction - 0.15) / 0.75;
  return c < 0.0 ? 0.0 : (c > 1.0 ? 1.0 : c);
}

// Long-wave irradiance on a plane of tilt β: sky part (1 + cos β)/2·ε_sky·σT_a⁴,
// ground part (1 − cos β)/2·σT_a⁴ (ground at air temperature), W/m².
inline double LongWaveOnPlaneWM2(double sky_emissivity, double t_amb_k, double tilt_rad) {
  const double black_body_w_m2 = kStefanBoltzmannW_m2k4 * std::pow(t_amb_k, 4);
  const double sky_view = 0.5 * (1.0 + std::cos(tilt_rad));
  return sky_view * sky_emissivity * black_body_w_m2 + (1.0 - sky_view) * black_body_w_m2;
}

const EffectModule& SkyRadiationEffect();

}  // namespace pvtwin
