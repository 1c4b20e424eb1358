// The pieces of one row of the model run (thermal_model.h), shared by
// Simulate and the run with sensitivities (sensitivities.h) so that both do
// the same arithmetic: the run's parameter-dependent constants, the row
// terms, the PV node's non-linear fluxes and the network linearised about a
// PV temperature. Internal to core/model.
#pragma once

#include <cmath>
#include <cstddef>

#include "core/common/model_data.h"
#include "core/common/params.h"
#include "core/common/units.h"
#include "core/model/thermal_model.h"
#include "core/physics/fluid_coupling.h"
#include "core/physics/pv_efficiency.h"
#include "core/physics/rc_network.h"
#include "core/physics/sky_radiation.h"
#include "core/physics/wind.h"

namespace pvtwin::model_row {

inline double P(const ParamVector& p, Param name) { return p[static_cast<std::size_t>(name)]; }

// Parameter-dependent constants of one run (W/K and J/K for the whole field).
struct RunConstants {
  int nodes;
  double area_m2;
  double f_th;
  double c_pv_j_k;
  double c_coll_j_k;
  double g_back_w_k;
  double g_coll_w_k;
  double u_front_w_m2k;
  double r_refwind;
  double n_wind;
  double eps_pvt;
  double r0_fluid_per_area;  // r0_fluid / A_PVT
  double r_front_m2k_w;      // 1 / U_front
  double r1_fluid;
  bool wind_paper;
  bool sky;
  PvEfficiencyParams pv;
};

RunConstants MakeConstants(const Drivers& d, const ParamVector& p);

// The run's per-row inputs: the Drivers' arrays, then the hooks of the
// spec's extensions (ModelExtension::transform_drivers), weather timing
// (stage 0) before values (stage 1), each stage in variant order.
void MakeRunInputs(const Drivers& d, const ParamVector& p, SimOutputs* out, RunInputs* run);

// Everything about one row that does not depend on the node temperatures.
struct RowTerms {
  double g_front_w_k;
  double g_fluid_w_k;
  double q_sun_w;
  PvEfficiencyLinear eta;
  double t_amb_c, t_back_c, t_in_c, t_sky_k4;
  // P_el = min(η(T)·p_per_eta_w, p_limit_w) with electric effects.
  double p_per_eta_w;
  double p_limit_w;

  // Electrical power at T_PV = t_c and its slope (W/K).
  double PElW(double t_c, double* slope_w_k) const {
    const double p_dc_w = eta.At(t_c) * p_per_eta_w;
    if (p_dc_w >= p_limit_w) {
      *slope_w_k = 0.0;
      return p_limit_w;
    }
    *slope_w_k = eta.SlopeAt(t_c) * p_per_eta_w;
    return p_dc_w;
  }
};

// Computed in the row loop rather than in arrays before it: the loop's time
// is the latency of each row's Newton pass (it needs the previous row's
// T_PV), and this arithmetic fills the idle units meanwhile (arrays filled
// before the loop measured 15 % slower in `bench sim`).
template <bool kElectric>
[[gnu::always_inline]] inline RowTerms MakeRowTerms(const RunConstants& k, const Drivers& d,
                                                    const RunInputs& w, std::size_t i) {
  RowTerms r;
  double u_front = k.u_front_w_m2k;
  if (w.u_front_w_m2k != nullptr) {
    u_front = w.u_front_w_m2k[i];
  } else if (k.wind_paper) {
    u_front =
        FrontConductancePaperWM2K(k.r_front_m2k_w, k.r_refwind, WindPower(w.ln_wind[i], k.n_wind));
  }
  r.g_front_w_k = u_front * k.area_m2;
  r.g_fluid_w_k = w.g_fluid_w_k != nullptr
                      ? w.g_fluid_w_k[i]
                      : GFluidWK(d.capacity_flow_w_k[i], k.r0_fluid_per_area, k.r1_fluid);
  r.q_sun_w = k.f_th * k.area_m2 * w.g_abs_w_m2[i];
  r.eta = PvEfficiencyAt(k.pv, w.g_poa_w_m2[i]);
  r.t_amb_c = w.t_amb_c[i];
  r.t_back_c = w.t_back_c[i];
  r.t_in_c = d.t_in_c[i];
  r.t_sky_k4 = w.t_sky_k4[i];
  r.p_per_eta_w =
      kElectric ? k.area_m2 * w.g_abs_w_m2[i] * (w.pv_factor ? w.pv_factor[i] : 1.0) : 0.0;
  r.p_limit_w = w.p_limit_w;
  return r;
}

// The non-linear fluxes of the PV node at T_PV = t_c with their slopes: the
// sky loss (paper eq. 2.6, with 'r') and Q_abs (paper eq. 2.3: Q_abs =
// (1 − η)·F_th·A·I_at; when an effect limits or reduces P_el, the power that
// is not converted stays as heat: Q_abs = F_th·(A·I_at − P_el)).
struct PvFluxes {
  double q_rad_w = 0.0, dq_rad_w_k = 0.0;
  double q_abs_w, dq_abs_w_k;
};

template <bool kSky, bool kElectric>
[[gnu::always_inline]] inline PvFluxes FluxesAt(const RunConstants& k, const RowTerms& r,
                                                double t_c) {
  PvFluxes f;
  if constexpr (kSky) {
    const SkyRadiationLoss loss = SkyRadiation(k.eps_pvt, CToK(t_c), r.t_sky_k4);
    f.dq_rad_w_k = loss.dq_dt_w_m2k * k.area_m2;
    f.q_rad_w = loss.q_w_m2 * k.area_m2;
  }
  if constexpr (kElectric) {
    double dp_w_k;
    const double p_el_w = r.PElW(t_c, &dp_w_k);
    f.dq_abs_w_k = -k.f_th * dp_w_k;
    f.q_abs_w = r.q_sun_w - k.f_th * p_el_w;
  } else {
    f.dq_abs_w_k = -r.q_sun_w * r.eta.SlopeAt(t_c);
    f.q_abs_w = r.q_sun_w * (1.0 - r.eta.At(t_c));
  }
  return f;
}

// The network linearised about T_PV = t_lin_c, with the pieces needed to
// report its fluxes consistently.
struct Linearised {
  RcNetwork net;
  double t_lin_c;
  PvFluxes lin;         // at t_lin_c: Q ≈ lin.q + lin.dq·(T − t_lin); dq_abs 0 where explicit
  double g_pv_own_w_k;  // PV node conductance without the coupling
};

constexpr bool TwoNodes(RcShape shape) {
  return shape != RcShape::kOneAlgebraic && shape != RcShape::kOneCapacitive;
}

// The node that carries the back and fluid links (paper 2.10: the PV node
// in the one-node model).
constexpr int FluidNode(RcShape shape) { return TwoNodes(shape) ? 1 : 0; }

// Fills *out (in place: no struct copies in the row loop) from the fluxes
// `at` the linearisation point.
template <RcShape kShape, bool kSky>
[[gnu::always_inline]] inline void Linearise(const RunConstants& k, const RowTerms& r,
                                             double t_lin_c, const PvFluxes& at, Linearised* out) {
  Linearised& l = *out;
  l.net = RcNetwork{};
  l.t_lin_c = t_lin_c;
  l.lin = at;
  l.net.nodes = TwoNodes(kShape) ? 2 : 1;
  l.net.coupling_w_k = k.g_coll_w_k;
  l.net.node[0].capacitance_j_k = k.c_pv_j_k;
  if constexpr (TwoNodes(kShape)) l.net.node[1].capacitance_j_k = k.c_coll_j_k;

  RcNode& pv = l.net.node[0];
  pv.conductance_w_k = r.g_front_w_k;
  pv.source_w = r.g_front_w_k * r.t_amb_c;
  if constexpr (kSky) {
    pv.conductance_w_k += at.dq_rad_w_k;
    pv.source_w += at.dq_rad_w_k * t_lin_c - at.q_rad_w;
  }
  RcNode& fluid = l.net.node[FluidNode(kShape)];
  fluid.conductance_w_k += k.g_back_w_k + r.g_fluid_w_k;
  fluid.source_w += k.g_back_w_k * r.t_back_c + r.g_fluid_w_k * r.t_in_c;

  // Q_abs = q_sun·(1 − η(T)): η falls with T, so Q_abs rises with slope
  // −q_sun·dη/dT. The slope enters the conductance only while it leaves at
  // least half of the node's own loss conductance (it is tiny in any
  // physical case); otherwise it stays explicit and the iteration resolves it.
  if (l.lin.dq_abs_w_k > 0.5 * pv.conductance_w_k) l.lin.dq_abs_w_k = 0.0;
  pv.conductance_w_k -= l.lin.dq_abs_w_k;
  pv.source_w += l.lin.q_abs_w - l.lin.dq_abs_w_k * t_lin_c;
  l.g_pv_own_w_k = pv.conductance_w_k;
}

// True when the flux error that the linearisation leaves at T_PV = t_pv_c
// (where the fluxes are `at`) moves the PV node by less than kNodeToleranceK
// (error / own conductance).
template <bool kSky>
[[gnu::always_inline]] inline bool LinearisationConverged(const Linearised& l, const PvFluxes& at,
                                                          double t_pv_c) {
  const double dt = t_pv_c - l.t_lin_c;
  double flux_error_w = 0.0;
  if constexpr (kSky) flux_error_w += at.q_rad_w - (l.lin.q_rad_w + l.lin.dq_rad_w_k * dt);
  flux_error_w -= at.q_abs_w - (l.lin.q_abs_w + l.lin.dq_abs_w_k * dt);
  return std::fabs(flux_error_w) < kNodeToleranceK * l.g_pv_own_w_k;
}

// A weather value moved by an effect's hook may come from a row with a gap.
[[gnu::always_inline]] inline bool RowInputsFinite(const RowTerms& r) {
  return std::isfinite(r.q_sun_w) && std::isfinite(r.t_amb_c) && std::isfinite(r.t_back_c) &&
         std::isfinite(r.t_sky_k4) && std::isfinite(r.eta.eta_at_ref_temp) &&
         !std::isnan(r.g_front_w_k);
}

}  // namespace pvtwin::model_row
