// Effect "capacitance": thermal mass of the collector (paper 2.2), expressed
// by the variant's capacitance placement (1C, 1Cpv, 1Ccol, 2C).
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

const EffectModule& CapacitanceEffect();

}  // namespace pvtwin
