// Effect "clock_offset": the weather logger's clock differs from the
// collector logger's. A ModelExtension that shifts the weather drivers in
// time before every other transform (driver_stage 0).
#pragma once

#include <cstdint>
#include <vector>

#include "core/effects/effect_module.h"

namespace pvtwin {

// v at time t + offset_s by linear interpolation between rows (held at the
// ends); out[i] for every row i of d.
void ShiftInTime(const Drivers& d, const double* v, double offset_s, std::vector<double>* out);

// --- Other-form truth: an offset of no whole number of steps, drifting ---

// v at time t_s by cubic Catmull–Rom interpolation between the row stamps
// (time_s increasing; held at the ends; linear where a neighbour is NaN):
// on [t_k, t_k+1] with u = (t − t_k)/(t_k+1 − t_k) the cubic Hermite with
// slopes m_k = (v_k+1 − v_k−1)/(t_k+1 − t_k−1) (Catmull & Rom 1974; exact
// for quadratics on a uniform grid).
double CubicAt(const std::vector<std::int64_t>& time_s, const std::vector<double>& v, double t_s);

// The weather logger's clock runs Δt(t) = Δt0 + r·(t − t_first) ahead (an
// offset of no whole number of rows plus a quartz drift, IEC 61724-1's
// time-stamp accuracy).
struct DriftingClock {
  double offset_s = 97.0;        // Δt0
  double drift_s_per_day = 2.0;  // r (23 ppm)
};

inline constexpr DriftingClock kOtherTruthClock{};

const EffectModule& ClockOffsetEffect();

}  // namespace pvtwin
