#include "core/model/sensitivities.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/common/threads.h"
#include "core/model/model_row.h"
#include "core/model/thermal_model.h"
#include "core/physics/rc_network_tangent.h"

namespace pvtwin {

namespace {

using namespace model_row;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kMaxCols = kMaxRcTangents;
using Column = double[kMaxCols];

// A whole column array copied or zeroed: a size the compiler knows becomes a
// few vector moves inline, where a copy of the run's `cols` entries was a
// library call, several per row (5-9 % of a run's perf samples in a scratch
// program; 1.9 % of a whole calibrate's instructions under callgrind). The
// entries past `cols` are never read.
void CopyColumn(const double* from, double* to) { std::memcpy(to, from, sizeof(Column)); }
void ZeroColumn(double* to) { std::memset(to, 0, sizeof(Column)); }

// What one sensitivity run reads besides the row. A run may do a share of
// the columns (SimSensitivities::threads): wrt are then its parameters,
// written to the output's columns from col0 on.
struct SensRun {
  const Drivers& d;
  const RunConstants& k;
  const RunInputs& w;
  std::span<const Param> wrt;
  int cols;
  std::size_t col0;
  bool values;            // writes the outputs' values too (one share does)
  SensitivitySink* sink;  // the derivatives go there when set
  bool outlet;  // also the collector node's and the outlet's temperature (SimSensitivities)
  bool t_pv;    // the derivatives of T_PV (SimSensitivities::t_pv_derivatives)
};

// Derivatives of one row's terms (RowTerms, the parameters' products)
// with respect to each parameter of wrt: d(term)/d(wrt[j]) at [j].
struct RowTermTangents {
  Column g_front_w_k, g_fluid_w_k, q_sun_w;
  Column eta_at_ref_temp;   // η_PVref·(1 + f_corr_I·(I_gt − I_gtref))
  Column temp_coeff_per_k;  // f_corr_T
  Column eps_pvt, area_m2;
  Column g_back_w_k, g_coll_w_k, c_pv_j_k, c_coll_j_k;
  Column f_th, p_per_eta_w;  // F_th and, with electric effects, RowTerms::p_per_eta_w
};

// The partial derivatives of row i's terms by parameter, scattered to the
// columns. A column's parameter writes the same entries at every row (zero
// where the row has none), so *t is zeroed once per run, not per row.
// Paper 2.8 ('w'): U = 1/(1/U_front + r_refwind·v^n), so dU/dU_front =
// U²/U_front², dU/dr_refwind = −U²·v^n, dU/dn = −U²·r_refwind·v^n·ln v.
// Eq. 2.7 per field: G_fluid = 2w/(r1 + 2w·r0/A), so dG/dr1 = −G²/(2w),
// dG/dr0 = −G²/A, dG/dA = G²·r0/A².
void MakeRowTermTangents(const SensRun& run, const RowTerms& r, std::size_t i, RowTermTangents* t) {
  const RunConstants& k = run.k;
  const double area = k.area_m2;
  const double u_front = r.g_front_w_k / area;
  double du_dufront = 1.0, du_drref = 0.0, du_dn = 0.0;
  if (k.wind_paper) {
    const double wind_pow = WindPower(run.w.ln_wind[i], k.n_wind);
    const double u2 = u_front * u_front;
    du_dufront = u2 * k.r_front_m2k_w * k.r_front_m2k_w;
    du_drref = -u2 * wind_pow;
    du_dn = wind_pow > 0.0 ? -u2 * k.r_refwind * wind_pow * run.w.ln_wind[i] : 0.0;
  }
  const double cap_w_k = run.d.capacity_flow_w_k[i];
  const double g_fl = r.g_fluid_w_k;
  const bool flow = cap_w_k > 0.0;
  const double g_abs = run.w.g_abs_w_m2[i];
  const double pv_factor = run.w.pv_factor != nullptr ? run.w.pv_factor[i] : 1.0;
  const double irr_dev = run.w.g_poa_w_m2[i] - k.pv.pv_g_ref_w_m2;
  const bool two = k.nodes == 2;
  for (int j = 0; j < run.cols; ++j) {
    switch (run.wrt[static_cast<std::size_t>(j)]) {
      case Param::kAreaM2:
        t->area_m2[j] = 1.0;
        t->g_front_w_k[j] = u_front;
        t->g_fluid_w_k[j] = flow ? g_fl * g_fl * k.r0_fluid_per_area / area : 0.0;
        t->q_sun_w[j] = k.f_th * g_abs;
        t->p_per_eta_w[j] = g_abs * pv_factor;
        t->g_back_w_k[j] = k.g_back_w_k / area;
        t->g_coll_w_k[j] = two ? k.g_coll_w_k / area : 0.0;
        t->c_pv_j_k[j] = k.c_pv_j_k / area;
        t->c_coll_j_k[j] = k.c_coll_j_k / area;
        break;
      case Param::kEpsPvt:
        t->eps_pvt[j] = k.sky ? 1.0 : 0.0;
        break;
      case Param::kEtaPvRef:
        t->eta_at_ref_temp[j] = 1.0 + k.pv.pv_irr_coeff_m2_w * irr_dev;
        break;
      case Param::kFTh:
        t->q_sun_w[j] = area * g_abs;
        t->f_th[j] = 1.0;
        break;
      case Param::kUFrontWM2K:
        t->g_front_w_k[j] = area * du_dufront;
        break;
      case Param::kUBackWM2K:
        t->g_back_w_k[j] = area;
        break;
      case Param::kUCollWM2K:
        t->g_coll_w_k[j] = two ? area : 0.0;
        break;
      case Param::kR0FluidM2KW:
        t->g_fluid_w_k[j] = flow ? -g_fl * g_fl / area : 0.0;
        break;
      case Param::kR1Fluid:
        t->g_fluid_w_k[j] = flow ? -g_fl * g_fl / (2.0 * cap_w_k) : 0.0;
        break;
      case Param::kCPvJM2K:
        t->c_pv_j_k[j] = k.c_pv_j_k > 0.0 ? area : 0.0;
        break;
      case Param::kCCollJM2K:
        t->c_coll_j_k[j] = k.c_coll_j_k > 0.0 ? area : 0.0;
        break;
      case Param::kRRefWind:
        t->g_front_w_k[j] = area * du_drref;
        break;
      case Param::kNWind:
        t->g_front_w_k[j] = area * du_dn;
        break;
      case Param::kPvTempCoeffPerK:
        t->temp_coeff_per_k[j] = 1.0;
        break;
      case Param::kPvIrrCoeffM2W:
        t->eta_at_ref_temp[j] = k.pv.eta_pv_ref * irr_dev;
        break;
      default:  // not used by the base model, or read by a hook (HookParams)
        break;
    }
  }
}

// η_PV at t_c (eq. 2.4) with its slope and, per column, the derivatives of
// both at fixed t_c; all zero where the efficiency is clamped to [0, 1].
struct EfficiencyTangent {
  double eta, slope_per_k;
  Column d_eta, d_slope;
};

void EfficiencyAt(const RunConstants& k, const RowTerms& r, const RowTermTangents& t, double t_c,
                  int cols, EfficiencyTangent* e) {
  e->eta = r.eta.At(t_c);
  e->slope_per_k = r.eta.SlopeAt(t_c);
  const double dev = t_c - r.eta.t_ref_c;
  const double coeff = k.pv.pv_temp_coeff_per_k;
  const double eta0 = r.eta.eta_at_ref_temp;
  const bool free = e->eta > 0.0 && e->eta < 1.0;  // else clamped: constant
  for (int j = 0; j < cols; ++j) {
    // η = η0 + η0·f_corr_T·(T − T_ref), slope = η0·f_corr_T.
    const double d_eta0 = t.eta_at_ref_temp[j];
    const double d_coeff = t.temp_coeff_per_k[j];
    e->d_eta[j] = free ? d_eta0 * (1.0 + coeff * dev) + eta0 * d_coeff * dev : 0.0;
    e->d_slope[j] = free ? d_eta0 * coeff + eta0 * d_coeff : 0.0;
  }
}

// The sun's power that leaves the PV node as electricity, as its heat
// balance counts it (FluxesAt: Q_abs = q_sun − conversion): q_sun·η without
// electric effects; F_th·P_el with them, P_el = min(η·p_per_eta, P_limit),
// constant where clipped. With its slope in T_PV and, per column, the
// derivatives of both at fixed T_PV (`e` at the same T_PV). The limit's own
// dependence on A_PVT is the clipping hook's (HookParams): not a column.
struct ConversionTangent {
  double slope_per_k;
  Column d_value, d_slope;
};

template <bool kElectric>
void ConversionAt(const RunConstants& k, const RowTerms& r, const RowTermTangents& t,
                  const EfficiencyTangent& e, int cols, ConversionTangent* c) {
  if constexpr (kElectric) {
    if (e.eta * r.p_per_eta_w >= r.p_limit_w) {  // RowTerms::PElW's test
      c->slope_per_k = 0.0;
      for (int j = 0; j < cols; ++j) {
        c->d_value[j] = t.f_th[j] * r.p_limit_w;
        c->d_slope[j] = 0.0;
      }
      return;
    }
  }
  const double scale = kElectric ? k.f_th * r.p_per_eta_w : r.q_sun_w;
  c->slope_per_k = scale * e.slope_per_k;
  for (int j = 0; j < cols; ++j) {
    const double d_scale =
        kElectric ? t.f_th[j] * r.p_per_eta_w + k.f_th * t.p_per_eta_w[j] : t.q_sun_w[j];
    c->d_value[j] = d_scale * e.eta + scale * e.d_eta[j];
    c->d_slope[j] = d_scale * e.slope_per_k + scale * e.d_slope[j];
  }
}

// The derivatives of the network that `l` linearised about t_lin (see
// Linearise), per column: of the row terms `t` at fixed t_lin, plus the
// linearisation point's own derivative d_lin times its effect (d G_PV/d t_lin
// = q_rad'', d S_PV/d t_lin = q_rad''·t_lin, and q_abs' when the Q_abs slope
// stays explicit). d_start: the derivatives of the start temperatures.
template <RcShape kShape, bool kSky, bool kElectric>
void NetworkTangent(const SensRun& run, const RowTerms& r, const Linearised& l,
                    const RowTermTangents& t, const double* d_lin, const double* d_start0,
                    const double* d_start1, RcNetworkTangent* dn) {
  const RunConstants& k = run.k;
  const int cols = run.cols;
  const double x = l.t_lin_c;
  EfficiencyTangent e;
  EfficiencyAt(k, r, t, x, cols, &e);
  ConversionTangent c;
  ConversionAt<kElectric>(k, r, t, e, cols, &c);
  const bool slope_in_g = l.lin.dq_abs_w_k != 0.0;
  double kappa_g = 0.0, kappa_s = 0.0, r1 = 0.0, r0 = 0.0;
  if constexpr (kSky) {
    const double xk = CToK(x);
    r1 = 4.0 * kStefanBoltzmannW_m2k4 * xk * xk * xk;                // q_rad'/(ε·A)
    r0 = kStefanBoltzmannW_m2k4 * (xk * xk * xk * xk - r.t_sky_k4);  // q_rad/(ε·A)
    kappa_g = 12.0 * k.eps_pvt * kStefanBoltzmannW_m2k4 * k.area_m2 * xk * xk;
    kappa_s = kappa_g * x;
  }
  if (!slope_in_g) kappa_s -= c.slope_per_k;
  constexpr int f = FluidNode(kShape);
  dn->directions = cols;
  for (int j = 0; j < cols; ++j) {
    double g0 = t.g_front_w_k[j];
    double s0 = t.g_front_w_k[j] * r.t_amb_c;
    if constexpr (kSky) {
      const double d_eps_area = k.area_m2 * t.eps_pvt[j] + k.eps_pvt * t.area_m2[j];
      g0 += r1 * d_eps_area;
      s0 += (r1 * x - r0) * d_eps_area;
    }
    g0 += kappa_g * d_lin[j];
    s0 += kappa_s * d_lin[j];
    const double dq = t.q_sun_w[j];
    if (slope_in_g) {  // G += conversion', S += q_sun − conversion + conversion'·x
      g0 += c.d_slope[j];
      s0 += dq - c.d_value[j] + c.d_slope[j] * x;
    } else {  // S += q_sun − conversion
      s0 += dq - c.d_value[j];
    }
    dn->conductance_w_k[0][j] = g0;
    dn->source_w[0][j] = s0;
    if constexpr (f == 1) {
      dn->conductance_w_k[1][j] = 0.0;
      dn->source_w[1][j] = 0.0;
    }
    dn->conductance_w_k[f][j] += t.g_back_w_k[j] + t.g_fluid_w_k[j];
    dn->source_w[f][j] += t.g_back_w_k[j] * r.t_back_c + t.g_fluid_w_k[j] * r.t_in_c;
    dn->coupling_w_k[j] = t.g_coll_w_k[j];
    dn->capacitance_j_k[0][j] = t.c_pv_j_k[j];
    dn->capacitance_j_k[1][j] = t.c_coll_j_k[j];
    dn->t_start_c[0][j] = d_start0[j];
    dn->t_start_c[1][j] = d_start1[j];
  }
}

// One row solved as SolveRow (thermal_model.cc) does, keeping each pass's
// linearisation and step; returns the number of passes (the row's result
// is the last pass's).
template <RcShape kShape, bool kSky, bool kElectric>
int SolveRowPasses(const RunConstants& k, const RowTerms& r, const double start[2], double dt_s,
                   bool steady, double t_guess_c, Linearised lins[kMaxNodeIterations],
                   RcStepResult results[kMaxNodeIterations]) {
  double t_lin = t_guess_c;
  PvFluxes at = FluxesAt<kSky, kElectric>(k, r, t_lin);
  int passes = 0;
  for (int it = 0; it < kMaxNodeIterations; ++it) {
    Linearised* l = &lins[passes];
    RcStepResult* result = &results[passes++];
    Linearise<kShape, kSky>(k, r, t_lin, at, l);
    *result = steady ? SteadyRc(l->net) : AdvanceRcShaped<kShape>(l->net, start, dt_s);
    const double t_pv = result->t_mean_c[0];
    if (!std::isfinite(t_pv)) break;
    at = FluxesAt<kSky, kElectric>(k, r, t_pv);
    if (LinearisationConverged<kSky>(*l, at, t_pv)) break;
    t_lin = t_pv;
  }
  return passes;
}

// The derivatives of one solved row (steady or a step from `start`) through
// its passes: the first pass's linearisation point has derivatives d_guess,
// each next one the previous pass's step-mean T_PV derivatives.
template <RcShape kShape, bool kSky, bool kElectric>
void RowTangent(const SensRun& run, const RowTerms& r, const RowTermTangents& t,
                const Linearised lins[], const RcStepResult results[], int passes,
                const double start[2], double dt_s, bool steady, const double* d_guess,
                const double* d_start0, const double* d_start1, RcStepTangent* out) {
  RcNetworkTangent dn;
  Column d_lin;
  CopyColumn(d_guess, d_lin);
  for (int pass = 0; pass < passes; ++pass) {
    const Linearised& l = lins[pass];
    NetworkTangent<kShape, kSky, kElectric>(run, r, l, t, d_lin, d_start0, d_start1, &dn);
    if (steady) {
      SteadyRcTangent(l.net, results[pass], dn, out);
    } else {
      AdvanceRcTangent<kShape>(l.net, start, dt_s, results[pass], dn, out);
    }
    CopyColumn(out->t_mean_c[0], d_lin);
  }
  if constexpr (!TwoNodes(kShape)) {
    ZeroColumn(out->t_end_c[1]);
    ZeroColumn(out->t_mean_c[1]);
  }
}

// Row i's outputs and their derivatives from its step `res`, `dres`.
template <RcShape kShape, bool kElectric>
void WriteSensRow(const SensRun& run, const RowTerms& r, const RowTermTangents& t, std::size_t i,
                  const RcStepResult& res, const RcStepTangent& dres, SimSensitivities* out) {
  const RunConstants& k = run.k;
  const std::size_t n = out->rows;
  const double t_pv = res.t_mean_c[0];
  const double t_fluid = res.t_mean_c[FluidNode(kShape)];
  const double g_abs = run.w.g_abs_w_m2[i];
  EfficiencyTangent e;
  EfficiencyAt(k, r, t, t_pv, run.cols, &e);
  const bool flow = run.d.mdot_kg_s[i] > 0.0;
  if (run.values) {
    out->t_pv_c[i] = t_pv;
    const double q_th_w = r.g_fluid_w_k * (t_fluid - r.t_in_c);
    out->q_th_w[i] = q_th_w;
    // The outlet as Simulate's WriteRow: without flow the fluid rests at
    // the node temperature.
    if (run.outlet) {
      out->t_coll_c[i] = t_fluid;
      out->t_out_c[i] = flow ? r.t_in_c + q_th_w / run.d.capacity_flow_w_k[i] : t_fluid;
    }
    // P_el as Simulate's WriteRow: η·A·I_at, or RowTerms::PElW with
    // electric effects (constant where clipped).
    if constexpr (kElectric) {
      double unused_slope;
      out->p_el_w[i] = r.PElW(t_pv, &unused_slope);
    } else {
      out->p_el_w[i] = e.eta * k.area_m2 * g_abs;
    }
  }
  bool clipped = false;
  if constexpr (kElectric) clipped = e.eta * r.p_per_eta_w >= r.p_limit_w;
  SensitivitySink* sink = run.sink;
  if (sink != nullptr && sink->position[i] < 0) return;
  for (int j = 0; j < run.cols; ++j) {
    const std::size_t c = run.col0 + static_cast<std::size_t>(j);
    const double d_pv = dres.t_mean_c[0][j];
    const double d_fluid = dres.t_mean_c[FluidNode(kShape)][j];
    const double dq = t.g_fluid_w_k[j] * (t_fluid - r.t_in_c) + r.g_fluid_w_k * d_fluid;
    double dp;
    if constexpr (kElectric) {
      dp = clipped ? 0.0
                   : (e.d_eta[j] + e.slope_per_k * d_pv) * r.p_per_eta_w + e.eta * t.p_per_eta_w[j];
    } else {
      dp = (e.d_eta[j] + e.slope_per_k * d_pv) * k.area_m2 * g_abs + e.eta * t.area_m2[j] * g_abs;
    }
    if (sink != nullptr) {
      double* at =
          sink->base + sink->column[c] * sink->stride + static_cast<std::size_t>(sink->position[i]);
      const double f = sink->column_factor[c];
      const double vp = dp * sink->value_factor * f;
      const double vq = dq * sink->value_factor * f;
      at[0] = vp;
      at[sink->rows] = vq;
      if (!std::isfinite(vp) || !std::isfinite(vq)) sink->finite[c] = 0;
      if (run.t_pv) {
        const double vt = sink->t_pv_factor * d_pv * f;
        at[2 * sink->rows] = vt;
        if (!std::isfinite(vt)) sink->finite[c] = 0;
      }
      continue;
    }
    const std::size_t col = c * n;
    if (run.t_pv) out->dt_pv_c[col + i] = d_pv;
    out->dq_th_w[col + i] = dq;
    if (run.outlet) {
      out->dt_coll_c[col + i] = d_fluid;
      out->dt_out_c[col + i] = flow ? dq / run.d.capacity_flow_w_k[i] : d_fluid;
    }
    out->dp_el_w[col + i] = dp;
  }
}

void SetSensRowNaN(const SensRun& run, SimSensitivities* out, std::size_t i) {
  if (run.values) {
    out->p_el_w[i] = out->q_th_w[i] = out->t_pv_c[i] = kNaN;
    if (run.outlet) out->t_coll_c[i] = out->t_out_c[i] = kNaN;
  }
  if (SensitivitySink* sink = run.sink; sink != nullptr) {
    // A row in the sink without a result: its columns are not finite.
    if (sink->position[i] >= 0) {
      for (int j = 0; j < run.cols; ++j) sink->finite[run.col0 + static_cast<std::size_t>(j)] = 0;
    }
    return;
  }
  for (int j = 0; j < run.cols; ++j) {
    const std::size_t at = (run.col0 + static_cast<std::size_t>(j)) * out->rows + i;
    out->dp_el_w[at] = out->dq_th_w[at] = kNaN;
    if (run.t_pv) out->dt_pv_c[at] = kNaN;
    if (run.outlet) out->dt_coll_c[at] = out->dt_out_c[at] = kNaN;
  }
}

// The state a row hands to the next: node temperatures at its end, the
// last two step-mean T_PV (the next linearisation guess), and their
// derivatives.
struct SensState {
  double t_c[2] = {0.0, 0.0};
  double t_pv_prev = kNaN, t_pv_prev2 = kNaN;
  Column d_t0{}, d_t1{}, d_prev{}, d_prev2{};

  void TakeEnd(const RcStepResult& res, const RcStepTangent& d) {
    t_c[0] = res.t_end_c[0];
    t_c[1] = res.t_end_c[1];
    CopyColumn(d.t_end_c[0], d_t0);
    CopyColumn(d.t_end_c[1], d_t1);
  }
};

// The row loop of Simulate (IntegrateRows) with the derivatives.
template <RcShape kShape, bool kSky, bool kElectric>
void IntegrateRowsSens(const SensRun& run, SimSensitivities* out) {
  const Drivers& d = run.d;
  const int cols = run.cols;
  SensState s;
  bool need_restart = true;
  RcStepResult res;
  RcStepTangent dres;
  RowTermTangents t{};
  Linearised lins[kMaxNodeIterations];
  RcStepResult pass_results[kMaxNodeIterations];
  Column d_guess, zero{};
  for (std::size_t i = 0; i < d.size(); ++i) {
    const RowTerms r = MakeRowTerms<kElectric>(run.k, d, run.w, i);
    if (!d.usable[i] || !RowInputsFinite(r)) {
      SetSensRowNaN(run, out, i);
      need_restart = true;
      continue;
    }
    MakeRowTermTangents(run, r, i, &t);
    if (need_restart || d.restart[i]) {
      // Paper 2.2: the steady state of this row's inputs, from T_amb (data).
      const int passes = SolveRowPasses<kShape, kSky, kElectric>(run.k, r, s.t_c, 0.0, true,
                                                                 r.t_amb_c, lins, pass_results);
      res = pass_results[passes - 1];
      RowTangent<kShape, kSky, kElectric>(run, r, t, lins, pass_results, passes, s.t_c, 0.0, true,
                                          zero, zero, zero, &dres);
      s.TakeEnd(res, dres);
      s.t_pv_prev = s.t_pv_prev2 = res.t_mean_c[0];
      CopyColumn(dres.t_mean_c[0], s.d_prev);
      CopyColumn(dres.t_mean_c[0], s.d_prev2);
      need_restart = false;
    }
    const double start[2] = {s.t_c[0], s.t_c[1]};
    const double guess = 2.0 * s.t_pv_prev - s.t_pv_prev2;
    for (int j = 0; j < cols; ++j) d_guess[j] = 2.0 * s.d_prev[j] - s.d_prev2[j];
    const int passes = SolveRowPasses<kShape, kSky, kElectric>(run.k, r, start, d.dt_s[i], false,
                                                               guess, lins, pass_results);
    res = pass_results[passes - 1];
    RowTangent<kShape, kSky, kElectric>(run, r, t, lins, pass_results, passes, start, d.dt_s[i],
                                        false, d_guess, s.d_t0, s.d_t1, &dres);
    s.TakeEnd(res, dres);
    s.t_pv_prev2 = s.t_pv_prev;
    s.t_pv_prev = res.t_mean_c[0];
    CopyColumn(s.d_prev, s.d_prev2);
    CopyColumn(dres.t_mean_c[0], s.d_prev);
    WriteSensRow<kShape, kElectric>(run, r, t, i, res, dres, out);
  }
}

using SensLoop = void (*)(const SensRun& run, SimSensitivities* out);

// The outputs and their derivatives through the spec's transform_outputs
// hooks, each affine in the outputs (ModelExtension::outputs_affine): with
// y the outputs before them and d a column, T(y + s·d) − T(y) = s·T'd. The
// scale s makes the largest entry of s·d one unit (K or W), far above the
// rounding of T(y) and, T being affine, without truncation error. Each
// application starts from the hooks' work space as the run left it.
void PushThroughOutputTransforms(const Drivers& d, const ParamVector& params, RunInputs* w,
                                 SimSensitivities* out) {
  const std::size_t n = out->rows, used = w->work_used;
  auto apply = [&](SimOutputs* y) {
    w->work_used = used;
    for (const ModelExtension* e : d.spec.extensions) {
      if (e->transform_outputs != nullptr) e->transform_outputs(d, params, w, y);
    }
  };
  // (SimOutputs field, value before, derivatives before) of what a hook may read.
  struct Field {
    std::vector<double> SimOutputs::*y;
    std::vector<double>* value;
    std::vector<double>* d;
  };
  const Field fields[] = {{&SimOutputs::p_el_w, &out->p_el_w, &out->dp_el_w},
                          {&SimOutputs::q_th_w, &out->q_th_w, &out->dq_th_w},
                          {&SimOutputs::t_pv_c, &out->t_pv_c, &out->dt_pv_c},
                          {&SimOutputs::t_coll_c, &out->t_coll_c, &out->dt_coll_c},
                          {&SimOutputs::t_out_c, &out->t_out_c, &out->dt_out_c}};
  SimOutputs& base = out->hook_work;
  SimOutputs& pushed = out->pushed;
  for (const Field& f : fields) base.*f.y = *f.value;
  apply(&base);
  for (std::size_t j = 0; j < out->wrt.size(); ++j) {
    double largest = 0.0;
    for (const Field& f : fields) {
      for (std::size_t i = 0; i < n; ++i) {
        const double v = std::fabs((*f.d)[j * n + i]);
        if (v > largest && std::isfinite(v)) largest = v;
      }
    }
    if (!(largest > 0.0)) continue;  // a zero column stays zero
    const double s = 1.0 / largest;
    for (const Field& f : fields) {
      std::vector<double>& y = pushed.*f.y;
      y.resize(n);
      for (std::size_t i = 0; i < n; ++i) y[i] = (*f.value)[i] + s * (*f.d)[j * n + i];
    }
    apply(&pushed);
    for (const Field& f : fields) {
      const std::vector<double>& y = pushed.*f.y;
      const std::vector<double>& y0 = base.*f.y;
      for (std::size_t i = 0; i < n; ++i) (*f.d)[j * n + i] = (y[i] - y0[i]) / s;
    }
  }
  for (const Field& f : fields) *f.value = base.*f.y;
}

template <RcShape kShape>
SensLoop PickSensLoop(bool sky, bool electric) {
  if (sky) {
    return electric ? &IntegrateRowsSens<kShape, true, true>
                    : &IntegrateRowsSens<kShape, true, false>;
  }
  return electric ? &IntegrateRowsSens<kShape, false, true>
                  : &IntegrateRowsSens<kShape, false, false>;
}

// The network shape of a spec (every capacitance parameter is positive
// within its bounds).
RcShape SpecShape(const ModelSpec& spec) {
  RcNetwork net;
  net.nodes = spec.nodes;
  net.node[0].capacitance_j_k = spec.c_pv ? 1.0 : 0.0;
  net.node[1].capacitance_j_k = spec.nodes == 2 && spec.c_coll ? 1.0 : 0.0;
  return ShapeOf(net);
}

SensLoop PickSensLoop(const ModelSpec& spec, bool electric) {
  switch (SpecShape(spec)) {
    case RcShape::kOneAlgebraic:
      return PickSensLoop<RcShape::kOneAlgebraic>(spec.sky, electric);
    case RcShape::kOneCapacitive:
      return PickSensLoop<RcShape::kOneCapacitive>(spec.sky, electric);
    case RcShape::kTwoAlgebraic:
      return PickSensLoop<RcShape::kTwoAlgebraic>(spec.sky, electric);
    case RcShape::kTwoCapacitive0:
      return PickSensLoop<RcShape::kTwoCapacitive0>(spec.sky, electric);
    case RcShape::kTwoCapacitive1:
      return PickSensLoop<RcShape::kTwoCapacitive1>(spec.sky, electric);
    case RcShape::kTwoCapacitiveBoth:
      break;
  }
  return PickSensLoop<RcShape::kTwoCapacitiveBoth>(spec.sky, electric);
}

}  // namespace

std::size_t MaxSensitivityParams() { return kMaxCols; }

std::vector<Param> WithoutHookParams(const ModelSpec& spec, std::span<const Param> params) {
  const std::vector<Param> hook = HookParams(spec);
  std::vector<Param> out;
  for (Param p : params) {
    if (std::find(hook.begin(), hook.end(), p) == hook.end()) out.push_back(p);
  }
  return out;
}

std::vector<Param> HookParams(const ModelSpec& spec) {
  std::vector<Param> out;
  for (const ModelExtension* e : spec.extensions) {
    for (const std::vector<Param>* list : {&e->params, &e->reads_base_params}) {
      for (Param p : *list) {
        if (std::find(out.begin(), out.end(), p) == out.end()) out.push_back(p);
      }
    }
  }
  return out;
}

bool SensitivitiesSupported(const ModelSpec& spec, std::span<const Param> wrt, std::string* why) {
  auto fail = [why](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  for (const ModelExtension* e : spec.extensions) {
    if (e->transform_outputs != nullptr && !e->outputs_affine) {
      return fail(spec.Name() + ": +" + std::string(e->name) +
                  " transforms the outputs, not affinely: no sensitivities (finite differences)");
    }
  }
  const std::vector<Param> hook = HookParams(spec);
  for (Param p : wrt) {
    if (std::find(hook.begin(), hook.end(), p) != hook.end()) {
      return fail(std::string(Info(p).name) + " is read by an effect's hook in " + spec.Name() +
                  ": no sensitivity (finite differences)");
    }
  }
  if (wrt.size() > MaxSensitivityParams()) {
    return fail(std::to_string(wrt.size()) + " parameters: at most " +
                std::to_string(MaxSensitivityParams()) + " per sensitivity run");
  }
  return true;
}

bool SimulateSensitivities(const Drivers& d, const ParamVector& params, std::span<const Param> wrt,
                           SimSensitivities* out, std::string* why) {
  if (!SensitivitiesSupported(d.spec, wrt, why)) return false;
  const std::size_t n = d.size();
  out->wrt.assign(wrt.begin(), wrt.end());
  out->rows = n;
  const bool outlet =
      std::any_of(d.spec.extensions.begin(), d.spec.extensions.end(),
                  [](const ModelExtension* e) { return e->transform_outputs != nullptr; });
  // The output transforms take every output's derivatives.
  const bool t_pv = out->t_pv_derivatives || outlet;
  // The output transforms read the stored derivatives.
  SensitivitySink* sink = outlet ? nullptr : out->sink;
  out->in_sink = sink != nullptr;
  const std::size_t stored = sink != nullptr ? 0 : n * wrt.size();
  for (auto* v : {&out->p_el_w, &out->q_th_w, &out->t_pv_c}) v->resize(n);
  for (auto* v : {&out->dp_el_w, &out->dq_th_w}) v->resize(stored);
  out->dt_pv_c.resize(t_pv ? stored : 0);
  if (sink != nullptr) sink->finite.assign(wrt.size(), 1);
  if (outlet) {
    for (auto* v : {&out->t_coll_c, &out->t_out_c}) v->resize(n);
    for (auto* v : {&out->dt_coll_c, &out->dt_out_c}) v->resize(n * wrt.size());
  }
  const RunConstants k = MakeConstants(d, params);
  RunInputs w;
  MakeRunInputs(d, params, &out->hook_work, &w);
  const SensLoop loop = PickSensLoop(d.spec, w.electric_effects);
  // Two shares of the columns, each with its own pass through the rows
  // (the values computed twice, written once): each column's derivatives
  // are the same arithmetic on either thread. For 14 days at 1 min and 11
  // columns 5.3 -> 4.0 ms (`bench sim`); at 5 min (4 032 rows) nothing
  // measurable in `calibrate --timing`, hence kSensitivitySplitWork. One
  // node's columns are too cheap to pay for writing the output arrays from
  // both cores (core/fit/README.md): `calibrate --timing --threads 1` and
  // `--threads 2` on the bench's 1-min days (medians of 9, alternated) had
  // the fine stage of 1N at 29.7 and 34.1 ms (1Nwr 41.7 and 48.3 ms, 1N1C
  // 30.3 and 31.5 ms), where two nodes gained (2N1Ccolwr 18.8 -> 16.1 ms,
  // 2N2Cwr 100.0 -> 85.0 ms, 2N1Cpvwr 92.6 -> 85.2 ms).
  const std::size_t cols = wrt.size();
  const bool split = out->threads > 1 && cols >= 2 && n * cols >= kSensitivitySplitWork &&
                     TwoNodes(SpecShape(d.spec));
  const std::size_t first = split ? (cols + 1) / 2 : cols;
  const SensRun run{d, k,    w,    wrt.first(first), static_cast<int>(first),
                    0, true, sink, outlet,           t_pv};
  if (first == cols) {
    loop(run, out);
  } else {
    const SensRun rest{
        d,    k,      w,   wrt.subspan(first), static_cast<int>(cols - first), first, false,
        sink, outlet, t_pv};
    RunBoth([&] { loop(rest, out); }, [&] { loop(run, out); });
  }
  if (outlet) PushThroughOutputTransforms(d, params, &w, out);
  return true;
}

}  // namespace pvtwin
