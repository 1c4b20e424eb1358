#include "core/effects/second_node.h"

namespace pvtwin {

namespace {

bool InSpec(const ModelSpec& spec) { return spec.nodes == 2; }

// 1N → 2N; a capacitance on the PV node stays there (1N1C → 2N1Cpv).
void AddToSpec(ModelSpec* spec) { spec->nodes = 2; }

// ΔT = T_in − T_amb, K.
std::vector<double> Signature(const Drivers& d, const SimOutputs&) {
  std::vector<double> out(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) out[i] = d.t_in_c[i] - d.t_amb_c[i];
  return out;
}

}  // namespace

const EffectModule& SecondNodeEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = EffectName(Effect::kSecondNode);
    m.physics =
        "A finite conductance U_coll between the PV laminate and the absorber/fluid "
        "channel: the cells run warmer than the fluid-side node by Q/U_coll, which lowers "
        "P_el at high heat flux (paper 2.10, two-node network).";
    m.source = "paper 2.10 (two-node network, U_coll)";
    m.params = EffectParams(Effect::kSecondNode);
    // A PVT module without lamination of the cells onto the absorber.
    m.typical_truth = {{Param::kUCollWM2K, 12.0}};
    m.signature = "inlet minus ambient temperature, K";
    m.advice =
        "Model the cells and the absorber as two nodes (a 2N variant); check the bond "
        "between laminate and absorber if U_coll is low.";
    m.in_spec = InSpec;
    m.add_to_spec = AddToSpec;
    m.signature_values = Signature;
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
