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

namespace pvtwin {

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

// AdvanceRc for a network of shape kShape (ShapeOf(net) == kShape).
template <RcShape kShape>
RcStepResult AdvanceRcShaped(const RcNetwork& net, const double t_start_c[2], double dt_s);

// Steady state of the network (all capacitances ignored): paper 2.2's
// initial node temperatures.
RcStepResult SteadyRc(const RcNetwork& net);

}  // namespace pvtwin
