// Effect "second_node": a finite conductance between the PV laminate and the
// absorber/fluid node (paper 2.10), expressed by the variant's "2N".
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

const EffectModule& SecondNodeEffect();

}  // namespace pvtwin
