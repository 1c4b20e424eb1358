// Effect "soiling": dust and pollen on the front cover. A ModelExtension
// that scales the absorbed irradiance with the days since the last cleaning
// (Drivers::days_since_clean, SetCleaningTimes in core/model/thermal_model.h).
#pragma once

#include <algorithm>

#include "core/effects/effect_module.h"

namespace pvtwin {

// Transmittance of the soiled cover, τ_soil = max(0, 1 − r_soil·d): r_soil
// per day, d days since the last cleaning (Kimber et al. 2006, linear
// soiling rate).
inline double SoilingTransmittance(double rate_per_day, double days_since_clean) {
  return std::max(0.0, 1.0 - rate_per_day * days_since_clean);
}

const EffectModule& SoilingEffect();

}  // namespace pvtwin
