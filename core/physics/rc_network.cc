#include "core/physics/rc_network.h"

#include <cmath>

namespace pvtwin {

RcShape ShapeOf(const RcNetwork& net) {
  const bool cap0 = net.node[0].capacitance_j_k > 0.0;
  if (net.nodes == 1) return cap0 ? RcShape::kOneCapacitive : RcShape::kOneAlgebraic;
  const bool cap1 = net.node[1].capacitance_j_k > 0.0;
  if (cap0 && cap1) return RcShape::kTwoCapacitiveBoth;
  if (cap0) return RcShape::kTwoCapacitive0;
  return cap1 ? RcShape::kTwoCapacitive1 : RcShape::kTwoAlgebraic;
}

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
