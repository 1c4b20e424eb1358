// The one list of the effects of doc/contracts.md's vocabulary, in the
// vocabulary's order (the order the diagnosis tries them and reports ties
// in). Everything else that knows the set of effects derives from it:
//  * Effect and EffectName() below;
//  * the registry (core/effects/registry.cc), which expands the list into
//    the modules' accessors <Name>Effect();
//  * the parameter slots each effect adds (params.h's PVTWIN_PARAMS names
//    its owner by the second column here);
//  * the structure check (tests/structure/check_structure.cmake), which
//    reads the names from the X(...) lines of this file;
//  * the tests of the registry, the golden model outputs and
//    doc/contracts.md's vocabulary paragraph (tests/unit/test_effect_registry.cc).
// Adding an effect: one X(...) line here, its parameters' rows in params.h,
// and its module core/effects/<name>.{h,cc}.
//
// Columns: the effect's name (doc/contracts.md, params.json's variant
// names), its CamelCase name (Effect::k<Name>, <Name>Effect()).
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

// clang-format off
#define PVTWIN_EFFECTS(X)                   \
  X(capacitance, Capacitance)               \
  X(second_node, SecondNode)                \
  X(wind, Wind)                             \
  X(sky_radiation, SkyRadiation)            \
  X(iam, Iam)                               \
  X(flow_dependent_u, FlowDependentU)       \
  X(transport_delay, TransportDelay)        \
  X(pv_clipping, PvClipping)                \
  X(shading, Shading)                       \
  X(soiling, Soiling)                       \
  X(clock_offset, ClockOffset)              \
  X(irradiance_bias, IrradianceBias)
// clang-format on

namespace pvtwin {

enum class Effect : std::size_t {
#define PVTWIN_EFFECT_ENUM(name, Name) k##Name,
  PVTWIN_EFFECTS(PVTWIN_EFFECT_ENUM)
#undef PVTWIN_EFFECT_ENUM
      kCount
};

inline constexpr std::size_t kNumEffects = static_cast<std::size_t>(Effect::kCount);

// The effects' names, in the list's order.
inline constexpr std::array<std::string_view, kNumEffects> kEffectNames = {
#define PVTWIN_EFFECT_NAME(name, Name) #name,
    PVTWIN_EFFECTS(PVTWIN_EFFECT_NAME)
#undef PVTWIN_EFFECT_NAME
};

constexpr std::string_view EffectName(Effect e) {
  return kEffectNames[static_cast<std::size_t>(e)];
}

}  // namespace pvtwin
