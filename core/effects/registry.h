// The registry of the effect modules: one per entry of the list of effects
// (core/common/effect_list.h, doc/contracts.md's vocabulary), in the list's
// order (the order the diagnosis tries them and reports ties in).
#pragma once

#include <string_view>
#include <vector>

#include "core/effects/effect_module.h"

namespace pvtwin {

// Every module, in the vocabulary's order.
const std::vector<const EffectModule*>& EffectRegistry();

// The module named `name`, or null.
const EffectModule* FindEffect(std::string_view name);

}  // namespace pvtwin
