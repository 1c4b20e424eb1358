// The one list that names the effect modules. Adding an effect: write its
// module (core/effects/<name>.{h,cc}) and add one line here.
#include "core/effects/registry.h"

#include "core/effects/capacitance.h"
#include "core/effects/clock_offset.h"
#include "core/effects/flow_dependent_u.h"
#include "core/effects/iam.h"
#include "core/effects/irradiance_bias.h"
#include "core/effects/pv_clipping.h"
#include "core/effects/second_node.h"
#include "core/effects/shading.h"
#include "core/effects/sky_radiation.h"
#include "core/effects/soiling.h"
#include "core/effects/transport_delay.h"
#include "core/effects/wind.h"

namespace pvtwin {

const std::vector<const EffectModule*>& EffectRegistry() {
  static const std::vector<const EffectModule*> kModules = {
      &CapacitanceEffect(),    &SecondNodeEffect(),  &WindEffect(),
      &SkyRadiationEffect(),   &IamEffect(),         &FlowDependentUEffect(),
      &TransportDelayEffect(), &PvClippingEffect(),  &ShadingEffect(),
      &SoilingEffect(),        &ClockOffsetEffect(), &IrradianceBiasEffect(),
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
