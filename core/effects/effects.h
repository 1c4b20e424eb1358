// The effect library's generic functions: what any effect module
// (effect_module.h) answers, asked the same way for every effect. Callers
// iterate EffectRegistry() (registry.h) or look a module up by name.
#pragma once

#include <string>
#include <vector>

#include "core/effects/effect_module.h"
#include "core/effects/registry.h"

namespace pvtwin {

// Whether spec contains the effect (capacitance: at least one node has a
// capacitance; second_node: two nodes; wind: 'w' or "+wind"; …).
bool HasEffect(const ModelSpec& spec, const EffectModule& effect);

// Whether adding the effect to spec makes sense: false when already present
// (for capacitance: when every node has one), with the reason in *why_not
// (may be null).
bool CanAddEffect(const ModelSpec& spec, const EffectModule& effect, std::string* why_not);
// The same, also checking that the data provide what the effect needs (e.g.
// irradiance_bias: "not identifiable without a second irradiance source
// (ghi_w_m2 + dhi_w_m2)").
bool CanAddEffect(const ModelSpec& spec, const EffectModule& effect, const Series& data,
                  std::string* why_not);

// spec with the effect added (EffectModule::add_to_spec, or its "+name"
// extension). Adding a present effect returns spec unchanged.
ModelSpec WithEffect(ModelSpec spec, const EffectModule& effect);

// One form of an effect added to a spec, with the form's name
// (EffectModule::form or a diagnosis_forms entry's).
struct NamedForm {
  std::string form;
  ModelSpec spec;
};

// Every form of the effect that the diagnosis fits, added to spec: WithEffect
// first (named EffectModule::form), then each of EffectModule::diagnosis_forms
// that differs from it.
std::vector<NamedForm> DiagnosisForms(const ModelSpec& spec, const EffectModule& effect);

// Per-row value of the effect's signature (EffectModule::signature), for
// residual evidence; NaN where undefined.
std::vector<double> EffectSignature(const EffectModule& effect, const Drivers& drivers,
                                    const SimOutputs& base_outputs);

// Every effect name, in the registry's order.
std::vector<std::string> EffectNames();

}  // namespace pvtwin
