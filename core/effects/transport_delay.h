// Effect "transport_delay": the outlet sensor sits behind a pipe. A
// ModelExtension that transforms the outputs: the delayed, cooled outlet
// temperature and the heat measured with it.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

const EffectModule& TransportDelayEffect();

}  // namespace pvtwin
