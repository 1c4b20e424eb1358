// Aggregation of 5 s samples into 1-min rows: analytic means, Q_u from flow,
// c_p and ΔT per sample, the paper's corrections and the qc_flags bits.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/data/aggregate.h"
#include "tests/support/fixtures.h"

namespace pvtwin {
namespace {

using testing::kJune1Noon2024UtcS;
constexpr double kCpJKgK = 3650.0;

// n samples every 5 s from t0 with every required channel set to a constant,
// t_amb_c a ramp 10 + 0.1·(t − t0).
std::vector<Sample> Samples(std::int64_t t0, int n) {
  std::vector<Sample> samples(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    Sample& s = samples[static_cast<std::size_t>(i)];
    s.ts_s = t0 + 5 * i;
    s.Set(Channel::kTInC, 20.0);
    s.Set(Channel::kTOutC, 30.0);
    s.Set(Channel::kMdotKgS, 0.03);
    s.Set(Channel::kGPoaWM2, 600.0);
    s.Set(Channel::kTAmbC, 10.0 + 0.1 * (5.0 * i));
    s.Set(Channel::kPElW, 150.0);
  }
  return samples;
}

MinuteRows Aggregate(const std::vector<Sample>& samples, double period_s = 5.0) {
  AggregateOptions options;
  options.sample_period_s = period_s;
  options.fluid_cp_j_kgk = kCpJKgK;
  MinuteRows rows;
  std::string error;
  EXPECT_TRUE(AggregateSamples(samples, options, &rows, &error)) << error;
  return rows;
}

TEST(Aggregate, FullMinuteMeansAndThermalPowerFromFlowCpAndDeltaT) {
  const MinuteRows m = Aggregate(Samples(kJune1Noon2024UtcS, 12));
  ASSERT_EQ(m.rows.size(), 1u);
  EXPECT_EQ(m.rows.time_s[0], kJune1Noon2024UtcS);
  EXPECT_EQ(m.rows.step_s, 60.0);
  EXPECT_EQ(m.n_samples[0], 12);
  // Ramp 10 + 0.1·t at t = 0, 5, ..., 55 s: mean 10 + 0.1·27.5.
  EXPECT_NEAR(m.rows[Channel::kTAmbC][0], 12.75, 1e-12);
  EXPECT_EQ(m.rows[Channel::kPElW][0], 150.0);
  // Q_u = 0.03 kg/s · 3650 J/(kg·K) · 10 K = 1095 W.
  EXPECT_NEAR(m.rows[Channel::kQThW][0], 1095.0, 1e-9);
  EXPECT_EQ(m.rows[Channel::kValid][0], 1.0);
  const std::uint32_t f = m.qc_flags[0];
  EXPECT_TRUE(f & kQcThermalPowerComputed);
  EXPECT_FALSE(f & (kQcFewSamples | kQcRequiredMissing | kQcRejectedValues |
                    kQcIrradianceCorrected | kQcFlowCorrected | kQcInvalidSamples));
  EXPECT_TRUE(f & QcChannelMissingBit(Channel::kTBackC));
  EXPECT_FALSE(f & QcChannelMissingBit(Channel::kQThW));
  EXPECT_FALSE(f & QcChannelMissingBit(Channel::kTAmbC));
}

TEST(Aggregate, ThermalPowerIsTheMeanOfThePerSampleProductsNotTheProductOfMeans) {
  std::vector<Sample> samples = Samples(kJune1Noon2024UtcS, 12);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const bool odd = i % 2 == 1;
    samples[i].Set(Channel::kMdotKgS, odd ? 0.04 : 0.02);
    samples[i].Set(Channel::kTOutC, odd ? 35.0 : 25.0);  // ΔT 15 K or 5 K
  }
  const MinuteRows m = Aggregate(samples);
  // Even: 0.02·3650·5 = 365 W; odd: 0.04·3650·15 = 2190 W; mean 1277.5 W
  // (the product of the means would be 0.03·3650·10 = 1095 W).
  EXPECT_NEAR(m.rows[Channel::kQThW][0], 1277.5, 1e-9);
  EXPECT_NEAR(m.rows[Channel::kMdotKgS][0], 0.03, 1e-15);
}

TEST(Aggregate, MeasuredThermalPowerIsAveragedNotRecomputed) {
  std::vector<Sample> samples = Samples(kJune1Noon2024UtcS, 12);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    samples[i].Set(Channel::kQThW, i < 6 ? 1000.0 : std::nan(""));  // meter read half the time
  }
  const MinuteRows m = Aggregate(samples);
  EXPECT_EQ(m.rows[Channel::kQThW][0], 1000.0);
  EXPECT_FALSE(m.qc_flags[0] & kQcThermalPowerComputed);
}

TEST(Aggregate, HalfTheExpectedSamplesIsEnoughFewerIsFlagged) {
  // 6 of 12 expected: valid; 5 of 12: kQcFewSamples and valid 0.
  MinuteRows m = Aggregate(Samples(kJune1Noon2024UtcS, 6));
  EXPECT_EQ(m.n_samples[0], 6);
  EXPECT_FALSE(m.qc_flags[0] & kQcFewSamples);
  EXPECT_EQ(m.rows[Channel::kValid][0], 1.0);
  m = Aggregate(Samples(kJune1Noon2024UtcS, 5));
  EXPECT_EQ(m.n_samples[0], 5);
  EXPECT_TRUE(m.qc_flags[0] & kQcFewSamples);
  EXPECT_EQ(m.rows[Channel::kValid][0], 0.0);
  // At a 10 s poll period, 3 of 6 expected samples are enough.
  std::vector<Sample> slow = Samples(kJune1Noon2024UtcS, 6);
  slow = {slow[0], slow[2], slow[4]};  // t = 0, 10, 20 s
  m = Aggregate(slow, 10.0);
  EXPECT_FALSE(m.qc_flags[0] & kQcFewSamples);
}

TEST(Aggregate, PaperCorrectionsApplyBeforeAveragingAndAreFlagged) {
  std::vector<Sample> samples = Samples(kJune1Noon2024UtcS, 12);
  samples[3].Set(Channel::kGPoaWM2, 6500.0);   // night-time glitch (paper Table 2) → 0
  samples[4].Set(Channel::kMdotKgS, -0.0005);  // pump off noise (paper Table 1) → 0
  samples[5].Set(Channel::kMdotKgS, -0.5);     // broken meter → dropped
  const MinuteRows m = Aggregate(samples);
  EXPECT_NEAR(m.rows[Channel::kGPoaWM2][0], 600.0 * 11 / 12, 1e-9);
  // Flow: ten samples of 0.03, one 0, one missing.
  EXPECT_NEAR(m.rows[Channel::kMdotKgS][0], 0.3 / 11, 1e-15);
  // Q_u per sample: ten of 1095 W, one 0 W (zero flow), one missing.
  EXPECT_NEAR(m.rows[Channel::kQThW][0], 10950.0 / 11, 1e-9);
  EXPECT_TRUE(m.qc_flags[0] & kQcIrradianceCorrected);
  EXPECT_TRUE(m.qc_flags[0] & kQcFlowCorrected);
  EXPECT_EQ(m.n_samples[0], 12);
}

TEST(Aggregate, RejectedAndMissingChannelsAreFlaggedAndLeftOutOfTheMeans) {
  std::vector<Sample> samples = Samples(kJune1Noon2024UtcS, 12);
  samples[0].Set(Channel::kPElW, 90.0);
  samples[0].Reject(Channel::kPElW);  // rejected reading: NaN with its bit
  samples[1].Set(Channel::kPElW, 90.0);
  for (Sample& s : samples) s.Set(Channel::kTAmbC, std::nan(""));  // weather station down
  const MinuteRows m = Aggregate(samples);
  EXPECT_NEAR(m.rows[Channel::kPElW][0], (90.0 + 10 * 150.0) / 11, 1e-12);
  EXPECT_TRUE(std::isnan(m.rows.At(Channel::kTAmbC, 0)));
  const std::uint32_t f = m.qc_flags[0];
  EXPECT_TRUE(f & kQcRejectedValues);
  EXPECT_TRUE(f & QcChannelMissingBit(Channel::kTAmbC));
  EXPECT_TRUE(f & kQcRequiredMissing);
}

TEST(Aggregate, HorizontalIrradianceReplacesThePlaneOfArrayOneAsRequiredInput) {
  std::vector<Sample> samples = Samples(kJune1Noon2024UtcS, 12);
  for (Sample& s : samples) {
    s.Set(Channel::kGPoaWM2, std::nan(""));
    s.Set(Channel::kGhiWM2, 500.0);
  }
  EXPECT_TRUE(Aggregate(samples).qc_flags[0] & kQcRequiredMissing);  // ghi without dhi
  for (Sample& s : samples) s.Set(Channel::kDhiWM2, 100.0);
  EXPECT_FALSE(Aggregate(samples).qc_flags[0] & kQcRequiredMissing);
}

TEST(Aggregate, AnInvalidSampleMakesTheMinuteInvalid) {
  std::vector<Sample> samples = Samples(kJune1Noon2024UtcS, 12);
  samples[7].Set(Channel::kValid, 0.0);
  const MinuteRows m = Aggregate(samples);
  EXPECT_EQ(m.rows[Channel::kValid][0], 0.0);
  EXPECT_TRUE(m.qc_flags[0] & kQcInvalidSamples);
}

TEST(Aggregate, MinutesAlignToUnixMinutesAndGapsStayGaps) {
  // 35 s into minute 0: samples at 35..55 (5), minute 1 complete (12),
  // minute 2 empty, minute 3 with 2 samples.
  std::vector<Sample> samples = Samples(kJune1Noon2024UtcS + 35, 17);
  const std::vector<Sample> late = Samples(kJune1Noon2024UtcS + 180, 2);
  samples.insert(samples.end(), late.begin(), late.end());
  const MinuteRows m = Aggregate(samples);
  EXPECT_EQ(m.rows.time_s, (std::vector<std::int64_t>{kJune1Noon2024UtcS, kJune1Noon2024UtcS + 60,
                                                      kJune1Noon2024UtcS + 180}));
  EXPECT_EQ(m.n_samples, (std::vector<int>{5, 12, 2}));
}

TEST(Aggregate, RejectsBadPeriodsAndUnorderedSamples) {
  AggregateOptions options;
  MinuteRows rows;
  std::string error;
  options.sample_period_s = 7.0;  // does not divide 60
  EXPECT_FALSE(AggregateSamples(Samples(kJune1Noon2024UtcS, 3), options, &rows, &error));
  EXPECT_NE(error.find("sample_period_s = 7"), std::string::npos) << error;
  options.sample_period_s = 5.0;
  std::vector<Sample> samples = Samples(kJune1Noon2024UtcS, 3);
  std::swap(samples[1], samples[2]);
  EXPECT_FALSE(AggregateSamples(samples, options, &rows, &error));
  EXPECT_NE(error.find("strictly increasing"), std::string::npos) << error;
}

TEST(Aggregate, SamplesAndSeriesConvertBothWays) {
  std::vector<Sample> samples = Samples(kJune1Noon2024UtcS, 3);
  const Series s = SeriesFromSamples(samples, 5.0);
  EXPECT_EQ(s.step_s, 5.0);
  EXPECT_TRUE(s.Has(Channel::kTInC));
  EXPECT_FALSE(s.Has(Channel::kTBackC));  // never set: absent, not a NaN column
  const std::vector<Sample> back = SamplesFromSeries(s);
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back[i].ts_s, samples[i].ts_s);
    EXPECT_EQ(back[i].Get(Channel::kTAmbC), samples[i].Get(Channel::kTAmbC));
    EXPECT_FALSE(back[i].Has(Channel::kTBackC));
  }
}

}  // namespace
}  // namespace pvtwin
