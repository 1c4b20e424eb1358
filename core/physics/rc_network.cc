#include "core/physics/rc_network.h"

#include <cmath>

namespace pvtwin {

namespace {

struct Phi {
  double phi1;  // (1 − e^(−x))/x
  double phi2;  // (x − 1 + e^(−x))/x²
};

// Both φ functions from one expm1; Taylor series near 0 where the closed
// forms cancel.
[[gnu::always_inline]] inline Phi ExpPhis(double x) {
  if (std::fabs(x) < 1e-3) {
    return {1.0 - x / 2.0 + x * x / 6.0 - x * x * x / 24.0,
            0.5 - x / 6.0 + x * x / 24.0 - x * x * x / 120.0};
  }
  const double em1 = std::expm1(-x);
  const double inv_x = 1.0 / x;
  return {-em1 * inv_x, (x + em1) * inv_x * inv_x};
}

}  // namespace

namespace {

// One capacitive node: C·dT/dt = S − G·T. End value and mean over dt:
//   T(dt) = T0 + (S − G·T0)·dt/C·φ1(G·dt/C),   mean = T0 + (S − G·T0)·dt/C·φ2(·)
[[gnu::always_inline]] inline void AdvanceOne(double c, double g, double s, double t0, double dt_s,
                                              double* t_end, double* t_mean) {
  const double dt_over_c = dt_s / c;
  const double rate = (s - g * t0) * dt_over_c;
  const Phi phi = ExpPhis(g * dt_over_c);
  *t_end = t0 + rate * phi.phi1;
  *t_mean = t0 + rate * phi.phi2;
}

// Two capacitive nodes. With y = C^(1/2)·T the system matrix becomes the
// symmetric M = C^(-1/2)·K·C^(-1/2), diagonalised by a rotation R(θ); each
// mode then evolves as in AdvanceOne.
void AdvanceTwo(const RcNetwork& net, const double t0[2], double dt_s, RcStepResult* r) {
  const double g = net.coupling_w_k;
  const double k00 = net.node[0].conductance_w_k + g;
  const double k11 = net.node[1].conductance_w_k + g;
  const double sc0 = 1.0 / std::sqrt(net.node[0].capacitance_j_k);
  const double sc1 = 1.0 / std::sqrt(net.node[1].capacitance_j_k);
  const double m00 = k00 * sc0 * sc0;
  const double m11 = k11 * sc1 * sc1;
  const double m01 = -g * sc0 * sc1;
  const double half_sum = 0.5 * (m00 + m11);
  const double half_diff = 0.5 * (m00 - m11);
  const double radius = std::hypot(half_diff, m01);
  const double theta = 0.5 * std::atan2(2.0 * m01, m00 - m11);
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  const double lambda_a = half_sum + radius;  // along (c, s)
  const double lambda_b = half_sum - radius;  // along (−s, c)
  // Initial rate dy/dt = C^(-1/2)·(S − K·T0), projected on the modes.
  const double f0 = (net.node[0].source_w - k00 * t0[0] + g * t0[1]) * sc0;
  const double f1 = (net.node[1].source_w - k11 * t0[1] + g * t0[0]) * sc1;
  const double fa = c * f0 + s * f1;
  const double fb = -s * f0 + c * f1;
  const Phi phi_a = ExpPhis(lambda_a * dt_s);
  const Phi phi_b = ExpPhis(lambda_b * dt_s);
  const double end_a = fa * dt_s * phi_a.phi1;
  const double end_b = fb * dt_s * phi_b.phi1;
  const double mean_a = fa * dt_s * phi_a.phi2;
  const double mean_b = fb * dt_s * phi_b.phi2;
  r->t_end_c[0] = t0[0] + (c * end_a - s * end_b) * sc0;
  r->t_end_c[1] = t0[1] + (s * end_a + c * end_b) * sc1;
  r->t_mean_c[0] = t0[0] + (c * mean_a - s * mean_b) * sc0;
  r->t_mean_c[1] = t0[1] + (s * mean_a + c * mean_b) * sc1;
}

}  // namespace

RcShape ShapeOf(const RcNetwork& net) {
  const bool cap0 = net.node[0].capacitance_j_k > 0.0;
  if (net.nodes == 1) return cap0 ? RcShape::kOneCapacitive : RcShape::kOneAlgebraic;
  const bool cap1 = net.node[1].capacitance_j_k > 0.0;
  if (cap0 && cap1) return RcShape::kTwoCapacitiveBoth;
  if (cap0) return RcShape::kTwoCapacitive0;
  return cap1 ? RcShape::kTwoCapacitive1 : RcShape::kTwoAlgebraic;
}

template <RcShape kShape>
[[gnu::always_inline]] inline RcStepResult AdvanceRcShaped(const RcNetwork& net,
                                                           const double t_start_c[2], double dt_s) {
  RcStepResult r;
  const RcNode& n0 = net.node[0];
  if constexpr (kShape == RcShape::kOneAlgebraic) {
    r.t_end_c[0] = r.t_mean_c[0] = n0.source_w / n0.conductance_w_k;
  } else if constexpr (kShape == RcShape::kOneCapacitive) {
    AdvanceOne(n0.capacitance_j_k, n0.conductance_w_k, n0.source_w, t_start_c[0], dt_s,
               &r.t_end_c[0], &r.t_mean_c[0]);
  } else if constexpr (kShape == RcShape::kTwoAlgebraic) {
    r = SteadyRc(net);
  } else if constexpr (kShape == RcShape::kTwoCapacitiveBoth) {
    AdvanceTwo(net, t_start_c, dt_s, &r);
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
    AdvanceOne(net.node[b].capacitance_j_k, g_red, s_red, t_start_c[b], dt_s, &r.t_end_c[b],
               &r.t_mean_c[b]);
    r.t_end_c[a] = (net.node[a].source_w + g * r.t_end_c[b]) * inv_denom_a;
    r.t_mean_c[a] = (net.node[a].source_w + g * r.t_mean_c[b]) * inv_denom_a;
  }
  return r;
}

template RcStepResult AdvanceRcShaped<RcShape::kOneAlgebraic>(const RcNetwork&, const double[2],
                                                              double);
template RcStepResult AdvanceRcShaped<RcShape::kOneCapacitive>(const RcNetwork&, const double[2],
                                                               double);
template RcStepResult AdvanceRcShaped<RcShape::kTwoAlgebraic>(const RcNetwork&, const double[2],
                                                              double);
template RcStepResult AdvanceRcShaped<RcShape::kTwoCapacitive0>(const RcNetwork&, const double[2],
                                                                double);
template RcStepResult AdvanceRcShaped<RcShape::kTwoCapacitive1>(const RcNetwork&, const double[2],
                                                                double);
template RcStepResult AdvanceRcShaped<RcShape::kTwoCapacitiveBoth>(const RcNetwork&,
                                                                   const double[2], double);

RcStepResult AdvanceRc(const RcNetwork& net, const double t_start_c[2], double dt_s) {
  switch (ShapeOf(net)) {
    case RcShape::kOneAlgebraic:
      return AdvanceRcShaped<RcShape::kOneAlgebraic>(net, t_start_c, dt_s);
    case RcShape::kOneCapacitive:
      return AdvanceRcShaped<RcShape::kOneCapacitive>(net, t_start_c, dt_s);
    case RcShape::kTwoAlgebraic:
      return AdvanceRcShaped<RcShape::kTwoAlgebraic>(net, t_start_c, dt_s);
    case RcShape::kTwoCapacitive0:
      return AdvanceRcShaped<RcShape::kTwoCapacitive0>(net, t_start_c, dt_s);
    case RcShape::kTwoCapacitive1:
      return AdvanceRcShaped<RcShape::kTwoCapacitive1>(net, t_start_c, dt_s);
    case RcShape::kTwoCapacitiveBoth:
      break;
  }
  return AdvanceRcShaped<RcShape::kTwoCapacitiveBoth>(net, t_start_c, dt_s);
}

RcStepResult SteadyRc(const RcNetwork& net) {
  RcStepResult r;
  if (net.nodes == 1) {
    r.t_end_c[0] = r.t_mean_c[0] = net.node[0].source_w / net.node[0].conductance_w_k;
    return r;
  }
  // [G0+g  −g ] [T0]   [S0]
  // [ −g  G1+g] [T1] = [S1]
  const double g = net.coupling_w_k;
  const double k00 = net.node[0].conductance_w_k + g;
  const double k11 = net.node[1].conductance_w_k + g;
  const double det = k00 * k11 - g * g;
  r.t_end_c[0] = r.t_mean_c[0] = (k11 * net.node[0].source_w + g * net.node[1].source_w) / det;
  r.t_end_c[1] = r.t_mean_c[1] = (g * net.node[0].source_w + k00 * net.node[1].source_w) / det;
  return r;
}

}  // namespace pvtwin
