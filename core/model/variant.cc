#include "core/model/variant.h"

#include <algorithm>
#include <utility>

#include "core/effects/effects.h"

namespace pvtwin {

namespace {

// The modules with a "+name" extension, in variant order.
std::vector<const EffectModule*> ExtensionsInVariantOrder() {
  std::vector<const EffectModule*> out;
  for (const EffectModule* m : EffectRegistry()) {
    if (m->extension != nullptr) out.push_back(m);
  }
  std::stable_sort(out.begin(), out.end(), [](const EffectModule* a, const EffectModule* b) {
    return a->extension->variant_order < b->extension->variant_order;
  });
  return out;
}

bool ConsumePrefix(std::string_view* s, std::string_view prefix) {
  if (s->substr(0, prefix.size()) != prefix) return false;
  s->remove_prefix(prefix.size());
  return true;
}

bool ParseBase(std::string_view base, ModelSpec* spec, std::string* error) {
  std::string_view s = base;
  if (ConsumePrefix(&s, "1N")) {
    spec->nodes = 1;
    if (ConsumePrefix(&s, "1Cpv") || ConsumePrefix(&s, "1C")) spec->c_pv = true;
  } else if (ConsumePrefix(&s, "2N")) {
    spec->nodes = 2;
    if (ConsumePrefix(&s, "1Cpv")) {
      spec->c_pv = true;
    } else if (ConsumePrefix(&s, "1Ccol")) {
      spec->c_coll = true;
    } else if (ConsumePrefix(&s, "2C")) {
      spec->c_pv = spec->c_coll = true;
    } else if (s.substr(0, 2) == "1C") {
      *error = "'" + std::string(base) +
               "': a two-node model needs the capacitance's node: 1Cpv or 1Ccol";
      return false;
    }
  } else {
    *error = "'" + std::string(base) + "': a variant starts with 1N or 2N";
    return false;
  }
  if (ConsumePrefix(&s, "w")) spec->wind_paper = true;
  if (ConsumePrefix(&s, "r")) spec->sky = true;
  if (ConsumePrefix(&s, "I")) spec->iam = true;
  if (!s.empty()) {
    *error = "'" + std::string(base) + "': unexpected '" + std::string(s) +
             "' (grammar: {1,2}N[1C|1Cpv|1Ccol|2C][w][r][I], e.g. 2N1Ccolwr)";
    return false;
  }
  return true;
}

// "+effect": an effect with a model extension adds it; an effect that the
// paper's letters express sets its letters (sky_radiation = r, iam = I,
// capacitance = the next missing capacitance, second_node = 2N).
bool ParseEffect(std::string_view effect, ModelSpec* spec, std::string* error) {
  const EffectModule* m = FindEffect(effect);
  if (m == nullptr) {
    for (const EffectModule* e : EffectRegistry()) {
      for (const ModelExtension* form : e->form_extensions) {
        if (form->name != effect) continue;
        spec->Add(*form);
        return true;
      }
    }
    std::string known;
    for (const EffectModule* e : ExtensionsInVariantOrder()) {
      known += std::string(e->name) + ", ";
      for (const ModelExtension* form : e->form_extensions) known += std::string(form->name) + ", ";
    }
    std::string letters;
    for (const EffectModule* e : EffectRegistry()) {
      if (e->extension == nullptr) letters += (letters.empty() ? "" : ", ") + std::string(e->name);
    }
    *error = "unknown effect '" + std::string(effect) + "' (known: " + known + letters + ")";
    return false;
  }
  if (m->extension != nullptr) {
    spec->Add(*m->extension);
  } else {
    *spec = WithEffect(*spec, *m);
  }
  return true;
}

}  // namespace

bool ParseVariant(std::string_view name, ModelSpec* spec, std::string* error) {
  ModelSpec out;
  const std::size_t plus = name.find('+');
  if (!ParseBase(name.substr(0, plus), &out, error)) return false;
  std::string_view rest = plus == std::string_view::npos ? "" : name.substr(plus + 1);
  while (plus != std::string_view::npos) {
    const std::size_t next = rest.find('+');
    const std::string_view effect = rest.substr(0, next);
    if (effect.empty()) {
      *error = "'" + std::string(name) + "': empty effect name after '+'";
      return false;
    }
    if (!ParseEffect(effect, &out, error)) return false;
    if (next == std::string_view::npos) break;
    rest.remove_prefix(next + 1);
  }
  if (out.wind_paper && std::any_of(out.extensions.begin(), out.extensions.end(),
                                    [](const ModelExtension* e) { return e->reads_wind; })) {
    *error = "'" + std::string(name) +
             "': 'w' (paper's wind form) and '+wind' (physical form) exclude each other";
    return false;
  }
  *spec = out;
  return true;
}

const std::vector<std::string>& PaperVariants() {
  static const std::vector<std::string> kVariants = {
      "1N", "1Nwr", "1N1C", "1N1Cwr", "2Nwr", "2N1Cpvwr", "2N1Ccolwr", "2N1CcolwrI", "2N2Cwr"};
  return kVariants;
}

std::bitset<kNumParams> UsedParams(const ModelSpec& spec) {
  std::bitset<kNumParams> used;
  auto use = [&used](Param p) { used.set(static_cast<std::size_t>(p)); };
  for (Param p :
       {Param::kAreaM2, Param::kEtaPvRef, Param::kFTh, Param::kUFrontWM2K, Param::kUBackWM2K,
        Param::kR0FluidM2KW, Param::kR1Fluid, Param::kPvTempCoeffPerK, Param::kPvIrrCoeffM2W}) {
    use(p);
  }
  if (spec.nodes == 2) use(Param::kUCollWM2K);
  if (spec.c_pv) use(Param::kCPvJM2K);
  if (spec.c_coll) use(Param::kCCollJM2K);
  if (spec.sky) use(Param::kEpsPvt);
  if (spec.wind_paper) {
    use(Param::kRRefWind);
    use(Param::kNWind);
  }
  for (const ModelExtension* e : spec.extensions) {
    for (Param p : e->params) use(p);
  }
  return used;
}

std::bitset<kNumParams> DefaultFreeParams(const ModelSpec& spec) {
  std::bitset<kNumParams> free = UsedParams(spec);
  free.reset(static_cast<std::size_t>(Param::kAreaM2));
  free.reset(static_cast<std::size_t>(Param::kPvTempCoeffPerK));
  free.reset(static_cast<std::size_t>(Param::kPvIrrCoeffM2W));
  return free;
}

std::vector<InputRequirement> RequiredInputs(const ModelSpec& spec) {
  using C = Channel;
  std::vector<InputRequirement> req = {
      {"fluid inlet temperature", {{C::kTInC}}},
      {"fluid mass flow", {{C::kMdotKgS}}},
      {"ambient temperature", {{C::kTAmbC}}},
  };
  if (spec.iam) {
    req.push_back({"beam/diffuse irradiance (I)",
                   {{C::kGPoaWM2, C::kGPoaDiffuseWM2}, {C::kGhiWM2, C::kDhiWM2}}});
  } else {
    req.push_back({"irradiance in the collector plane", {{C::kGPoaWM2}, {C::kGhiWM2, C::kDhiWM2}}});
  }
  if (spec.ReadsWind()) req.push_back({"wind speed (w)", {{C::kWindMS}}});
  if (spec.sky) req.push_back({"sky temperature (r)", {{C::kTSkyC}, {C::kLwDownWM2}}});
  for (const ModelExtension* e : spec.extensions) {
    req.insert(req.end(), e->inputs.begin(), e->inputs.end());
  }
  return req;
}

}  // namespace pvtwin
