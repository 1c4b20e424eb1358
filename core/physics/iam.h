// Incidence angle modifier (IAM) of the collector's transmittance-absorptance
// product, and the irradiance absorbed by the collector with beam, sky and
// ground parts weighted at their own incidence angles.
//
// Source: paper section 2.5 (Souka & Safwat 1966 model up to 60°, completed
// by a linear segment to 0 at 90°; I_at equation). Angles in radians.
#pragma once

#include "core/physics/irradiance.h"

namespace pvtwin {

// Relative transmittance-absorptance τα(θ)/τα(0), paper 2.5:
//
//   τα(θ) = 1 − b0 · (1/cos θ − 1)           0 ≤ θ < 60°
//   τα(θ) = (1 − b0) · (1 − (θ − 60°)/30°)   60° ≤ θ ≤ 90°
//   τα(θ) = 0                                θ > 90° (radiation from behind)
//
//   θ = aoi_rad (|θ| is used for negative input), b0 = iam_b0, first-order
//   coefficient (paper Table 3 start value 0.05), dimensionless.
//
// Both branches give 1 − b0 at 60°, so τα is continuous. The result is
// clamped to [0, 1] (b0 < 0 or b0 > 1 would leave that range). NaN in, NaN out.
double IamSoukaSafwat(double aoi_rad, double b0);

// Irradiance absorbed by the collector, relative to normal incidence, paper
// 2.5:
//
//   I_at = τα(θ_inc) · beam + τα(θ_eff,sky) · I_dsky + τα(θ_eff,gnd) · I_dgd
//
//   beam, I_dsky, I_dgd = poa (W/m²), θ_inc = aoi_rad (beam angle of
//   incidence), θ_eff,sky/gnd = diffuse_angles (BrandemuehlBeckmanAngles of
//   the tilt), b0 = iam_b0. Returns W/m². A part that is exactly 0
//   contributes 0 even when its angle is NaN (no beam at night).
double AbsorbedIrradianceWM2(const PoaComponents& poa, double aoi_rad,
                             const EffectiveDiffuseAngles& diffuse_angles, double b0);

}  // namespace pvtwin
