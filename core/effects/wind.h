// Effect "wind": forced convection on the uncovered front. Two forms: the
// paper's printed form, the letter 'w' (paper 2.8, core/physics/wind.h),
// and the physical form "+wind", U_front + c_wind·v^n_wind (ISO 9806 style),
// a ModelExtension that sets the front conductance per row.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

const EffectModule& WindEffect();

}  // namespace pvtwin
