// Exact integration of a linear RC network of one or two nodes over one time
// step with its inputs held constant.
//
// Node i obeys   C_i·dT_i/dt = S_i − G_i·T_i + g·(T_j − T_i)
// with C_i = capacitance_j_k (J/K; 0 makes the node algebraic: its equation is
// solved as a steady balance at every instant), G_i = conductance_w_k (W/K)
// to boundary temperatures plus any linearised source slope, S_i = source_w
// (W: Σ g_b·T_b over the boundaries plus a constant heat input), and
// g = coupling_w_k (W/K) between the two nodes.
//
// Algebraic nodes are eliminated (Schur complement); the remaining 0, 1 or 2
// states are advanced with the matrix exponential, which is exact for
// piecewise-constant inputs and stable for any step and any positive
// parameters (exponential integrator). The result gives the node temperatures
// at the end of the step and their means over the step (what an averaging
// logger records).
#pragma once

#include <cmath>

namespace pvtwin {

// The step's exponential factors for x = G·dt/C:
//   φ1(x) = (1 − e^(−x))/x,   φ2(x) = (x − 1 + e^(−x))/x² = (1 − φ1)/x,
// (T_end and T_mean of one node: T0 + (S − G·T0)·dt/C·φ1 resp. φ2).
// For |x| ≥ kPhiSeriesBelow from exp, which costs a fraction of expm1 (the
// row loop waits for this value), the cancellation costing at most ~3e-14
// of φ2; below, from their Taylor series to x⁹ (remainder < 3e-18).
inline constexpr double kPhiSeriesBelow = 0.1;
inline constexpr int kPhiSeriesDegree = 9;

struct ExpPhi {
  double phi1;
  double phi2;
};

// Coefficients (−1)^k/(k + m)!, k = 0..kPhiSeriesDegree, of φ1 (m = 1) and
// φ2 (m = 2).
struct PhiSeriesCoefficients {
  double c[kPhiSeriesDegree + 1];
};
constexpr PhiSeriesCoefficients MakePhiSeries(int m) {
  PhiSeriesCoefficients s{};
  double fact = 1.0;
  for (int j = 2; j <= m; ++j) fact *= j;
  for (int k = 0; k <= kPhiSeriesDegree; ++k) {
    s.c[k] = (k % 2 == 0 ? 1.0 : -1.0) / fact;
    fact *= k + m + 1;
  }
  return s;
}
inline constexpr PhiSeriesCoefficients kPhi1Series = MakePhiSeries(1);
inline constexpr PhiSeriesCoefficients kPhi2Series = MakePhiSeries(2);

// The series by Estrin's scheme: four levels of independent products
// instead of Horner's nine dependent ones (the row loop waits for this
// value).
[[gnu::always_inline]] inline double PhiSeries(const PhiSeriesCoefficients& s, double x) {
  static_assert(kPhiSeriesDegree == 9);
  const double* c = s.c;
  const double x2 = x * x;
  const double x4 = x2 * x2;
  const double p01 = c[0] + c[1] * x, p23 = c[2] + c[3] * x;
  const double p45 = c[4] + c[5] * x, p67 = c[6] + c[7] * x;
  const double p89 = c[8] + c[9] * x;
  return (p01 + x2 * p23) + x4 * ((p45 + x2 * p67) + x4 * p89);
}

[[gnu::always_inline]] inline ExpPhi ExpPhis(double x) {
  if (std::fabs(x) < kPhiSeriesBelow) return {PhiSeries(kPhi1Series, x), PhiSeries(kPhi2Series, x)};
  const double inv_x = 1.0 / x;
  const double phi1 = (1.0 - std::exp(-x)) * inv_x;
  return {phi1, (1.0 - phi1) * inv_x};
}

struct RcNode {
  double capacitance_j_k = 0.0;
  double conductance_w_k = 0.0;
  double source_w = 0.0;
};

struct RcNetwork {
  int nodes = 1;  // 1 or 2
  RcNode node[2];
  double coupling_w_k = 0.0;  // between node 0 and node 1
};

struct RcStepResult {
  double t_end_c[2] = {0.0, 0.0};
  double t_mean_c[2] = {0.0, 0.0};
};

// Advances the network over dt_s from t_start_c (only the capacitive nodes'
// start values matter). Requires G_i ≥ 0 with a positive total conductance per
// connected group.
RcStepResult AdvanceRc(const RcNetwork& net, const double t_start_c[2], double dt_s);

// Which nodes of a network hold a capacitance (C > 0): the case AdvanceRc
// solves. A caller that steps one network shape many times (the model's row
// loop) picks it once and calls AdvanceRcShaped, which does the same
// arithmetic as AdvanceRc without testing the shape at every step.
enum class RcShape {
  kOneAlgebraic,      // one node, C = 0
  kOneCapacitive,     // one node, C > 0
  kTwoAlgebraic,      // two nodes, no capacitance
  kTwoCapacitive0,    // two nodes, capacitance on node 0 only
  kTwoCapacitive1,    // two nodes, capacitance on node 1 only
  kTwoCapacitiveBoth  // two nodes, both capacitive
};
RcShape ShapeOf(const RcNetwork& net);

// Steady state of the network (all capacitances ignored): paper 2.2's
// initial node temperatures.
RcStepResult SteadyRc(const RcNetwork& net);

// The steps themselves, inline so that the row loop's compiler sees them.
namespace rc_step {

// One capacitive node: C·dT/dt = S − G·T. End value and mean over dt:
//   T(dt) = T0 + (S − G·T0)·dt/C·φ1(G·dt/C),   mean = T0 + (S − G·T0)·dt/C·φ2(·)
[[gnu::always_inline]] inline void AdvanceOne(double c, double g, double s, double t0, double dt_s,
                                              double* t_end, double* t_mean) {
  const double dt_over_c = dt_s / c;
  const double rate = (s - g * t0) * dt_over_c;
  const ExpPhi phi = ExpPhis(g * dt_over_c);
  *t_end = t0 + rate * phi.phi1;
  *t_mean = t0 + rate * phi.phi2;
}

// Eigen-decomposition of the symmetric M = [m00, m01; m01, m11]: the
// rotation (c, s) = (cos θ, sin θ) with θ = ½·atan2(2·m01, m00 − m11), whose
// first column (c, s) belongs to λa = mean + radius and second (−s, c) to
// λb = mean − radius. The rotation comes from the half-angle formulas with
// cos 2θ = (m00 − m11)/(2·radius) and sin 2θ = m01/radius instead of atan2,
// cos and sin, which were 13 % of the instructions of a 2N2Cwr calibrate
// (callgrind): the larger of |c|, |s| from
// √((1 ± cos 2θ)/2), which has no cancellation,
// the other from sin 2θ = 2·s·c. θ lies in (−π/2, π/2], so c ≥ 0 and s has
// the sign of m01 (as atan2 gives it, −0 included).
struct SymmetricModes {
  double c, s;
  double lambda_a, lambda_b;
};
[[gnu::always_inline]] inline SymmetricModes DiagonaliseSymmetric(double m00, double m11,
                                                                  double m01) {
  const double half_sum = 0.5 * (m00 + m11);
  const double half_diff = 0.5 * (m00 - m11);
  const double radius = std::sqrt(half_diff * half_diff + m01 * m01);
  SymmetricModes modes{1.0, 0.0, half_sum + radius, half_sum - radius};
  if (radius == 0.0) return modes;  // M = λ·I: any rotation, θ = 0 as atan2(0, 0)
  const double inv_2r = 0.5 / radius;
  if (half_diff >= 0.0) {
    modes.c = std::sqrt((radius + half_diff) * inv_2r);
    modes.s = m01 * inv_2r / modes.c;
  } else {
    modes.s = std::copysign(std::sqrt((radius - half_diff) * inv_2r), m01);
    modes.c = m01 * inv_2r / modes.s;
  }
  return modes;
}

// Two capacitive nodes. With y = C^(1/2)·T the system matrix becomes the
// symmetric M = C^(-1/2)·K·C^(-1/2), diagonalised by a rotation R(θ); each
// mode then evolves as in AdvanceOne.
inline void AdvanceTwo(const RcNetwork& net, const double t0[2], double dt_s, RcStepResult* r) {
  const double g = net.coupling_w_k;
  const double k00 = net.node[0].conductance_w_k + g;
  const double k11 = net.node[1].conductance_w_k + g;
  const double sc0 = 1.0 / std::sqrt(net.node[0].capacitance_j_k);
  const double sc1 = 1.0 / std::sqrt(net.node[1].capacitance_j_k);
  const SymmetricModes modes =
      DiagonaliseSymmetric(k00 * sc0 * sc0, k11 * sc1 * sc1, -g * sc0 * sc1);
  const double c = modes.c;
  const double s = modes.s;
  const double lambda_a = modes.lambda_a;  // along (c, s)
  const double lambda_b = modes.lambda_b;  // along (−s, c)
  // Initial rate dy/dt = C^(-1/2)·(S − K·T0), projected on the modes.
  const double f0 = (net.node[0].source_w - k00 * t0[0] + g * t0[1]) * sc0;
  const double f1 = (net.node[1].source_w - k11 * t0[1] + g * t0[0]) * sc1;
  const double fa = c * f0 + s * f1;
  const double fb = -s * f0 + c * f1;
  const ExpPhi phi_a = ExpPhis(lambda_a * dt_s);
  const ExpPhi phi_b = ExpPhis(lambda_b * dt_s);
  const double end_a = fa * dt_s * phi_a.phi1;
  const double end_b = fb * dt_s * phi_b.phi1;
  const double mean_a = fa * dt_s * phi_a.phi2;
  const double mean_b = fb * dt_s * phi_b.phi2;
  r->t_end_c[0] = t0[0] + (c * end_a - s * end_b) * sc0;
  r->t_end_c[1] = t0[1] + (s * end_a + c * end_b) * sc1;
  r->t_mean_c[0] = t0[0] + (c * mean_a - s * mean_b) * sc0;
  r->t_mean_c[1] = t0[1] + (s * mean_a + c * mean_b) * sc1;
}

}  // namespace rc_step

// AdvanceRc for a network of shape kShape (ShapeOf(net) == kShape).
template <RcShape kShape>
[[gnu::always_inline]] inline RcStepResult AdvanceRcShaped(const RcNetwork& net,
                                                           const double t_start_c[2], double dt_s) {
  RcStepResult r;
  const RcNode& n0 = net.node[0];
  if constexpr (kShape == RcShape::kOneAlgebraic) {
    r.t_end_c[0] = r.t_mean_c[0] = n0.source_w / n0.conductance_w_k;
  } else if constexpr (kShape == RcShape::kOneCapacitive) {
    rc_step::AdvanceOne(n0.capacitance_j_k, n0.conductance_w_k, n0.source_w, t_start_c[0], dt_s,
                        &r.t_end_c[0], &r.t_mean_c[0]);
  } else if constexpr (kShape == RcShape::kTwoAlgebraic) {
    r = SteadyRc(net);
  } else if constexpr (kShape == RcShape::kTwoCapacitiveBoth) {
    rc_step::AdvanceTwo(net, t_start_c, dt_s, &r);
  } else {
    // One algebraic node a, one capacitive node b. Eliminating a:
    //   T_a = (S_a + g·T_b)/(G_a + g)
    //   C_b·dT_b/dt = S_b + g·S_a/(G_a + g) − (G_b + g·G_a/(G_a + g))·T_b
    constexpr int a = kShape == RcShape::kTwoCapacitive0 ? 1 : 0;
    constexpr int b = 1 - a;
    const double g = net.coupling_w_k;
    const double inv_denom_a = 1.0 / (net.node[a].conductance_w_k + g);
    const double s_red = net.node[b].source_w + g * net.node[a].source_w * inv_denom_a;
    const double g_red =
        net.node[b].conductance_w_k + g * net.node[a].conductance_w_k * inv_denom_a;
    rc_step::AdvanceOne(net.node[b].capacitance_j_k, g_red, s_red, t_start_c[b], dt_s,
                        &r.t_end_c[b], &r.t_mean_c[b]);
    r.t_end_c[a] = (net.node[a].source_w + g * r.t_end_c[b]) * inv_denom_a;
    r.t_mean_c[a] = (net.node[a].source_w + g * r.t_mean_c[b]) * inv_denom_a;
  }
  return r;
}

}  // namespace pvtwin
