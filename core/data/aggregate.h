// Aggregation of 5 s samples (core/common/sample.h, table sample_5s) into 1-min
// measurement rows (table measurement_1min), as the daemon stores them.
//
// Per minute [m, m + 60 s) of unix time (the row's time is the minute's start,
// the canonical time convention), in this order:
//   1. The paper's corrections (core/data/qc.h ApplyPaperCorrections) on the
//      samples: short-wave irradiance > 5000 W/m² → 0, small negative flows
//      → 0, large negative flows → missing.
//   2. If no sample of the minute carries a measured q_th_w, the useful
//      thermal power is computed per sample as
//          Q_u = ṁ · c_p · (T_out − T_in)          (paper eq. of Q_u)
//      q_th_w [W] = flow_kg_s [kg/s] · fluid_cp_j_kgk [J/(kg·K)] · (t_out_c −
//      t_in_c) [K], for the samples that have all three values.
//   3. Each channel's value is the mean of the minute's non-NaN values (NaN if
//      there is none); `valid` is 1 only if every sample is valid (a sample
//      without a `valid` value counts as valid) and the minute holds at least
//      half of the 60 s / sample_period_s samples it should (core/data/resample.h
//      Resample, whose rules these are).
// Units are those of core/common/channels.h (aoi in radians, as in Sample).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/common/channels.h"
#include "core/common/sample.h"
#include "core/common/series.h"

namespace pvtwin {

inline constexpr std::int64_t kMinuteS = 60;

// qc_flags of a measurement_1min row. Bits 0..7 describe the minute; bit
// kQcChannelMissingShift + c is set when channel c (core/common/channels.h order)
// has no valid value in the minute (never read, or every reading rejected).
enum QcFlag : std::uint32_t {
  kQcFewSamples = 1u << 0,            // fewer than half the expected samples (row valid = 0)
  kQcRequiredMissing = 1u << 1,       // a channel the model needs is missing (see below)
  kQcRejectedValues = 1u << 2,        // the poller rejected a reading (Sample::rejected_mask)
  kQcIrradianceCorrected = 1u << 3,   // paper Table 2: irradiance > 5000 W/m² set to 0
  kQcFlowCorrected = 1u << 4,         // paper Table 1: small negative flow set to 0,
                                      // or a large negative flow dropped
  kQcThermalPowerComputed = 1u << 5,  // q_th_w = flow · c_p · (t_out − t_in), not measured
  kQcInvalidSamples = 1u << 6,        // a sample had valid = 0 (row valid = 0)
  kQcImported = 1u << 7,              // row imported from a 1-min CSV, not aggregated here
};
inline constexpr unsigned kQcChannelMissingShift = 8;
static_assert(kQcChannelMissingShift + kNumChannels <= 32, "qc_flags holds one bit per channel");

constexpr std::uint32_t QcChannelMissingBit(Channel c) {
  return 1u << (kQcChannelMissingShift + static_cast<unsigned>(c));
}

// "Required" (kQcRequiredMissing) follows doc/contracts.md's canonical CSV: t_in_c,
// flow_kg_s, t_amb_c, p_el_w, t_out_c or q_th_w, g_poa_w_m2 or ghi_w_m2 +
// dhi_w_m2.
bool RequiredChannelsPresent(std::uint32_t qc_flags);

struct AggregateOptions {
  double sample_period_s = 5.0;    // poll period: whole seconds dividing 60
  double fluid_cp_j_kgk = 3650.0;  // fluid heat capacity (plant config)
  // Collector area for the area-scaled physical limits (core/data/physical_limits.h);
  // 0: unknown, the widest limits.
  double area_m2 = 0.0;
};

// The 1-min rows of a run of samples.
struct MinuteRows {
  Series rows;                          // step_s = 60, kValid always present
  std::vector<int> n_samples;           // samples per row
  std::vector<std::uint32_t> qc_flags;  // QcFlag bits per row
};

// Aggregates `samples` (strictly increasing ts_s) minute by minute. Every
// minute that holds at least one sample becomes one row; minutes without
// samples stay gaps. Returns false and sets *error if the options are invalid
// or the times are not increasing.
bool AggregateSamples(std::span<const Sample> samples, const AggregateOptions& options,
                      MinuteRows* out, std::string* error);

// Samples as a Series with step_s = period_s: one row per sample, a column for
// every channel that has a finite value in some sample.
Series SeriesFromSamples(std::span<const Sample> samples, double period_s);

// One Sample per row of `series`, absent channels NaN, rejected_mask 0.
std::vector<Sample> SamplesFromSeries(const Series& series);

}  // namespace pvtwin
