#include "core/effects/pv_clipping.h"

#include <limits>

namespace pvtwin {

namespace {

// P_el = min(P_dc, P_limit·A); the model keeps the clipped power as heat
// (RunInputs::electric_effects).
void InverterLimit(const Drivers&, const ParamVector& p, RunInputs* run) {
  run->p_limit_w = ParamOf(p, Param::kPLimitWM2) * ParamOf(p, Param::kAreaM2);
  run->electric_effects = true;
}

const ModelExtension& Extension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "pv_clipping";
    e.variant_order = 3;
    e.params = {Param::kPLimitWM2};
    e.transform_drivers = InverterLimit;
    return e;
  }();
  return kExtension;
}

// Base model P_el per m².
std::vector<double> Signature(const Drivers& d, const SimOutputs& base) {
  std::vector<double> out(d.size(), std::numeric_limits<double>::quiet_NaN());
  if (base.p_el_w.size() == d.size()) {
    for (std::size_t i = 0; i < d.size(); ++i) out[i] = base.p_el_w[i] / d.plant.area_m2;
  }
  return out;
}

}  // namespace

const EffectModule& PvClippingEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = "pv_clipping";
    m.physics =
        "The inverter or MPPT limits the AC power: P_el = min(P_dc, P_limit). A PVT "
        "module whose electricity is clipped moves its operating point away from the "
        "maximum power point, so the unconverted power stays in the laminate as heat: "
        "the node balance gets Q_abs = F_th·(A·I_at − P_el), which raises T_PV and Q_u "
        "while clipping.";
    m.source =
        "Dobos 2014, PVWatts Version 5 Manual (NREL/TP-6A20-62641): P_ac = min(P_dc·η, P_ac0)";
    m.params = {Param::kPLimitWM2};
    m.typical_truth = {{Param::kPLimitWM2, 120.0}};
    m.signature = "base model P_el per m² (evidence above the limit)";
    m.advice =
        "Check the inverter's AC limit against the array: clipped electricity stays in "
        "the collector as heat; model it with +pv_clipping.";
    m.extension = &Extension();
    m.signature_values = Signature;
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
