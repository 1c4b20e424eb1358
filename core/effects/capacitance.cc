#include "core/effects/capacitance.h"

namespace pvtwin {

namespace {

bool InSpec(const ModelSpec& spec) { return spec.c_pv || spec.c_coll; }

// The next missing capacitance: 1N → 1N1C, 2N → 2N1Ccol, 2N1Cpv/2N1Ccol → 2N2C.
void AddToSpec(ModelSpec* spec) {
  if (spec->nodes == 1) {
    spec->c_pv = true;
  } else if (!spec->c_coll) {
    spec->c_coll = true;
  } else {
    spec->c_pv = true;
  }
}

std::string CannotAdd(const ModelSpec& spec) {
  const bool full = spec.c_pv && (spec.nodes == 1 || spec.c_coll);
  return full ? "every node of " + spec.Name() + " already has a capacitance" : "";
}

std::vector<double> Signature(const Drivers& d, const SimOutputs&) {
  return RatePerMinute(d, d.g_abs_w_m2);
}

}  // namespace

const EffectModule& CapacitanceEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = EffectName(Effect::kCapacitance);
    m.physics =
        "Thermal mass of the PV laminate, absorber and fluid content: the collector "
        "temperature lags behind changes of irradiance, inlet temperature and flow, "
        "storing heat on rising irradiance and releasing it afterwards (paper 2.2, "
        "C·dT/dt in the node balance). Without it the model answers cloud edges and pump "
        "starts instantly.";
    m.source = "paper 2.2 (node balance C·dT/dt) and 2.10 (capacitance placement)";
    m.params = EffectParams(Effect::kCapacitance);
    m.typical_truth = {{Param::kCPvJM2K, 1.2e4}, {Param::kCCollJM2K, 3.5e4}};
    m.signature = "rate of change of the absorbed irradiance, W/m² per minute";
    m.advice =
        "Use a variant with the capacitance for this collector; its forecasts of cloud "
        "transients and pump starts then follow the measured lag.";
    m.in_spec = InSpec;
    m.add_to_spec = AddToSpec;
    m.cannot_add = CannotAdd;
    m.signature_values = Signature;
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
