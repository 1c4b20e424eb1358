// Directional derivatives (forward tangents) of the exact RC step of
// rc_network.h, in up to kMaxRcTangents directions at once: given the
// derivatives of the network's inputs (capacitances, conductances, sources,
// coupling, start temperatures) along each direction, the derivatives of the
// step's end and mean temperatures. Hand-derived from the closed forms of
// rc_network.h; used by the model run with sensitivities
// (core/model/sensitivities.h).
//
// One capacitive node (C·dT/dt = S − G·T over dt, u = G·dt/C):
//   T_end = T0 + (S − G·T0)·dt/C·φ1(u),   T_mean = T0 + (S − G·T0)·dt/C·φ2(u)
//   φ1(u) = (1 − e^(−u))/u,   φ1'(u) = (e^(−u) − φ1)/u
//   φ2(u) = (u − 1 + e^(−u))/u²,   φ2'(u) = (φ1 − 2·φ2)/u
// (Taylor series below |u| = kPhiSeriesBelow, differentiated term by term,
// as the values are computed). An algebraic node a coupled to a capacitive node b:
//   T_a = (S_a + g·T_b)/(G_a + g), and b sees S_b + g·S_a/(G_a + g) and
//   G_b + g·G_a/(G_a + g). Steady state: K·T = S with K = [G0+g, −g; −g,
//   G1+g], so K·dT = dS − dK·T.
// Two capacitive nodes (AdvanceTwo): with P = C^(−1/2) and the symmetric
// M = P·K·P = V·diag(λa, λb)·Vᵀ, T_end = T0 + P·g1(M)·P·(S − K·T0) with
// g1(λ) = dt·φ1(λ·dt) (g2, φ2 for the mean); the derivative of g(M) along
// dM is V·(Γ ∘ Vᵀ·dM·V)·Vᵀ with Γ_ab = (g(λa) − g(λb))/(λa − λb) and Γ_aa
// = g'(λa) (Daleckii–Krein; the mean of the slopes where λa ≈ λb).
#pragma once

#include <cmath>

#include "core/physics/rc_network.h"

namespace pvtwin {

inline constexpr int kMaxRcTangents = 16;

// Derivatives of an RcNetwork's inputs and start temperatures along
// `directions` directions (units as in RcNetwork, per unit of the direction).
struct RcNetworkTangent {
  int directions = 0;
  double capacitance_j_k[2][kMaxRcTangents];
  double conductance_w_k[2][kMaxRcTangents];
  double source_w[2][kMaxRcTangents];
  double coupling_w_k[kMaxRcTangents];
  double t_start_c[2][kMaxRcTangents];
};

// Derivatives of an RcStepResult along the same directions.
struct RcStepTangent {
  double t_end_c[2][kMaxRcTangents];
  double t_mean_c[2][kMaxRcTangents];
};

namespace rc_tangent {

struct PhiSlopes {
  double phi1, phi2;    // as ExpPhis (rc_network.h)
  double dphi1, dphi2;  // their derivatives in x
};

// The series' derivative Σ k·c_k·x^(k−1), by Estrin's scheme as PhiSeries.
inline double PhiSeriesSlope(const PhiSeriesCoefficients& s, double x) {
  static_assert(kPhiSeriesDegree == 9);
  const double* c = s.c;
  const double x2 = x * x;
  const double x4 = x2 * x2;
  const double p01 = c[1] + 2.0 * c[2] * x, p23 = 3.0 * c[3] + 4.0 * c[4] * x;
  const double p45 = 5.0 * c[5] + 6.0 * c[6] * x, p67 = 7.0 * c[7] + 8.0 * c[8] * x;
  return (p01 + x2 * p23) + x4 * ((p45 + x2 * p67) + x4 * (9.0 * c[9]));
}

inline PhiSlopes ExpPhisWithSlopes(double x) {
  if (std::fabs(x) < kPhiSeriesBelow) {
    return {PhiSeries(kPhi1Series, x), PhiSeries(kPhi2Series, x), PhiSeriesSlope(kPhi1Series, x),
            PhiSeriesSlope(kPhi2Series, x)};
  }
  const double e = std::exp(-x);
  const double inv_x = 1.0 / x;
  const double phi1 = (1.0 - e) * inv_x;
  const double phi2 = (1.0 - phi1) * inv_x;
  return {phi1, phi2, (e - phi1) * inv_x, (phi1 - 2.0 * phi2) * inv_x};
}

// Tangent of AdvanceOne (rc_network.h) for node inputs c, g, s, t0 with
// derivatives dc, dg, ds, dt0 (arrays over n directions).
inline void AdvanceOneTangent(double c, double g, double s, double t0, double dt_s,
                              const double* dc, const double* dg, const double* ds,
                              const double* dt0, int n, double* d_end, double* d_mean) {
  const double dt_over_c = dt_s / c;
  const double inv_c = 1.0 / c;
  const double rate = (s - g * t0) * dt_over_c;
  const double u = g * dt_over_c;
  const PhiSlopes ph = ExpPhisWithSlopes(u);
  for (int j = 0; j < n; ++j) {
    const double d_rate = (ds[j] - dg[j] * t0 - g * dt0[j]) * dt_over_c - rate * dc[j] * inv_c;
    const double du = dg[j] * dt_over_c - u * dc[j] * inv_c;
    d_end[j] = dt0[j] + d_rate * ph.phi1 + rate * ph.dphi1 * du;
    d_mean[j] = dt0[j] + d_rate * ph.phi2 + rate * ph.dphi2 * du;
  }
}

// Tangent of T = S/G (one algebraic node).
inline void AlgebraicTangent(const RcNode& node, double t_c, const double* dg, const double* ds,
                             int n, double* d_t) {
  const double inv_g = 1.0 / node.conductance_w_k;
  for (int j = 0; j < n; ++j) d_t[j] = (ds[j] - t_c * dg[j]) * inv_g;
}

// Γ_ab of g(λ) = dt·φ(λ·dt) from its values and slopes at λa ≥ λb.
inline double DividedDifference(double ga, double gb, double slope_a, double slope_b,
                                double lambda_a, double lambda_b) {
  const double gap = lambda_a - lambda_b;
  if (gap > 1e-6 * (std::fabs(lambda_a) + std::fabs(lambda_b))) return (ga - gb) / gap;
  return 0.5 * (slope_a + slope_b);
}

// Tangent of AdvanceTwo (rc_network.h): both nodes capacitive.
inline void AdvanceTwoTangent(const RcNetwork& net, const double t0[2], double dt_s,
                              const RcNetworkTangent& d, RcStepTangent* out) {
  const double g = net.coupling_w_k;
  const double k00 = net.node[0].conductance_w_k + g;
  const double k11 = net.node[1].conductance_w_k + g;
  const double c0 = net.node[0].capacitance_j_k;
  const double c1 = net.node[1].capacitance_j_k;
  const double p0 = 1.0 / std::sqrt(c0);
  const double p1 = 1.0 / std::sqrt(c1);
  const double m00 = k00 * p0 * p0;
  const double m11 = k11 * p1 * p1;
  const double m01 = -g * p0 * p1;
  const rc_step::SymmetricModes modes = rc_step::DiagonaliseSymmetric(m00, m11, m01);
  const double c = modes.c;
  const double s = modes.s;
  const double lambda_a = modes.lambda_a;
  const double lambda_b = modes.lambda_b;
  const PhiSlopes pa = ExpPhisWithSlopes(lambda_a * dt_s);
  const PhiSlopes pb = ExpPhisWithSlopes(lambda_b * dt_s);
  const double dt2 = dt_s * dt_s;
  // g(λ) = dt·φ(λ·dt), g'(λ) = dt²·φ'(λ·dt); [0]: end (φ1), [1]: mean (φ2).
  const double ga[2] = {dt_s * pa.phi1, dt_s * pa.phi2};
  const double gb[2] = {dt_s * pb.phi1, dt_s * pb.phi2};
  const double sa[2] = {dt2 * pa.dphi1, dt2 * pa.dphi2};
  const double sb[2] = {dt2 * pb.dphi1, dt2 * pb.dphi2};
  double dd[2];
  for (int f = 0; f < 2; ++f) {
    dd[f] = DividedDifference(ga[f], gb[f], sa[f], sb[f], lambda_a, lambda_b);
  }
  const double r0 = net.node[0].source_w - k00 * t0[0] + g * t0[1];  // S − K·T0
  const double r1 = net.node[1].source_w - k11 * t0[1] + g * t0[0];
  const double fa = c * p0 * r0 + s * p1 * r1;  // Vᵀ·P·(S − K·T0)
  const double fb = -s * p0 * r0 + c * p1 * r1;
  double w0[2], w1[2];  // g(M)·P·(S − K·T0)
  for (int f = 0; f < 2; ++f) {
    w0[f] = c * ga[f] * fa - s * gb[f] * fb;
    w1[f] = s * ga[f] * fa + c * gb[f] * fb;
  }
  for (int j = 0; j < d.directions; ++j) {
    const double dg = d.coupling_w_k[j];
    const double dk00 = d.conductance_w_k[0][j] + dg;
    const double dk11 = d.conductance_w_k[1][j] + dg;
    const double dp0 = -0.5 * p0 * d.capacitance_j_k[0][j] / c0;
    const double dp1 = -0.5 * p1 * d.capacitance_j_k[1][j] / c1;
    const double dt00 = d.t_start_c[0][j];
    const double dt01 = d.t_start_c[1][j];
    const double dr0 = d.source_w[0][j] - dk00 * t0[0] - k00 * dt00 + dg * t0[1] + g * dt01;
    const double dr1 = d.source_w[1][j] - dk11 * t0[1] - k11 * dt01 + dg * t0[0] + g * dt00;
    const double dq0 = dp0 * r0 + p0 * dr0;
    const double dq1 = dp1 * r1 + p1 * dr1;
    const double dm00 = dk00 * p0 * p0 + 2.0 * k00 * p0 * dp0;
    const double dm11 = dk11 * p1 * p1 + 2.0 * k11 * p1 * dp1;
    const double dm01 = -dg * p0 * p1 - g * (dp0 * p1 + p0 * dp1);
    // Vᵀ·dM·V with V = [(c, s), (−s, c)].
    const double e_aa = c * c * dm00 + 2.0 * c * s * dm01 + s * s * dm11;
    const double e_bb = s * s * dm00 - 2.0 * c * s * dm01 + c * c * dm11;
    const double e_ab = c * s * (dm11 - dm00) + (c * c - s * s) * dm01;
    const double dfa = c * dq0 + s * dq1;
    const double dfb = -s * dq0 + c * dq1;
    double* d_end_mean[2][2] = {{&out->t_end_c[0][j], &out->t_end_c[1][j]},
                                {&out->t_mean_c[0][j], &out->t_mean_c[1][j]}};
    for (int f = 0; f < 2; ++f) {
      const double ua = sa[f] * e_aa * fa + dd[f] * e_ab * fb + ga[f] * dfa;
      const double ub = dd[f] * e_ab * fa + sb[f] * e_bb * fb + gb[f] * dfb;
      *d_end_mean[f][0] = dt00 + dp0 * w0[f] + p0 * (c * ua - s * ub);
      *d_end_mean[f][1] = dt01 + dp1 * w1[f] + p1 * (s * ua + c * ub);
    }
  }
}

}  // namespace rc_tangent

// Tangent of SteadyRc(net) whose value is `value`.
inline void SteadyRcTangent(const RcNetwork& net, const RcStepResult& value,
                            const RcNetworkTangent& d, RcStepTangent* out) {
  const int n = d.directions;
  if (net.nodes == 1) {
    rc_tangent::AlgebraicTangent(net.node[0], value.t_mean_c[0], d.conductance_w_k[0],
                                 d.source_w[0], n, out->t_mean_c[0]);
    for (int j = 0; j < n; ++j) out->t_end_c[0][j] = out->t_mean_c[0][j];
    return;
  }
  const double g = net.coupling_w_k;
  const double k00 = net.node[0].conductance_w_k + g;
  const double k11 = net.node[1].conductance_w_k + g;
  const double inv_det = 1.0 / (k00 * k11 - g * g);
  const double t0 = value.t_mean_c[0];
  const double t1 = value.t_mean_c[1];
  for (int j = 0; j < n; ++j) {
    const double rhs0 =
        d.source_w[0][j] - d.conductance_w_k[0][j] * t0 - d.coupling_w_k[j] * (t0 - t1);
    const double rhs1 =
        d.source_w[1][j] - d.conductance_w_k[1][j] * t1 - d.coupling_w_k[j] * (t1 - t0);
    out->t_end_c[0][j] = out->t_mean_c[0][j] = (k11 * rhs0 + g * rhs1) * inv_det;
    out->t_end_c[1][j] = out->t_mean_c[1][j] = (g * rhs0 + k00 * rhs1) * inv_det;
  }
}

// Tangent of AdvanceRcShaped<kShape>(net, t_start_c, dt_s) whose value is
// `value`. The start temperature of an algebraic node has no influence.
template <RcShape kShape>
inline void AdvanceRcTangent(const RcNetwork& net, const double t_start_c[2], double dt_s,
                             const RcStepResult& value, const RcNetworkTangent& d,
                             RcStepTangent* out) {
  const int n = d.directions;
  const RcNode& n0 = net.node[0];
  if constexpr (kShape == RcShape::kOneAlgebraic) {
    rc_tangent::AlgebraicTangent(n0, value.t_mean_c[0], d.conductance_w_k[0], d.source_w[0], n,
                                 out->t_mean_c[0]);
    for (int j = 0; j < n; ++j) out->t_end_c[0][j] = out->t_mean_c[0][j];
  } else if constexpr (kShape == RcShape::kOneCapacitive) {
    rc_tangent::AdvanceOneTangent(n0.capacitance_j_k, n0.conductance_w_k, n0.source_w, t_start_c[0],
                                  dt_s, d.capacitance_j_k[0], d.conductance_w_k[0], d.source_w[0],
                                  d.t_start_c[0], n, out->t_end_c[0], out->t_mean_c[0]);
  } else if constexpr (kShape == RcShape::kTwoAlgebraic) {
    SteadyRcTangent(net, value, d, out);
  } else if constexpr (kShape == RcShape::kTwoCapacitiveBoth) {
    rc_tangent::AdvanceTwoTangent(net, t_start_c, dt_s, d, out);
  } else {
    // a algebraic, b capacitive (see AdvanceRcShaped).
    constexpr int a = kShape == RcShape::kTwoCapacitive0 ? 1 : 0;
    constexpr int b = 1 - a;
    const double g = net.coupling_w_k;
    const double s_a = net.node[a].source_w;
    const double g_a = net.node[a].conductance_w_k;
    const double inv_denom_a = 1.0 / (g_a + g);
    const double s_red = net.node[b].source_w + g * s_a * inv_denom_a;
    const double g_red = net.node[b].conductance_w_k + g * g_a * inv_denom_a;
    double ds_red[kMaxRcTangents] = {}, dg_red[kMaxRcTangents] = {};
    for (int j = 0; j < n; ++j) {
      const double dg = d.coupling_w_k[j];
      const double d_inv = -inv_denom_a * inv_denom_a * (d.conductance_w_k[a][j] + dg);
      ds_red[j] = d.source_w[b][j] + dg * s_a * inv_denom_a + g * d.source_w[a][j] * inv_denom_a +
                  g * s_a * d_inv;
      dg_red[j] = d.conductance_w_k[b][j] + dg * g_a * inv_denom_a +
                  g * d.conductance_w_k[a][j] * inv_denom_a + g * g_a * d_inv;
    }
    rc_tangent::AdvanceOneTangent(net.node[b].capacitance_j_k, g_red, s_red, t_start_c[b], dt_s,
                                  d.capacitance_j_k[b], dg_red, ds_red, d.t_start_c[b], n,
                                  out->t_end_c[b], out->t_mean_c[b]);
    // T_a = (S_a + g·T_b)/(G_a + g): dT_a = (dS_a + dg·T_b + g·dT_b − T_a·(dG_a + dg))/(G_a + g).
    for (int j = 0; j < n; ++j) {
      const double dg = d.coupling_w_k[j];
      const double dga = d.conductance_w_k[a][j] + dg;
      out->t_end_c[a][j] = (d.source_w[a][j] + dg * value.t_end_c[b] + g * out->t_end_c[b][j] -
                            value.t_end_c[a] * dga) *
                           inv_denom_a;
      out->t_mean_c[a][j] = (d.source_w[a][j] + dg * value.t_mean_c[b] + g * out->t_mean_c[b][j] -
                             value.t_mean_c[a] * dga) *
                            inv_denom_a;
    }
  }
}

}  // namespace pvtwin
