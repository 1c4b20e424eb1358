// Effect "pv_clipping": the inverter limits the AC power. A ModelExtension
// that sets the model's electrical limit.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

const EffectModule& PvClippingEffect();

}  // namespace pvtwin
