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

// Dew point from air temperature and relative humidity by the Magnus
// formula with the coefficients of Alduchov & Eskridge (1996), "Improved
// Magnus form approximation of saturation vapor pressure", J. Appl. Meteor.
// 35, 601–609 (their AERK: e_s = 6.1094·exp(17.625·t/(243.04 + t)) hPa):
//   γ = ln(RH/100) + a·t/(b + t),   t_d = b·γ/(a − γ),   a = 17.625, b = 243.04 °C
// t_air_c in °C, rh_pct in % (0 < RH ≤ 100), result in °C. Holds for
// −40 … 50 °C. NaN outside 0 < RH ≤ 100.
inline double DewPointC(double t_air_c, double rh_pct) {
  constexpr double kA = 17.625, kB = 243.04;
  if (!(rh_pct > 0.0 && rh_pct <= 100.0)) return std::nan("");
  const double gamma = std::log(rh_pct / 100.0) + kA * t_air_c / (kB + t_air_c);
  return kB * gamma / (kA - gamma);
}

// Clear-sky emittance from the dew point, Berdahl & Martin (1984),
// "Emissivity of clear skies", Solar Energy 32, 663–664, with the diurnal and
// pressure (site elevation) corrections of Martin & Berdahl (1984),
// "Characteristics of infrared sky radiation in the United States", Solar
// Energy 33, 321–336:
//   ε_clr = 0.711 + 0.56·(t_d/100) + 0.73·(t_d/100)²
//           + 0.013·cos(2π·h/24) + 0.00012·(p − 1000)
// t_d = t_dew_c (°C), h = solar_hour (hours from local solar midnight),
// p = p_air_hpa (hPa). A NaN p leaves its correction out (sea level). Fitted
// on dew points of −20 … 30 °C. Duffie & Beckman (Solar Engineering of
// Thermal Processes, 4th ed., eq. 3.9.2) give the same without the pressure
// term as T_sky = T_air·ε_clr^(1/4).
inline double BerdahlMartinClearSkyEmittance(double t_dew_c, double solar_hour,
                                             double p_air_hpa) {
  constexpr double kTwoPi = 6.283185307179586;
  const double x = t_dew_c / 100.0;
  const double pressure = std::isnan(p_air_hpa) ? 0.0 : 0.00012 * (p_air_hpa - 1000.0);
  return 0.711 + 0.56 * x + 0.73 * x * x + 0.013 * std::cos(kTwoPi * solar_hour / 24.0) +
         pressure;
}

// Equivalent sky temperature of a sky of emittance eps_sky over air at
// t_air_k: σ·T_sky⁴ = ε_sky·σ·T_air⁴, so T_sky = ε_sky^(1/4)·T_air (K).
inline double SkyTemperatureFromEmittanceK(double eps_sky, double t_air_k) {
  return std::sqrt(std::sqrt(eps_sky)) * t_air_k;
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

// Saturation vapour pressure over water, Magnus form (WMO 2008, Guide to
// Meteorological Instruments, annex 4.B): e_s = 6.112·exp(17.62·t/(243.12 + t))
// hPa, t in °C. The vapour pressure at dew point t_d is e_a = e_s(t_d); at
// relative humidity RH (0 … 1) it is RH·e_s(t_air). Holds for −45 … 60 °C.
inline double SaturationVapourPressureHpa(double t_c) {
  return 6.112 * std::exp(17.62 * t_c / (243.12 + t_c));
}

// Clear-sky emissivity of Brunt (1932), "Notes on radiation in the
// atmosphere", Q. J. R. Meteorol. Soc. 58, with the coefficients of
// Sellers (1965) for e_a in hPa:
//   ε_clr = 0.52 + 0.065·√e_a,   e_a = screen-level vapour pressure (hPa).
inline double BruntClearSkyEmissivity(double vapour_pressure_hpa) {
  return 0.52 + 0.065 * std::sqrt(vapour_pressure_hpa);
}

// Cloudy-sky emissivity with the cloud fraction c (0 … 1) as in Crawford &
// Duchon (1999), J. Appl. Meteor. 38, eq. 19: ε = c + (1 − c)·ε_clr (a cloud
// layer radiates as a black body at air temperature).
inline double CloudySkyEmissivity(double eps_clear, double cloud_fraction) {
  return cloud_fraction + (1.0 - cloud_fraction) * eps_clear;
}

// Long-wave irradiance on a plane of slope β (W/m²), the quantity a
// pyrgeometer in the collector plane reads (paper 3.1): the sky part
// (1 + cos β)/2·ε_sky·σ·T_a⁴ and the ground part (1 − cos β)/2·σ·T_a⁴, the
// ground at air temperature T_a (°C). SkyTemperatureK of the result is the
// equivalent sky temperature the model uses.
inline double LongWaveOnPlaneWM2(double eps_sky, double t_air_c, double tilt_rad) {
  const double cos_tilt = std::cos(tilt_rad);
  const double sky_view = 0.5 * (1.0 + cos_tilt);
  const double ground_view = 0.5 * (1.0 - cos_tilt);
  const double black_body_w_m2 = kStefanBoltzmannW_m2k4 * std::pow(CToK(t_air_c), 4);
  return sky_view * eps_sky * black_body_w_m2 + ground_view * black_body_w_m2;
}

}  // namespace pvtwin
