#include "core/effects/effects.h"

#include <algorithm>
#include <cmath>

namespace pvtwin {

bool HasEffect(const ModelSpec& spec, const EffectModule& e) {
  if (e.in_spec != nullptr) return e.in_spec(spec);
  return e.extension != nullptr && spec.Has(*e.extension);
}

bool CanAddEffect(const ModelSpec& spec, const EffectModule& e, std::string* why_not) {
  std::string reason;
  if (e.cannot_add != nullptr) {
    reason = e.cannot_add(spec);
  } else if (HasEffect(spec, e)) {
    reason = spec.Name() + " already has " + std::string(e.name);
  }
  if (reason.empty()) return true;
  if (why_not != nullptr) *why_not = reason;
  return false;
}

bool CanAddEffect(const ModelSpec& spec, const EffectModule& e, const Series& data,
                  std::string* why_not) {
  if (!CanAddEffect(spec, e, why_not)) return false;
  const std::string reason = e.data_lacks != nullptr ? e.data_lacks(data) : "";
  if (reason.empty()) return true;
  if (why_not != nullptr) *why_not = reason;
  return false;
}

ModelSpec WithEffect(ModelSpec spec, const EffectModule& e) {
  if (e.add_to_spec != nullptr) {
    e.add_to_spec(&spec);
  } else if (e.extension != nullptr) {
    spec.Add(*e.extension);
  }
  return spec;
}

std::vector<NamedForm> DiagnosisForms(const ModelSpec& spec, const EffectModule& e) {
  std::vector<NamedForm> forms = {{std::string(e.form), WithEffect(spec, e)}};
  for (const EffectForm& f : e.diagnosis_forms) {
    ModelSpec form = spec;
    f.add(&form);
    const std::string name = form.Name();
    if (std::none_of(forms.begin(), forms.end(),
                     [&name](const NamedForm& g) { return g.spec.Name() == name; })) {
      forms.push_back({std::string(f.name), form});
    }
  }
  return forms;
}

std::vector<double> EffectSignature(const EffectModule& e, const Drivers& drivers,
                                    const SimOutputs& base_outputs) {
  if (e.signature_values == nullptr) return std::vector<double>(drivers.size(), std::nan(""));
  return e.signature_values(drivers, base_outputs);
}

std::vector<std::string> EffectNames() {
  std::vector<std::string> names;
  for (const EffectModule* m : EffectRegistry()) names.emplace_back(m->name);
  return names;
}

}  // namespace pvtwin
