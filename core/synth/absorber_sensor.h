// The collector (absorber) temperature that the simulated plant's controller
// reads: a one-node lumped absorber, per m² of collector, with the truth
// plant's parameters. The weather generator decides the pump before the
// truth model runs on the whole series, so its controller cannot read the
// truth model's node; this sensor model runs inside the generator, step by
// step, in the same loop as the pump and the tank, and is the clean way to
// let the operation depend on the plant's temperature without running the
// (multi-node, delayed, whole-series) truth model row by row. It sees the
// same irradiance, ambient, wind, long-wave, flow and inlet as the truth
// model and uses its parameters (SensorParamsFromTruth in synthetic_plant.h),
// so it stagnates where the truth stagnates and falls toward the inlet when
// the pump runs: a real sensor on the absorber reads close to, not exactly,
// the model's node.
//
//   C·dT/dt = S + U_L·(T_a − T) + k_f·(T_in − T)
//   S   = (1 − η_PV,ref)·F_th·G + ε·(L↓ − σ·T_a⁴)          (paper eq. 2.3, sky
//         term linearised about T_a, +4εσT_a³ in U_L)
//   U_L = U_front + U_wind·w^n + U_back + 4·ε·σ·T_a³
//   1/k_f = r_internal + r0_fluid + r1_fluid/(2·w),  w = ṁ·c_p/A
//         (the truth model's fluid coupling, paper 2.7 after Koschenz &
//         Lehmann, params.h; r_internal = 1/U_coll in series for two-node
//         truths, 0 for one node); k_f = 0 without flow
//
// T = t_abs_c, T_a = t_amb_c, T_in = t_in_c (°C, σ with kelvin), G =
// g_poa_w_m2, L↓ = lw_down_w_m2, w = wind_m_s, ṁ = mdot_kg_s, A = area_m2.
// Inputs constant over the step; the step is exact for them (T relaxes to
// the steady state with τ = C/(U_L + k_f)), so any dt_s > 0 is stable.
// Q_u = k_f·(T − T_in)·A is the heat the fluid takes at the step's end.
#pragma once

namespace pvtwin {

struct AbsorberSensorParams {
  double absorbed_fraction = 0.76;       // (1 − η_PV,ref)·F_th, [0, 1]
  double u_front_w_m2k = 14.0;           // U_front, W/(m²K)
  double u_back_w_m2k = 1.5;             // U_back
  double u_wind_w_m2k = 3.0;             // U_wind, W/(m²K)/(m/s)^n
  double n_wind = 0.8;                   // n
  double eps_lw = 0.12;                  // ε, long-wave emittance
  double r_internal_m2k_w = 1.0 / 45.0;  // 1/U_coll (PV → collector node), ≥ 0
  double r0_fluid_m2k_w = 0.01;          // flow-independent absorber → fluid, ≥ 0
  double r1_fluid = 1.2;                 // flow-dependent part, > 0
  double c_j_m2k = 4.7e4;                // C, absorber + PV heat capacity
};

struct AbsorberSensorInput {
  double g_poa_w_m2 = 0.0;
  double t_amb_c = 0.0;
  double wind_m_s = 0.0;
  double lw_down_w_m2 = 0.0;  // on the collector plane
  double t_in_c = 0.0;
  double mdot_kg_s = 0.0;
  double area_m2 = 1.0;
  double fluid_cp_j_kgk = 3650.0;
  double dt_s = 60.0;
};

struct AbsorberSensorOutput {
  double t_abs_c = 0.0;  // at the step's end
  double q_u_w = 0.0;    // heat into the fluid at the step's end, W
};

// Steady state of the inputs (the start value, and τ → 0).
double AbsorberSteadyStateC(const AbsorberSensorParams& params, const AbsorberSensorInput& in);

// One step from t_abs_c.
AbsorberSensorOutput StepAbsorberSensor(const AbsorberSensorParams& params,
                                        const AbsorberSensorInput& in, double t_abs_c);

}  // namespace pvtwin
