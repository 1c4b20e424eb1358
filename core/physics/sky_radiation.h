// Long-wave radiation exchange between the collector front and the sky.
#pragma once

#include <cmath>

#include "core/common/units.h"

namespace pvtwin {

// Equivalent sky temperature from measured down-welling long-wave irradiance
// (paper 3.1): T_sky = (L↓/σ)^(1/4), L↓ = lw_down_w_m2 (W/m²), result in K.
// Domain: lw_down_w_m2 > 0.
inline double SkyTemperatureK(double lw_down_w_m2) {
  return std::sqrt(std::sqrt(lw_down_w_m2 / kStefanBoltzmannW_m2k4));
}

// Clear-sky equivalent sky temperature from the screen-level air
// temperature alone (Swinbank 1963, "Long-wave radiation from clear skies",
// Q. J. R. Meteorol. Soc. 89, 339–348): T_sky = 0.0552·T_air^1.5, both in K.
// At 20 °C it gives 277.0 K, 16 K below the air.
inline double SwinbankSkyTemperatureK(double t_air_k) {
  return 0.0552 * t_air_k * std::sqrt(t_air_k);
}

// Net long-wave loss of the PV surface to the sky per m² (W/m²):
//   q_rad = ε_PVT·σ·(T_PV⁴ − T_sky⁴)
// which is the paper's U_rad·(T_PV − T_sky) with (paper eq. 2.6, per m²)
//   U_rad = ε_PVT·σ·(T_PV + T_sky)·(T_PV² + T_sky²),   temperatures in K.
// Returned with its derivative d q_rad / d T_PV = 4·ε·σ·T_PV³ (W/m²K), used to
// linearise the node equation for Newton's method.
struct SkyRadiationLoss {
  double q_w_m2;
  double dq_dt_w_m2k;
};

inline SkyRadiationLoss SkyRadiation(double eps_pvt, double t_pv_k, double t_sky_k4) {
  const double t2 = t_pv_k * t_pv_k;
  return {eps_pvt * kStefanBoltzmannW_m2k4 * (t2 * t2 - t_sky_k4),
          4.0 * eps_pvt * kStefanBoltzmannW_m2k4 * t2 * t_pv_k};
}

// The paper's equivalent coefficient U_rad (W/m²K), eq. 2.6 per m².
inline double URadWM2K(double eps_pvt, double t_pv_k, double t_sky_k) {
  return eps_pvt * kStefanBoltzmannW_m2k4 * (t_pv_k + t_sky_k) *
         (t_pv_k * t_pv_k + t_sky_k * t_sky_k);
}

}  // namespace pvtwin
