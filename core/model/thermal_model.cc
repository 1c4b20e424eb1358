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

// Solves one row: the steady state when `steady`, else one step from `start`.
// Re-linearises about the step-mean PV temperature until the linearisation
// error is below kNodeToleranceK; the fluxes of the convergence test are the
// next pass's linearisation point (Newton's method).
template <RcShape kShape, bool kSky, bool kElectric>
[[gnu::always_inline]] inline void SolveRow(const RunConstants& k, const RowTerms& r,
                                            const double start[2], double dt_s, bool steady,
                                            double t_guess_c, Linearised* l, RcStepResult* result) {
  double t_lin = t_guess_c;
  PvFluxes at = FluxesAt<kSky, kElectric>(k, r, t_lin);
  for (int it = 0; it < kMaxNodeIterations; ++it) {
    Linearise<kShape, kSky>(k, r, t_lin, at, l);
    *result = steady ? SteadyRc(l->net) : AdvanceRcShaped<kShape>(l->net, start, dt_s);
    const double t_pv = result->t_mean_c[0];
    if (!std::isfinite(t_pv)) break;
    at = FluxesAt<kSky, kElectric>(k, r, t_pv);
    if (LinearisationConverged<kSky>(*l, at, t_pv)) break;
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

// A weather value moved by an effect's hook may come from a row with a gap.
[[gnu::always_inline]] inline bool RowInputsFinite(const RowTerms& r) {
  return std::isfinite(r.q_sun_w) && std::isfinite(r.t_amb_c) && std::isfinite(r.t_back_c) &&
         std::isfinite(r.t_sky_k4) && std::isfinite(r.eta.eta_at_ref_temp) &&
         !std::isnan(r.g_front_w_k);
}

// What one run's row loop reads besides the row.
struct RunContext {
  const Drivers& d;
  const RunConstants& k;
  const RunInputs& w;
  bool energy;
};

// Writes row i's outputs from its step `res` (started at `start`) and the
// linearisation `l` it converged with.
template <RcShape kShape, bool kElectric>
[[gnu::always_inline]] inline void WriteRow(const RunContext& run, const RowTerms& r, std::size_t i,
                                            const double start[2], const RcStepResult& res,
                                            const Linearised& l, SimOutputs* out) {
  const RunConstants& k = run.k;
  const double t_pv = res.t_mean_c[0];
  const double t_fluid_node = res.t_mean_c[FluidNode(kShape)];
  const double q_u = r.g_fluid_w_k * (t_fluid_node - r.t_in_c);
  out->t_pv_c[i] = t_pv;
  out->t_coll_c[i] = res.t_mean_c[FluidNode(kShape)];
  out->q_th_w[i] = q_u;
  if constexpr (kElectric) {
    double unused_slope;
    out->p_el_w[i] = r.PElW(t_pv, &unused_slope);
  } else {
    out->p_el_w[i] = r.eta.At(t_pv) * k.area_m2 * run.w.g_abs_w_m2[i];
  }
  // Without flow the fluid rests in the collector at the node temperature.
  out->t_out_c[i] =
      run.d.mdot_kg_s[i] > 0.0 ? r.t_in_c + q_u / run.d.capacity_flow_w_k[i] : t_fluid_node;
  if (run.energy) {
    const double dev = t_pv - l.t_lin_c;
    out->q_abs_w[i] = l.lin.q_abs_w + l.lin.dq_abs_w_k * dev;
    out->q_rad_w[i] = l.lin.q_rad_w + l.lin.dq_rad_w_k * dev;
    out->q_front_w[i] = r.g_front_w_k * (t_pv - r.t_amb_c);
    out->q_back_w[i] = k.g_back_w_k * (t_fluid_node - r.t_back_c);
    double stored_j = k.c_pv_j_k * (res.t_end_c[0] - start[0]);
    if constexpr (TwoNodes(kShape)) stored_j += k.c_coll_j_k * (res.t_end_c[1] - start[1]);
    out->q_store_w[i] = stored_j / run.d.dt_s[i];
  }
}

// The row loop for one network shape, with or without the sky term and the
// electric effects: no test of the variant inside it.
template <RcShape kShape, bool kSky, bool kElectric>
void IntegrateRows(const RunContext& run, SimOutputs* out) {
  const Drivers& d = run.d;
  double state[2] = {0.0, 0.0};  // node temperatures at the start of the row
  // Step-mean PV temperatures of the last two rows: their linear
  // extrapolation is the first linearisation point, which usually meets the
  // tolerance in one pass.
  double t_pv_prev = kNaN;
  double t_pv_prev2 = kNaN;
  bool need_restart = true;
  RcStepResult res;
  Linearised l;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const RowTerms r = MakeRowTerms<kElectric>(run.k, d, run.w, i);
    if (!d.usable[i] || !RowInputsFinite(r)) {
      SetRowNaN(out, i, run.energy);
      need_restart = true;
      continue;
    }
    if (need_restart || d.restart[i]) {
      // Paper 2.2: start from the steady state of this row's inputs.
      SolveRow<kShape, kSky, kElectric>(run.k, r, state, 0.0, /*steady=*/true, r.t_amb_c, &l, &res);
      state[0] = res.t_end_c[0];
      state[1] = res.t_end_c[1];
      t_pv_prev = t_pv_prev2 = res.t_mean_c[0];
      need_restart = false;
    }
    const double start[2] = {state[0], state[1]};
    const double guess = 2.0 * t_pv_prev - t_pv_prev2;
    SolveRow<kShape, kSky, kElectric>(run.k, r, start, d.dt_s[i], /*steady=*/false, guess, &l,
                                      &res);
    state[0] = res.t_end_c[0];
    state[1] = res.t_end_c[1];
    t_pv_prev2 = t_pv_prev;
    t_pv_prev = res.t_mean_c[0];
    WriteRow<kShape, kElectric>(run, r, i, start, res, l, out);
  }
}

using RowLoop = void (*)(const RunContext& run, SimOutputs* out);

template <RcShape kShape>
RowLoop PickRowLoop(bool sky, bool electric) {
  if (sky) {
    return electric ? &IntegrateRows<kShape, true, true> : &IntegrateRows<kShape, true, false>;
  }
  return electric ? &IntegrateRows<kShape, false, true> : &IntegrateRows<kShape, false, false>;
}

// The row loop of this run's network shape (RcNetwork's capacitive nodes).
RowLoop PickRowLoop(const RunConstants& k, bool electric) {
  RcNetwork net;
  net.nodes = k.nodes;
  net.node[0].capacitance_j_k = k.c_pv_j_k;
  if (k.nodes == 2) net.node[1].capacitance_j_k = k.c_coll_j_k;
  switch (ShapeOf(net)) {
    case RcShape::kOneAlgebraic:
      return PickRowLoop<RcShape::kOneAlgebraic>(k.sky, electric);
    case RcShape::kOneCapacitive:
      return PickRowLoop<RcShape::kOneCapacitive>(k.sky, electric);
    case RcShape::kTwoAlgebraic:
      return PickRowLoop<RcShape::kTwoAlgebraic>(k.sky, electric);
    case RcShape::kTwoCapacitive0:
      return PickRowLoop<RcShape::kTwoCapacitive0>(k.sky, electric);
    case RcShape::kTwoCapacitive1:
      return PickRowLoop<RcShape::kTwoCapacitive1>(k.sky, electric);
    case RcShape::kTwoCapacitiveBoth:
      break;
  }
  return PickRowLoop<RcShape::kTwoCapacitiveBoth>(k.sky, electric);
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
  PickRowLoop(k, w.electric_effects)({d, k, w, energy}, out);
  for (const ModelExtension* e : d.spec.extensions) {
    if (e->transform_outputs != nullptr) e->transform_outputs(d, params, &w, out);
  }
}

}  // namespace pvtwin
