// Effect "sky_radiation": long-wave exchange of the front with the sky
// (paper 2.9, core/physics/sky_radiation.h), expressed by the letter 'r'.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

const EffectModule& SkyRadiationEffect();

}  // namespace pvtwin
