// Effect "flow_dependent_u": the absorber-to-fluid resistance follows the
// flow regime. A ModelExtension that sets the fluid coupling per row.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

// The specific capacity flow at which the fluid-side resistance equals
// r0_fluid, w_ref = 0.02 kg/(s·m²) · c_p (the nominal specific flow of the
// paper's plant and of the weather generator).
inline constexpr double kFlowReferenceKgSM2 = 0.02;

// Fluid coupling conductance, W/K, with a flow-dependent convective part:
//   1/U_fluid = r1/(2w) + r0·(w_ref/w)^n_flow   (per m²; paper eq. 2.7 for
// n_flow = 0), w = ṁ·c_p/A. r0_fluid_per_area = r0/A (K/W),
// capacity_flow_w_k = ṁ·c_p, mdot_ref_kg_s = kFlowReferenceKgSM2·A. 0 without
// flow.
double FluidConductanceFlowDependentWK(double capacity_flow_w_k, double mdot_kg_s,
                                       double r0_fluid_per_area, double r1_fluid,
                                       double mdot_ref_kg_s, double n_flow);

const EffectModule& FlowDependentUEffect();

}  // namespace pvtwin
