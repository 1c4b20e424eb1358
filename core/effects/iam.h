// Effect "iam": the incidence-angle modifier of the beam and diffuse parts
// (paper 2.5, core/physics/iam.h), expressed by the letter 'I'.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

// --- Other-form truth: Fresnel/Snell reflection and absorption in the cover ---

// A glass cover: refractive index n, extinction coefficient K (1/m),
// thickness L (m); pvlib's iam.physical defaults.
struct FresnelCover {
  double refractive_index = 1.526;
  double extinction_per_m = 4.0;
  double thickness_m = 0.002;
};

inline constexpr FresnelCover kOtherTruthCover{};

// Transmittance of the cover for unpolarised light at incidence θ (rad),
// air–glass interface by Snell's and Fresnel's laws, absorption by
// Bouguer's law (Duffie & Beckman 5.1–5.3; De Soto et al. 2006, Solar
// Energy 80, eq. 14):
//   sin θ_r = sin θ / n,
//   r_⊥ = sin²(θ_r − θ)/sin²(θ_r + θ),  r_∥ = tan²(θ_r − θ)/tan²(θ_r + θ),
//   τ(θ) = exp(−K·L/cos θ_r)·(1 − (r_⊥ + r_∥)/2),
// and at θ = 0: τ(0) = exp(−K·L)·(1 − ((n − 1)/(n + 1))²). 0 for θ ≥ 90°.
double FresnelCoverTransmittance(double aoi_rad, const FresnelCover& cover);

// The incidence-angle modifier K(θ) = τ(θ)/τ(0) of that cover.
double FresnelIam(double aoi_rad, const FresnelCover& cover);

// --- The diagnosis's fitted form "+iam" ---

// ASHRAE's incidence-angle modifier over the whole range, from the beam's
// excess e = 1/cos θ − 1 (Souka & Safwat's form without the paper's linear
// segment above 60°): K = max(0, 1 − b0·e); +inf (θ ≥ 90°) gives 0.
// ASHRAE Standard 93; Duffie & Beckman 5.6; pvlib iam.ashrae.
double IamAshraeFromExcess(double excess, double b0);

const EffectModule& IamEffect();

}  // namespace pvtwin
