// Data corrections of the paper applied to measured series before anything
// else uses them (paper Tables 1 and 2). Shared by the CSV import, the
// resampling of polled 5 s samples and the Modbus path, so every source of
// data is corrected the same way.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

#include "core/common/series.h"

namespace pvtwin {

// Paper Table 2: "An occasional error occurs at night, with values above
// 5000 W/m²; these are corrected to 0 W/m²." Applied to every short-wave
// irradiance channel (g_poa, ghi, dhi, g_poa_diffuse). Long-wave irradiance
// (lw_down) is not touched: 0 W/m² is never a plausible long-wave value.
// The glitch is a value of some thousand W/m²; a reading of
// kIrradianceGlitchMaxWM2 or more (up to 1e308 from a broken register) is no
// such glitch and is left to the physical limits (core/data/physical_limits.h),
// which make it missing instead of a plausible 0.
inline constexpr double kIrradianceGlitchWM2 = 5000.0;
inline constexpr double kIrradianceGlitchMaxWM2 = 1e5;

// Paper Table 1: "The very small negative values (no flow) are corrected to
// zero." A magnetic-inductive flow meter reads a little below zero when the
// pump stands still. Readings in [-kNegativeFlowToleranceKgS, 0) are that
// noise and become 0. 1e-3 kg/s is 3.6 L/h of water, about 3 % of the flow of
// a 1.7 m² collector at 0.02 kg/(s·m²); a flow more negative than that is a
// reversed or broken meter, not noise.
inline constexpr double kNegativeFlowToleranceKgS = 1e-3;

// Whether a short-wave irradiance reading is the paper's night glitch.
inline bool IsIrradianceGlitch(double g_w_m2) {
  return g_w_m2 > kIrradianceGlitchWM2 && g_w_m2 < kIrradianceGlitchMaxWM2;
}

// The short-wave irradiance channels the glitch correction applies to.
inline constexpr std::array<Channel, 4> kShortWaveChannels = {
    Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaDiffuseWM2};
inline bool IsShortWave(Channel c) {
  return std::find(kShortWaveChannels.begin(), kShortWaveChannels.end(), c) !=
         kShortWaveChannels.end();
}

// How many cells ApplyPaperCorrections changed.
struct QcCorrections {
  std::size_t irradiance_zeroed = 0;  // short-wave irradiance in (5000, 1e5) W/m² set to 0
  std::size_t flow_zeroed = 0;        // small negative mass flow set to 0
  std::size_t flow_rejected = 0;      // mass flow < -tolerance set to NaN (missing)

  std::size_t Total() const { return irradiance_zeroed + flow_zeroed + flow_rejected; }
};

// Applies the corrections above in place. NaN cells and absent channels are
// left as they are. Readers that can point at the offending line (the CSV
// reader) report large negative flows as errors before calling this; here
// they become missing so that a live source keeps running.
QcCorrections ApplyPaperCorrections(Series* series);

}  // namespace pvtwin
