// Irradiance on the collector plane: isotropic-sky transposition of global
// and diffuse horizontal irradiance, the split of a measured in-plane global
// irradiance into beam, sky-diffuse and ground-reflected parts, and the
// effective incidence angles of the two diffuse parts.
//
// Source: paper section 2.5 (the I_at equation and its I_dsky, I_dgd terms;
// the isotropic sky of Liu & Jordan), Brandemuehl & Beckman (1980) for the
// effective angles. Angles in radians; irradiances in W/m².
#pragma once

#include <limits>

namespace pvtwin {

// The three parts of the irradiance on the collector plane, paper 2.5:
// I_gt = beam + I_dsky + I_dgd. Every part is ≥ 0 (or NaN when an input was
// NaN).
struct PoaComponents {
  double beam_w_m2 = 0.0;            // direct (beam) irradiance on the plane
  double sky_diffuse_w_m2 = 0.0;     // I_dsky, diffuse from the sky dome
  double ground_diffuse_w_m2 = 0.0;  // I_dgd, diffuse reflected by the ground
  // I_gt, global irradiance on the plane.
  double global_w_m2() const { return beam_w_m2 + sky_diffuse_w_m2 + ground_diffuse_w_m2; }
};

// Below this cos θ_z (θ_z > 89.0°) the horizontal beam is not converted to a
// beam normal irradiance: 1/cos θ_z grows without bound near the horizon and
// turns small errors in GHI − DHI into large in-plane beam.
inline constexpr double kMinCosZenithForBeam = 0.0175;

struct IsotropicSkyInput {
  double ghi_w_m2 = 0.0;       // I_gh, global horizontal
  double dhi_w_m2 = 0.0;       // I_dh, diffuse horizontal
  double zenith_rad = 0.0;     // θ_z, solar zenith (refraction-corrected)
  double aoi_rad = 0.0;        // θ_inc, beam angle of incidence on the plane
  double tilt_rad = 0.0;       // β, plane slope from horizontal
  double ground_albedo = 0.2;  // ρ_gnd
};

// Isotropic-sky transposition, paper 2.5:
//
//   beam   = max(0, I_gh − I_dh) / cos θ_z · max(0, cos θ_inc)
//   I_dsky = (1 + cos β)/2 · I_dh
//   I_dgd  = ρ_gnd · (1 − cos β)/2 · I_gh
//
// Beam rule: beam = 0 when cos θ_z < kMinCosZenithForBeam (sun below or
// within ~1° of the horizon) or θ_inc ≥ 90° (sun behind the plane); the
// horizontal beam of such a row is dropped, not moved to the diffuse parts.
// I_dh > I_gh (sensor mismatch) gives beam 0. Negative irradiances (night
// offsets of thermopile sensors) are clipped to 0; a NaN input gives NaN
// parts. For β = 0 and a row above the beam limit the parts sum to I_gh up
// to rounding.
PoaComponents TransposeIsotropicSky(const IsotropicSkyInput& in);

struct MeasuredPoaInput {
  double g_poa_w_m2 = 0.0;  // I_gt, measured global in the plane
  // Measured diffuse in the plane (a shaded pyranometer in the plane); NaN
  // when not measured.
  double g_poa_diffuse_w_m2 = std::numeric_limits<double>::quiet_NaN();
  double ghi_w_m2 = std::numeric_limits<double>::quiet_NaN();  // I_gh; NaN when not measured
  double dhi_w_m2 = std::numeric_limits<double>::quiet_NaN();  // I_dh; NaN when not measured
  double tilt_rad = 0.0;                                       // β
  double ground_albedo = 0.2;                                  // ρ_gnd
};

// Splits a measured in-plane global irradiance into beam, sky and ground
// parts (the inverse use of paper 2.5's I_at equation, beam = I_gt − I_dsky
// − I_dgd).
//
// With a measured in-plane diffuse D (clipped to [0, I_gt]):
//   I_dgd  = min(D, ρ_gnd · (1 − cos β)/2 · I_gh)     if I_gh is known,
//   I_dgd  = min(D, ρ_gnd · (1 − cos β)/2 · I_gt)     otherwise (the in-plane
//            global stands in for I_gh; for the usual β ≤ 45° and ρ ≈ 0.2
//            the ground part is < 3 % of I_gt, so the error is small),
//   I_dsky = D − I_dgd,
//   beam   = I_gt − D.
// The parts are ≥ 0 and sum to max(0, I_gt) (up to rounding).
//
// Without a measured in-plane diffuse but with I_gh and I_dh measured (the
// paper's own set-up, Table 2: I_gt_m, I_gh_m, I_dh_m), the diffuse parts are
// paper 2.5's:
//   I_dsky = (1 + cos β)/2 · I_dh,   I_dgd = ρ_gnd · (1 − cos β)/2 · I_gh,
//   beam   = I_gt − I_dsky − I_dgd.
// A row whose diffuse parts exceed the measured I_gt (an overcast sky that
// is not isotropic, or the sensors disagree) would get a negative beam; there
// the beam is 0 and the two diffuse parts are scaled down to sum to I_gt, so
// that no row absorbs more than its measured global irradiance.
//
// With neither, the split is not observable: the whole of max(0, I_gt) is
// returned as beam, and the caller applies the beam IAM at the measured or
// computed angle of incidence to all of it (the documented fallback). NaN
// I_gt gives NaN parts.
PoaComponents SplitMeasuredPoa(const MeasuredPoaInput& in);

// Effective incidence angles of isotropic sky-diffuse and ground-reflected
// radiation on a plane of slope β (Brandemuehl & Beckman 1980, as used in
// paper 2.5), β in degrees inside the fit:
//
//   θ_eff,sky = 59.68 − 0.1388 β + 0.001497 β²   [°]
//   θ_eff,gnd = 90 − 0.5788 β + 0.002693 β²      [°]
//
// Domain: 0 ≤ β ≤ 90° (the fit's range); outside, the polynomials are
// evaluated anyway.
struct EffectiveDiffuseAngles {
  double sky_rad = 0.0;     // θ_eff,sky
  double ground_rad = 0.0;  // θ_eff,gnd
};

EffectiveDiffuseAngles BrandemuehlBeckmanAngles(double tilt_rad);

}  // namespace pvtwin
