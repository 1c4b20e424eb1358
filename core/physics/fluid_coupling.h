// Heat transfer from the collector node to the heat-transfer fluid.
#pragma once

namespace pvtwin {

// Paper eq. 2.7 (Koschenz & Lehmann), per m² of collector (see params.h):
//   1 / U_fluid = r1_fluid / (2·w) + r0_fluid,     w = ṁ·c_p / A_PVT
// U_fluid in W/(m²K); ṁ = mdot_kg_s (kg/s), c_p = fluid_cp_j_kgk (J/kgK),
// A_PVT = area_m2; r1_fluid dimensionless, r0_fluid in m²K/W.
// Domain: ṁ ≥ 0. At ṁ = 0 no heat is extracted: U_fluid = 0 (the paper's
// boolean (ṁ > 0)).
inline double UFluidWM2K(double mdot_kg_s, double fluid_cp_j_kgk, double area_m2,
                         double r0_fluid_m2k_w, double r1_fluid) {
  if (!(mdot_kg_s > 0.0)) return 0.0;
  const double capacity_flow_w_m2k = mdot_kg_s * fluid_cp_j_kgk / area_m2;
  return 1.0 / (r1_fluid / (2.0 * capacity_flow_w_m2k) + r0_fluid_m2k_w);
}

// The same for the whole field in W/K, from the capacity flow ṁ·c_p (W/K):
//   U_fluid·A = 2·ṁc_p / (r1_fluid + 2·ṁc_p·r0_fluid/A)
// (one division; r0_per_area = r0_fluid_m2k_w / area_m2 precomputed).
inline double GFluidWK(double capacity_flow_w_k, double r0_per_area, double r1_fluid) {
  if (!(capacity_flow_w_k > 0.0)) return 0.0;
  const double two_w = 2.0 * capacity_flow_w_k;
  return two_w / (r1_fluid + two_w * r0_per_area);
}

}  // namespace pvtwin
