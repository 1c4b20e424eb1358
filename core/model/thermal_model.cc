#include "core/model/thermal_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "core/model/model_row.h"

namespace pvtwin {

namespace model_row {

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

}  // namespace model_row

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using namespace model_row;

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
