// Effect "clock_offset": the weather logger's clock differs from the
// collector logger's. A ModelExtension that shifts the weather drivers in
// time before every other transform (driver_stage 0).
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

// v at time t + offset_s by linear interpolation between rows (held at the
// ends); out[i] for every row i of d.
void ShiftInTime(const Drivers& d, const double* v, double offset_s, std::vector<double>* out);

const EffectModule& ClockOffsetEffect();

}  // namespace pvtwin
