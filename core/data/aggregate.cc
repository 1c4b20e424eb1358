#include "core/data/aggregate.h"

#include <cassert>
#include <cmath>

#include "core/data/physical_limits.h"
#include "core/data/qc.h"
#include "core/data/resample.h"

namespace pvtwin {
namespace {

std::int64_t MinuteStart(std::int64_t t_s) {
  std::int64_t k = t_s / kMinuteS;
  if (t_s % kMinuteS < 0) --k;
  return k * kMinuteS;
}

// Cells that ApplyPaperCorrections changed (NaN-aware comparison).
bool Changed(double before, double after) {
  return std::isnan(before) != std::isnan(after) || (!std::isnan(before) && before != after);
}

}  // namespace

bool RequiredChannelsPresent(std::uint32_t qc_flags) {
  auto has = [qc_flags](Channel c) { return (qc_flags & QcChannelMissingBit(c)) == 0; };
  return has(Channel::kTInC) && has(Channel::kMdotKgS) && has(Channel::kTAmbC) &&
         has(Channel::kPElW) && (has(Channel::kTOutC) || has(Channel::kQThW)) &&
         (has(Channel::kGPoaWM2) || (has(Channel::kGhiWM2) && has(Channel::kDhiWM2)));
}

Series SeriesFromSamples(std::span<const Sample> samples, double period_s) {
  Series s;
  s.step_s = period_s;
  s.time_s.reserve(samples.size());
  for (const Sample& sample : samples) s.time_s.push_back(sample.ts_s);
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    bool any = false;
    for (const Sample& sample : samples) {
      if (std::isfinite(sample.value[c])) {
        any = true;
        break;
      }
    }
    if (!any) continue;
    std::vector<double>& col = s.columns[c];
    col.reserve(samples.size());
    for (const Sample& sample : samples) col.push_back(sample.value[c]);
  }
  return s;
}

std::vector<Sample> SamplesFromSeries(const Series& series) {
  std::vector<Sample> samples(series.size());
  for (std::size_t i = 0; i < series.size(); ++i) {
    samples[i].ts_s = series.time_s[i];
    for (std::size_t c = 0; c < kNumChannels; ++c) {
      if (!series.columns[c].empty()) samples[i].value[c] = series.columns[c][i];
    }
  }
  return samples;
}

bool AggregateSamples(std::span<const Sample> samples, const AggregateOptions& options,
                      MinuteRows* out, std::string* error) {
  assert(out != nullptr && error != nullptr);
  const double period_s = options.sample_period_s;
  if (!(period_s >= 1.0) || period_s != std::floor(period_s) ||
      std::fmod(static_cast<double>(kMinuteS), period_s) != 0.0) {
    *error = "sample_period_s = " + std::to_string(period_s) +
             ": must be a whole number of seconds dividing 60";
    return false;
  }
  if (!(options.fluid_cp_j_kgk > 0.0)) {
    *error = "fluid_cp_j_kgk = " + std::to_string(options.fluid_cp_j_kgk) + ": must be > 0";
    return false;
  }
  MinuteRows result;
  if (samples.empty()) {
    result.rows.step_s = static_cast<double>(kMinuteS);
    result.rows.Ensure(Channel::kValid);
    *out = std::move(result);
    return true;
  }

  Series raw = SeriesFromSamples(samples, period_s);
  Series corrected = raw;
  ApplyPaperCorrections(&corrected);
  // The samples' edges applied the limits already (the Modbus poller, the
  // CSV reader of pvtwin import): on their samples this finds nothing. It
  // stays because table sample_5s is also written by other programs (SQL)
  // and the store's read of it does not check: this is that read's edge,
  // and it flags the minute (kQcRejectedValues) as the poller's rejections
  // are. Should the store's sample read apply the limits, this can go.
  ApplyPhysicalLimits(&corrected, options.area_m2);

  // Minute groups [group_begin[k], group_begin[k + 1]) of sample indices.
  std::vector<std::size_t> group_begin;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (i > 0 && samples[i].ts_s <= samples[i - 1].ts_s) {
      *error = "sample times must be strictly increasing (sample " + std::to_string(i) + ", ts " +
               std::to_string(samples[i].ts_s) + ")";
      return false;
    }
    if (i == 0 || MinuteStart(samples[i].ts_s) != MinuteStart(samples[i - 1].ts_s)) {
      group_begin.push_back(i);
    }
  }
  group_begin.push_back(samples.size());
  const std::size_t n_minutes = group_begin.size() - 1;
  std::vector<std::uint32_t> flags(n_minutes, 0);

  const std::vector<double>& q_th_measured = corrected[Channel::kQThW];
  const bool can_compute_q = corrected.Has(Channel::kMdotKgS) && corrected.Has(Channel::kTInC) &&
                             corrected.Has(Channel::kTOutC);
  std::vector<double> q_th_w = q_th_measured;
  if (q_th_w.empty() && can_compute_q) q_th_w.assign(samples.size(), std::nan(""));

  for (std::size_t k = 0; k < n_minutes; ++k) {
    std::uint32_t& f = flags[k];
    for (std::size_t i = group_begin[k]; i < group_begin[k + 1]; ++i) {
      if (samples[i].rejected_mask != 0) f |= kQcRejectedValues;
      if (samples[i].Get(Channel::kValid) == 0.0) f |= kQcInvalidSamples;
      for (const Channel c :
           {Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaDiffuseWM2}) {
        if (raw.Has(c) && Changed(raw[c][i], corrected[c][i])) f |= kQcIrradianceCorrected;
      }
      if (raw.Has(Channel::kMdotKgS) &&
          Changed(raw[Channel::kMdotKgS][i], corrected[Channel::kMdotKgS][i])) {
        f |= kQcFlowCorrected;
      }
      for (std::size_t c = 0; c < kNumChannels; ++c) {
        // A value outside its physical limits is a rejected reading too.
        const std::vector<double>& before = raw.columns[c];
        if (before.empty() || std::isnan(before[i]) || !std::isnan(corrected.columns[c][i])) {
          continue;
        }
        // A negative flow made missing is the paper's correction, above.
        if (static_cast<Channel>(c) != Channel::kMdotKgS || before[i] >= 0.0) {
          f |= kQcRejectedValues;
        }
      }
    }
    bool q_measured = false;
    for (std::size_t i = group_begin[k]; i < group_begin[k + 1] && !q_th_measured.empty(); ++i) {
      q_measured = q_measured || !std::isnan(q_th_measured[i]);
    }
    if (!q_measured && can_compute_q) {
      bool computed = false;
      for (std::size_t i = group_begin[k]; i < group_begin[k + 1]; ++i) {
        const double mdot_kg_s = corrected[Channel::kMdotKgS][i];
        const double delta_t_k = corrected[Channel::kTOutC][i] - corrected[Channel::kTInC][i];
        q_th_w[i] = mdot_kg_s * options.fluid_cp_j_kgk * delta_t_k;  // NaN if one is missing
        computed = computed || !std::isnan(q_th_w[i]);
      }
      if (computed) f |= kQcThermalPowerComputed;
    }
  }
  if (!q_th_w.empty()) corrected[Channel::kQThW] = std::move(q_th_w);

  if (!Resample(corrected, static_cast<double>(kMinuteS), &result.rows, error, &result.n_samples)) {
    return false;
  }
  assert(result.rows.size() == n_minutes);
  const double expected = static_cast<double>(kMinuteS) / period_s;
  for (std::size_t k = 0; k < n_minutes; ++k) {
    std::uint32_t& f = flags[k];
    if (2.0 * result.n_samples[k] < expected) f |= kQcFewSamples;
    for (std::size_t c = 0; c < kNumChannels; ++c) {
      const auto channel = static_cast<Channel>(c);
      if (channel == Channel::kValid) continue;
      if (std::isnan(result.rows.At(channel, k))) f |= QcChannelMissingBit(channel);
    }
    if (!RequiredChannelsPresent(f)) f |= kQcRequiredMissing;
  }
  result.qc_flags = std::move(flags);
  *out = std::move(result);
  return true;
}

}  // namespace pvtwin
