// Effect "soiling": dust and pollen on the front cover. A ModelExtension
// that scales the absorbed irradiance with the days since the last cleaning
// (Drivers::days_since_clean, SetCleaningTimes in core/model/thermal_model.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/effects/effect_module.h"

namespace pvtwin {

// Transmittance of the soiled cover, τ_soil = max(0, 1 − r_soil·d): r_soil
// per day, d days since the last cleaning (Kimber et al. 2006, linear
// soiling rate).
// With recovered = the recoveries measured at the cleanings the data show
// (Drivers::soiling_recovered): the loss r·d drops by them,
// τ = 1 − max(0, r·d − recovered).
inline double SoilingTransmittance(double rate_per_day, double days_since_clean,
                                   double recovered = 0.0) {
  return std::max(0.0, 1.0 - std::max(0.0, rate_per_day * days_since_clean - recovered));
}

// --- Other-form truth: saturating soiling, partly washed off by rain ---

// Soiling loss L (fraction of the irradiance, τ_soil = 1 − L) after
// `days` days from L0 without rain: the deposit saturates as wind removes
// what settles (exponential approach to L_max with time constant τ_s,
// Hegazy 2001, Renewable Energy 22, transmittance of dusty glass vs exposure
// days):
//   L(d) = L_max − (L_max − L0)·exp(−d/τ_s).
inline double SaturatingSoilingLoss(double loss0, double days, double max_loss,
                                    double time_constant_days) {
  return max_loss - (max_loss - loss0) * std::exp(-days / time_constant_days);
}

// A rain event washes off the share c of the deposit: L ← (1 − c)·L
// (partial natural cleaning, Kimber et al. 2006).
inline double SoilingLossAfterRain(double loss, double cleaned_share) {
  return (1.0 - cleaned_share) * loss;
}

struct SoilingWithRain {
  double max_loss = 0.10;                 // L_max
  double time_constant_days = 8.0;        // τ_s
  double rain_probability_per_day = 0.1;  // a rain event at 00:00 UTC of a drawn day
  double cleaned_share = 0.6;             // c
};

// The other-form truth's soiling, clean at the first row.
inline constexpr SoilingWithRain kOtherTruthSoiling{};

// Whether it rains at the start of UTC day `day` for seed (never on the
// first day of the data: the caller skips it).
bool RainOnDay(std::uint64_t seed, std::int64_t day, const SoilingWithRain& soiling);

// τ_soil = 1 − L per row (time_s in unix s, increasing): L from 0 at the
// first row, saturating between rains, reduced by each rain at the start of
// a drawn UTC day.
std::vector<double> SoilingTransmittanceWithRain(const std::vector<std::int64_t>& time_s,
                                                 const SoilingWithRain& soiling,
                                                 std::uint64_t seed);

const EffectModule& SoilingEffect();

}  // namespace pvtwin
