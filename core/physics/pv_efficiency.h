// PV conversion efficiency with temperature and irradiance correction.
#pragma once

#include <algorithm>

namespace pvtwin {

struct PvEfficiencyParams {
  double eta_pv_ref;           // η_PVref, efficiency at T_PVref and I_gtref (-)
  double pv_temp_coeff_per_k;  // f_corr_T (1/K), negative for silicon
  double pv_irr_coeff_m2_w;    // f_corr_I (m²/W)
  double pv_t_ref_c;           // T_PVref (°C)
  double pv_g_ref_w_m2;        // I_gtref (W/m²)
};

// Paper eq. 2.4:
//   η_PV = η_PVref · (1 + f_corr_T·(T_PV − T_PVref)) · (1 + f_corr_I·(I_gt − I_gtref))
// with T_PV = t_pv_c (°C) and I_gt = g_poa_w_m2 (global irradiance in the
// collector plane, W/m²). The linear form holds for cell temperatures within
// roughly ±100 K of T_PVref; outside it the efficiency is clamped to [0, 1] so
// that a fit far out of range cannot create energy.
struct PvEfficiencyLinear {
  double eta_at_ref_temp;  // η_PVref·(1 + f_corr_I·(I_gt − I_gtref)) (-)
  double slope_per_k;      // dη/dT_PV = eta_at_ref_temp·f_corr_T (1/K)
  double t_ref_c;

  double At(double t_pv_c) const {
    return std::clamp(eta_at_ref_temp + slope_per_k * (t_pv_c - t_ref_c), 0.0, 1.0);
  }
  // dη/dT at t_pv_c, zero where the clamp is active.
  double SlopeAt(double t_pv_c) const {
    const double eta = eta_at_ref_temp + slope_per_k * (t_pv_c - t_ref_c);
    return (eta > 0.0 && eta < 1.0) ? slope_per_k : 0.0;
  }
};

// η_PV as a linear function of T_PV for one irradiance level.
inline PvEfficiencyLinear PvEfficiencyAt(const PvEfficiencyParams& p, double g_poa_w_m2) {
  const double irradiance_factor = 1.0 + p.pv_irr_coeff_m2_w * (g_poa_w_m2 - p.pv_g_ref_w_m2);
  const double eta0 = p.eta_pv_ref * irradiance_factor;
  return {eta0, eta0 * p.pv_temp_coeff_per_k, p.pv_t_ref_c};
}

}  // namespace pvtwin
