// Wind dependence of the front heat-loss coefficient.
#pragma once

#include <cmath>

namespace pvtwin {

// v^n for v ≥ 0 from a precomputed ln(v) (−inf for calm), so that the hot loop
// pays one exp() instead of a pow().
inline double WindPower(double ln_wind, double n_wind) { return std::exp(n_wind * ln_wind); }

// Paper eq. 2.8, as printed (variant letter 'w'):
//   U_front,w = 1 / (1/U_front + r_refwind·v^n_wind)
// U in W/(m²K), v = wind speed (m/s), r_refwind in (m²K/W)/(m/s)^n.
// Note: this form makes the front loss FALL as wind rises, the opposite of
// forced convection; it is kept so that the paper's variants reproduce the
// paper. Use FrontConductanceConvective (effect "wind") for the physical form.
// Takes the still-air resistance 1/U_front (m²K/W) so that a run can
// precompute it.
inline double FrontConductancePaperWM2K(double r_front_m2k_w, double r_refwind, double wind_pow) {
  return 1.0 / (r_front_m2k_w + r_refwind * wind_pow);
}

// Physical form (effect "wind", after ISO 9806's c3·u term):
//   U_front,w = U_front + c_wind·v^n_wind
// c_wind = u_wind_w_m2k in W/(m²K)/(m/s)^n; loss grows with wind speed.
inline double FrontConductanceConvectiveWM2K(double u_front_w_m2k, double u_wind_w_m2k,
                                             double wind_pow) {
  return u_front_w_m2k + u_wind_w_m2k * wind_pow;
}

// Wind speed at height z from a speed measured or forecast at z_ref, by the
// power law with the Hellmann exponent α (Hellmann 1916; α = 1/7 for open
// terrain, the value of IEC 61400-1 and of most engineering use):
//   v(z) = v(z_ref)·(z / z_ref)^α,   heights in m above ground, speeds in m/s.
// Holds within the surface layer (up to about 100 m), for neutral
// stratification; v = 0 stays 0.
inline constexpr double kHellmannExponentOpenTerrain = 1.0 / 7.0;
inline double WindAtHeightPowerLaw(double v_ref_m_s, double z_ref_m, double z_m,
                                   double alpha = kHellmannExponentOpenTerrain) {
  return v_ref_m_s * std::pow(z_m / z_ref_m, alpha);
}

}  // namespace pvtwin
