// Unit suffixes and physical constants used throughout pvtwin.
//
// Every quantity carries its unit in its name. The suffixes are:
//
//   suffix   unit               example
//   _c       degree Celsius     t_pv_c, t_in_c
//   _k       kelvin             t_sky_k (absolute temperatures only)
//   _w       watt               p_el_w, q_th_w
//   _w_m2    W/m²               g_poa_w_m2
//   _w_m2k   W/(m²·K)           u_front_w_m2k
//   _m2k_w   m²·K/W             r0_fluid_m2k_w
//   _j_m2k   J/(m²·K)           c_coll_j_m2k
//   _j_kgk   J/(kg·K)           fluid_cp_j_kgk
//   _kg_s    kg/s               mdot_kg_s
//   _kg_m3   kg/m³              fluid_density_kg_m3
//   _l_h     litre per hour     flow_l_h
//   _m_s     m/s                wind_m_s
//   _m2      m²                 area_m2
//   _m       metre              elevation_m
//   _s       second             dt_s, time_s (unix seconds, UTC)
//   _rad     radian             aoi_rad, tilt_rad
//   _deg     degree             tilt_deg (config and I/O edge only)
//   _per_k   1/K                pv_temp_coeff_per_k
//   _m2_w    m²/W               pv_irr_coeff_m2_w
//
// Fractions (eta_pv, iam, f_th) carry no suffix. Angles are radians inside
// core/; degrees appear only where config files and CSV columns are read.
#pragma once

#include <numbers>

namespace pvtwin {

inline constexpr double kStefanBoltzmannW_m2k4 = 5.670374419e-8;
inline constexpr double kZeroCelsiusK = 273.15;
inline constexpr double kPi = std::numbers::pi;

constexpr double DegToRad(double deg) { return deg * (kPi / 180.0); }
constexpr double RadToDeg(double rad) { return rad * (180.0 / kPi); }
constexpr double CToK(double t_c) { return t_c + kZeroCelsiusK; }
constexpr double KToC(double t_k) { return t_k - kZeroCelsiusK; }

}  // namespace pvtwin
