#include "core/data/qc.h"

#include <cassert>
#include <cmath>

namespace pvtwin {

QcCorrections ApplyPaperCorrections(Series* series) {
  assert(series != nullptr);
  QcCorrections counts;
  for (const Channel c : kShortWaveChannels) {
    for (double& g_w_m2 : (*series)[c]) {
      if (IsIrradianceGlitch(g_w_m2)) {
        g_w_m2 = 0.0;
        ++counts.irradiance_zeroed;
      }
    }
  }
  for (double& mdot_kg_s : (*series)[Channel::kMdotKgS]) {
    if (mdot_kg_s < -kNegativeFlowToleranceKgS) {
      mdot_kg_s = std::nan("");
      ++counts.flow_rejected;
    } else if (mdot_kg_s < 0.0) {
      mdot_kg_s = 0.0;
      ++counts.flow_zeroed;
    }
  }
  return counts;
}

}  // namespace pvtwin
