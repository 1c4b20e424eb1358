#include "core/model/thermal_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "core/common/units.h"
#include "core/physics/fluid_coupling.h"
#include "core/physics/pv_efficiency.h"
#include "core/physics/rc_network.h"
#include "core/physics/sky_radiation.h"
#include "core/physics/wind.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double P(const ParamVector& p, Param name) { return p[static_cast<std::size_t>(name)]; }

// Parameter-dependent constants of one run (W/K and J/K for the whole field).
struct RunConstants {
  int nodes;
  int fluid_node;  // node that carries the back and fluid links
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

RunConstants MakeConstants(const Drivers& d, const ParamVector& p) {
  const ModelSpec& spec = d.spec;
  RunConstants k{};
  k.nodes = spec.nodes;
  k.fluid_node = spec.nodes == 2 ? 1 : 0;
  k.area_m2 = P(p, Param::kAreaM2);
  k.f_th = P(p, Param::kFTh);
  k.c_pv_j_k = spec.c_pv ? P(p, Param::kCPvJM2K) * k.area_m2 : 0.0;
  k.c_coll_j_k = spec.c_coll ? P(p, Param::kCCollJM2K) * k.area_m2 : 0.0;
  k.g_back_w_k = P(p, Param::kUBackWM2K) * k.area_m2;
  k.g_coll_w_k = spec.nodes == 2 ? P(p, Param::kUCollWM2K) * k.area_m2 : 0.0;
  k.u_front_w_m2k = P(p, Param::kUFrontWM2K);
  k.r_refwind = P(p, Param::kRRefWind);
  k.n_wind = P(p, Param::kNWind);
  k.eps_pvt = spec.sky ? P(p, Param::kEpsPvt) : 0.0;
  k.r0_fluid_per_area = P(p, Param::kR0FluidM2KW) / k.area_m2;
  k.r_front_m2k_w = 1.0 / k.u_front_w_m2k;
  k.r1_fluid = P(p, Param::kR1Fluid);
  k.wind_paper = spec.wind_paper;
  k.sky = spec.sky;
  k.pv = {P(p, Param::kEtaPvRef), P(p, Param::kPvTempCoeffPerK), P(p, Param::kPvIrrCoeffM2W),
          d.plant.pv_t_ref_c, d.plant.pv_g_ref_w_m2};
  return k;
}

// The run's per-row inputs: the Drivers' arrays, then the hooks of the
// spec's extensions (ModelExtension::transform_drivers), weather timing
// (stage 0) before values (stage 1), each stage in variant order.
void MakeRunInputs(const Drivers& d, const ParamVector& p, SimOutputs* out, RunInputs* run) {
  run->n = d.size();
  run->g_poa_w_m2 = d.g_poa_w_m2.data();
  run->g_abs_w_m2 = d.g_abs_w_m2.data();
  run->g_beam_w_m2 = d.g_beam_w_m2.data();
  run->t_amb_c = d.t_amb_c.data();
  run->t_back_c = d.t_back_c.data();
  run->ln_wind = d.ln_wind.data();
  run->t_sky_k4 = d.t_sky_k4.data();
  run->work = &out->work;
  for (int stage = 0; stage <= 1; ++stage) {
    for (const ModelExtension* e : d.spec.extensions) {
      if (e->transform_drivers != nullptr && e->driver_stage == stage) {
        e->transform_drivers(d, p, run);
      }
    }
  }
}

// Everything about one row that does not depend on the node temperatures.
struct RowTerms {
  double g_front_w_k;
  double g_fluid_w_k;
  double q_sun_w;  // F_th·A·I_at: heat absorbed if no electricity were produced
  PvEfficiencyLinear eta;
  double t_amb_c, t_back_c, t_in_c, t_sky_k4;
  // P_el = min(η(T)·p_per_eta_w, p_limit_w) when `electric`.
  double p_per_eta_w;  // A·I_at·pv_factor
  double p_limit_w;
  double f_th;
  bool electric;  // RunInputs::electric_effects

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

RowTerms MakeRowTerms(const RunConstants& k, const Drivers& d, const RunInputs& w, std::size_t i) {
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
  r.p_per_eta_w = k.area_m2 * w.g_abs_w_m2[i] * (w.pv_factor ? w.pv_factor[i] : 1.0);
  r.p_limit_w = w.p_limit_w;
  r.f_th = k.f_th;
  r.electric = w.electric_effects;
  return r;
}

// Q_abs at T_PV = t_c and its slope dQ_abs/dT (W, W/K). Paper eq. 2.3:
// Q_abs = (1 − η)·F_th·A·I_at. When an effect limits or reduces P_el
// (RunInputs::electric_effects) the power that is not converted stays as
// heat: Q_abs = F_th·(A·I_at − P_el).
double QAbsW(const RowTerms& r, double t_c, double* slope_w_k) {
  if (!r.electric) {
    *slope_w_k = -r.q_sun_w * r.eta.SlopeAt(t_c);
    return r.q_sun_w * (1.0 - r.eta.At(t_c));
  }
  double dp_w_k;
  const double p_el_w = r.PElW(t_c, &dp_w_k);
  *slope_w_k = -r.f_th * dp_w_k;
  return r.q_sun_w - r.f_th * p_el_w;
}

// The network linearised about T_PV = t_lin_c, with the pieces needed to
// report its fluxes consistently.
struct Linearised {
  RcNetwork net;
  double t_lin_c;
  double q_abs_lin_w, dq_abs_w_k;  // Q_abs ≈ q_abs_lin + dq_abs·(T − t_lin)
  double q_rad_lin_w, dq_rad_w_k;  // q_rad ≈ q_rad_lin + dq_rad·(T − t_lin)
  double g_pv_own_w_k;             // PV node conductance without the coupling
};

double SkyLossW(const RunConstants& k, const RowTerms& r, double t_pv_c, double* slope_w_k) {
  const SkyRadiationLoss loss = SkyRadiation(k.eps_pvt, CToK(t_pv_c), r.t_sky_k4);
  *slope_w_k = loss.dq_dt_w_m2k * k.area_m2;
  return loss.q_w_m2 * k.area_m2;
}

// Fills *out (in place: no struct copies in the row loop).
void Linearise(const RunConstants& k, const RowTerms& r, double t_lin_c, Linearised* out) {
  Linearised& l = *out;
  l.net = RcNetwork{};
  l.t_lin_c = t_lin_c;
  l.net.nodes = k.nodes;
  l.net.coupling_w_k = k.g_coll_w_k;
  l.net.node[0].capacitance_j_k = k.c_pv_j_k;
  if (k.nodes == 2) l.net.node[1].capacitance_j_k = k.c_coll_j_k;

  RcNode& pv = l.net.node[0];
  pv.conductance_w_k = r.g_front_w_k;
  pv.source_w = r.g_front_w_k * r.t_amb_c;
  if (k.sky) {
    l.q_rad_lin_w = SkyLossW(k, r, t_lin_c, &l.dq_rad_w_k);
    pv.conductance_w_k += l.dq_rad_w_k;
    pv.source_w += l.dq_rad_w_k * t_lin_c - l.q_rad_lin_w;
  } else {
    l.q_rad_lin_w = l.dq_rad_w_k = 0.0;
  }
  RcNode& fluid = l.net.node[k.fluid_node];
  fluid.conductance_w_k += k.g_back_w_k + r.g_fluid_w_k;
  fluid.source_w += k.g_back_w_k * r.t_back_c + r.g_fluid_w_k * r.t_in_c;

  // Q_abs = q_sun·(1 − η(T)): η falls with T, so Q_abs rises with slope
  // −q_sun·dη/dT. The slope enters the conductance only while it leaves at
  // least half of the node's own loss conductance (it is tiny in any
  // physical case); otherwise it stays explicit and the iteration resolves it.
  l.q_abs_lin_w = QAbsW(r, t_lin_c, &l.dq_abs_w_k);
  if (l.dq_abs_w_k > 0.5 * pv.conductance_w_k) l.dq_abs_w_k = 0.0;
  pv.conductance_w_k -= l.dq_abs_w_k;
  pv.source_w += l.q_abs_lin_w - l.dq_abs_w_k * t_lin_c;
  l.g_pv_own_w_k = pv.conductance_w_k;
}

// True when the flux error that the linearisation leaves at T_PV = t_pv_c
// moves the PV node by less than kNodeToleranceK (error / own conductance).
bool LinearisationConverged(const RunConstants& k, const RowTerms& r, const Linearised& l,
                            double t_pv_c) {
  const double dt = t_pv_c - l.t_lin_c;
  double flux_error_w = 0.0;
  if (k.sky) {
    double unused;
    flux_error_w += SkyLossW(k, r, t_pv_c, &unused) - (l.q_rad_lin_w + l.dq_rad_w_k * dt);
  }
  double unused_slope;
  flux_error_w -= QAbsW(r, t_pv_c, &unused_slope) - (l.q_abs_lin_w + l.dq_abs_w_k * dt);
  return std::fabs(flux_error_w) < kNodeToleranceK * l.g_pv_own_w_k;
}

// Solves one row: the steady state when `steady`, else one step from `start`.
// Re-linearises about the step-mean PV temperature until the linearisation
// error is below kNodeToleranceK.
void SolveRow(const RunConstants& k, const RowTerms& r, const double start[2], double dt_s,
              bool steady, double t_guess_c, Linearised* l, RcStepResult* result) {
  double t_lin = t_guess_c;
  for (int it = 0; it < kMaxNodeIterations; ++it) {
    Linearise(k, r, t_lin, l);
    *result = steady ? SteadyRc(l->net) : AdvanceRc(l->net, start, dt_s);
    const double t_pv = result->t_mean_c[0];
    if (!std::isfinite(t_pv) || LinearisationConverged(k, r, *l, t_pv)) break;
    t_lin = t_pv;
  }
}

void SetRowNaN(SimOutputs* out, std::size_t i, bool energy) {
  out->p_el_w[i] = out->q_th_w[i] = out->t_pv_c[i] = out->t_coll_c[i] = out->t_out_c[i] = kNaN;
  if (energy) {
    out->q_abs_w[i] = out->q_front_w[i] = out->q_back_w[i] = out->q_rad_w[i] = out->q_store_w[i] =
        kNaN;
  }
}

}  // namespace

void Simulate(const Drivers& d, const ParamVector& params, SimOutputs* out,
              const SimOptions& options) {
  const std::size_t n = d.size();
  const bool energy = options.energy_terms;
  for (auto* v : {&out->p_el_w, &out->q_th_w, &out->t_pv_c, &out->t_coll_c, &out->t_out_c}) {
    v->resize(n);
  }
  if (energy) {
    for (auto* v :
         {&out->q_abs_w, &out->q_front_w, &out->q_back_w, &out->q_rad_w, &out->q_store_w}) {
      v->resize(n);
    }
  }
  const RunConstants k = MakeConstants(d, params);
  RunInputs w;
  MakeRunInputs(d, params, out, &w);
  if (options.after_extensions) options.after_extensions(d, &w);
  double state[2] = {0.0, 0.0};  // node temperatures at the start of the row
  // Step-mean PV temperatures of the last two rows: their linear
  // extrapolation is the first linearisation point, which usually meets the
  // tolerance in one pass.
  double t_pv_prev = kNaN;
  double t_pv_prev2 = kNaN;
  bool need_restart = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (!d.usable[i]) {
      SetRowNaN(out, i, energy);
      need_restart = true;
      continue;
    }
    const RowTerms r = MakeRowTerms(k, d, w, i);
    // A weather value moved by an effect's hook may come from a row with a gap.
    if (!std::isfinite(r.q_sun_w) || !std::isfinite(r.t_amb_c) || !std::isfinite(r.t_back_c) ||
        !std::isfinite(r.t_sky_k4) || !std::isfinite(r.eta.eta_at_ref_temp) ||
        std::isnan(r.g_front_w_k)) {
      SetRowNaN(out, i, energy);
      need_restart = true;
      continue;
    }
    RcStepResult res;
    Linearised l;
    if (need_restart || d.restart[i]) {
      // Paper 2.2: start from the steady state of this row's inputs.
      SolveRow(k, r, state, 0.0, /*steady=*/true, r.t_amb_c, &l, &res);
      state[0] = res.t_end_c[0];
      state[1] = res.t_end_c[1];
      t_pv_prev = t_pv_prev2 = res.t_mean_c[0];
      need_restart = false;
    }
    const double start[2] = {state[0], state[1]};
    const double guess = 2.0 * t_pv_prev - t_pv_prev2;
    SolveRow(k, r, start, d.dt_s[i], /*steady=*/false, guess, &l, &res);
    state[0] = res.t_end_c[0];
    state[1] = res.t_end_c[1];
    const double t_pv = res.t_mean_c[0];
    const double t_fluid_node = res.t_mean_c[k.fluid_node];
    t_pv_prev2 = t_pv_prev;
    t_pv_prev = t_pv;

    const double q_u = r.g_fluid_w_k * (t_fluid_node - r.t_in_c);
    out->t_pv_c[i] = t_pv;
    out->t_coll_c[i] = res.t_mean_c[k.nodes == 2 ? 1 : 0];
    out->q_th_w[i] = q_u;
    if (r.electric) {
      double unused_slope;
      out->p_el_w[i] = r.PElW(t_pv, &unused_slope);
    } else {
      out->p_el_w[i] = r.eta.At(t_pv) * k.area_m2 * w.g_abs_w_m2[i];
    }
    // Without flow the fluid rests in the collector at the node temperature.
    out->t_out_c[i] = d.mdot_kg_s[i] > 0.0 ? r.t_in_c + q_u / d.capacity_flow_w_k[i] : t_fluid_node;
    if (energy) {
      const double dev = t_pv - l.t_lin_c;
      out->q_abs_w[i] = l.q_abs_lin_w + l.dq_abs_w_k * dev;
      out->q_rad_w[i] = l.q_rad_lin_w + l.dq_rad_w_k * dev;
      out->q_front_w[i] = r.g_front_w_k * (t_pv - r.t_amb_c);
      out->q_back_w[i] = k.g_back_w_k * (t_fluid_node - r.t_back_c);
      double stored_j = k.c_pv_j_k * (res.t_end_c[0] - start[0]);
      if (k.nodes == 2) stored_j += k.c_coll_j_k * (res.t_end_c[1] - start[1]);
      out->q_store_w[i] = stored_j / d.dt_s[i];
    }
  }
  for (const ModelExtension* e : d.spec.extensions) {
    if (e->transform_outputs != nullptr) e->transform_outputs(d, params, &w, out);
  }
}

}  // namespace pvtwin
