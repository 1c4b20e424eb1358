// Effect "iam": the incidence-angle modifier of the beam and diffuse parts
// (paper 2.5, core/physics/iam.h), expressed by the letter 'I'.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

const EffectModule& IamEffect();

}  // namespace pvtwin
