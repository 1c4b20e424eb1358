// The registry of the effect modules, expanded from the one list of effects
// (core/common/effect_list.h): module <Name> is <Name>Effect(), defined in
// core/effects/<name>.cc. Adding an effect: write its module and add its
// line to the list.
#include "core/effects/registry.h"

namespace pvtwin {

// Every module's accessor, declared from the list (each module's header
// declares its own as well).
#define PVTWIN_EFFECT_ACCESSOR(name, Name) const EffectModule& Name##Effect();
PVTWIN_EFFECTS(PVTWIN_EFFECT_ACCESSOR)
#undef PVTWIN_EFFECT_ACCESSOR

const std::vector<const EffectModule*>& EffectRegistry() {
  static const std::vector<const EffectModule*> kModules = {
#define PVTWIN_EFFECT_MODULE(name, Name) &Name##Effect(),
      PVTWIN_EFFECTS(PVTWIN_EFFECT_MODULE)
#undef PVTWIN_EFFECT_MODULE
  };
  return kModules;
}

const EffectModule* FindEffect(std::string_view name) {
  for (const EffectModule* m : EffectRegistry()) {
    if (m->name == name) return m;
  }
  return nullptr;
}

}  // namespace pvtwin
