// Resampling onto an aligned grid (analytic means of a ramp, partial
// buckets, valid propagation) and the paper's data corrections.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/data/qc.h"
#include "core/data/resample.h"

namespace pvtwin {
namespace {

// 5 s samples from t0 for n rows; t_amb_c is a ramp a + b·t (t relative to
// the first bucket start), p_el_w is constant.
Series Ramp(std::int64_t t0, std::size_t n, double a, double b) {
  Series s;
  s.step_s = 5;
  for (std::size_t i = 0; i < n; ++i) s.time_s.push_back(t0 + 5 * static_cast<std::int64_t>(i));
  std::vector<double>& ramp = s.Ensure(Channel::kTAmbC);
  std::vector<double>& constant = s.Ensure(Channel::kPElW);
  for (std::size_t i = 0; i < n; ++i) {
    ramp[i] = a + b * static_cast<double>(s.time_s[i] - t0);
    constant[i] = 250.0;
  }
  return s;
}

TEST(Resample, MeanOfARampIsTheRampAtTheBucketsMidSample) {
  // Samples at start + 0, 5, ..., 55 s: the mean of a + b·t over them is
  // a + b·(start + 27.5).
  constexpr std::int64_t kT0 = 1502094240;  // a multiple of 60
  constexpr double kA = 12.0, kB = 0.01;
  const Series in = Ramp(kT0, 12 * 10, kA, kB);
  Series out;
  std::string error;
  std::vector<int> n_samples;
  ASSERT_TRUE(Resample(in, 60, &out, &error, &n_samples)) << error;
  ASSERT_EQ(out.size(), 10u);
  EXPECT_EQ(out.step_s, 60);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::int64_t start = kT0 + 60 * static_cast<std::int64_t>(k);
    EXPECT_EQ(out.time_s[k], start);
    EXPECT_NEAR(out[Channel::kTAmbC][k], kA + kB * (static_cast<double>(start - kT0) + 27.5),
                1e-12);
    EXPECT_EQ(out[Channel::kPElW][k], 250.0);
    EXPECT_EQ(out[Channel::kValid][k], 1.0);
    EXPECT_EQ(n_samples[k], 12);
  }
  EXPECT_FALSE(out.Has(Channel::kTInC));
}

TEST(Resample, BucketsAlignToMultiplesOfTheStepAndPartialOnesNeedHalfTheSamples) {
  // First sample 35 s into a minute: that bucket holds 5 of 12 samples (35,
  // 40, ..., 55); then one full bucket; the last holds 6 (0, ..., 25).
  constexpr std::int64_t kMinute = 1502094240;
  const Series in = Ramp(kMinute + 35, 5 + 12 + 6, 0.0, 1.0);
  Series out;
  std::string error;
  std::vector<int> n_samples;
  ASSERT_TRUE(Resample(in, 60, &out, &error, &n_samples)) << error;
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out.time_s, (std::vector<std::int64_t>{kMinute, kMinute + 60, kMinute + 120}));
  EXPECT_EQ(n_samples, (std::vector<int>{5, 12, 6}));
  EXPECT_EQ(out[Channel::kValid], (std::vector<double>{0.0, 1.0, 1.0}));
  // Ramp values relative to the first sample: 0, 5, ..., 20 → mean 10.
  EXPECT_DOUBLE_EQ(out[Channel::kTAmbC][0], 10.0);
  EXPECT_DOUBLE_EQ(out[Channel::kTAmbC][1], 25.0 + 27.5);
  EXPECT_DOUBLE_EQ(out[Channel::kTAmbC][2], 85.0 + 12.5);
}

TEST(Resample, OneInvalidRowMakesItsBucketInvalid) {
  Series in = Ramp(0, 24, 0.0, 1.0);
  in.Ensure(Channel::kValid).assign(24, 1.0);
  in[Channel::kValid][15] = 0.0;          // second bucket
  in[Channel::kValid][3] = std::nan("");  // no verdict: counts as valid
  Series out;
  std::string error;
  ASSERT_TRUE(Resample(in, 60, &out, &error)) << error;
  EXPECT_EQ(out[Channel::kValid], (std::vector<double>{1.0, 0.0}));
}

TEST(Resample, MeansSkipMissingValuesAndGapsStayGaps) {
  Series in = Ramp(0, 36, 0.0, 1.0);
  // Bucket 0: two missing values; bucket 1: all missing; bucket 2: removed.
  in[Channel::kTAmbC][0] = std::nan("");
  in[Channel::kTAmbC][11] = std::nan("");
  for (std::size_t i = 12; i < 24; ++i) in[Channel::kTAmbC][i] = std::nan("");
  Series gap = in.Slice(0, 24);
  gap.time_s.push_back(600);  // next row ten minutes later
  gap[Channel::kTAmbC].push_back(7.0);
  gap[Channel::kPElW].push_back(1.0);
  Series out;
  std::string error;
  std::vector<int> n_samples;
  ASSERT_TRUE(Resample(gap, 60, &out, &error, &n_samples)) << error;
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out.time_s, (std::vector<std::int64_t>{0, 60, 600}));
  EXPECT_DOUBLE_EQ(out[Channel::kTAmbC][0], 27.5);  // mean of 5, 10, ..., 50
  EXPECT_TRUE(std::isnan(out[Channel::kTAmbC][1]));
  EXPECT_EQ(out[Channel::kTAmbC][2], 7.0);
  EXPECT_EQ(n_samples, (std::vector<int>{12, 12, 1}));
  EXPECT_EQ(out[Channel::kValid], (std::vector<double>{1.0, 1.0, 0.0}));
}

TEST(Resample, NegativeTimesUseFloorBuckets) {
  const Series in = Ramp(-30, 12, 0.0, 1.0);  // -30 ... 25 s
  Series out;
  std::string error;
  ASSERT_TRUE(Resample(in, 60, &out, &error)) << error;
  EXPECT_EQ(out.time_s, (std::vector<std::int64_t>{-60, 0}));
}

TEST(Resample, RejectsStepsThatDoNotFitTheInput) {
  Series out;
  out.step_s = -1;  // untouched on error
  std::string error;
  const Series in = Ramp(0, 24, 0.0, 1.0);
  EXPECT_FALSE(Resample(in, 62, &out, &error));
  EXPECT_EQ(error, "step 62 s must be a whole multiple of the input step 5 s");
  EXPECT_FALSE(Resample(in, 2.5, &out, &error));
  EXPECT_FALSE(Resample(in, 60.5, &out, &error));
  EXPECT_FALSE(Resample(in, 0, &out, &error));
  EXPECT_FALSE(Resample(in, std::nan(""), &out, &error));
  Series no_step = in;
  no_step.step_s = 0;
  EXPECT_FALSE(Resample(no_step, 60, &out, &error));
  Series unordered = in;
  std::swap(unordered.time_s[3], unordered.time_s[4]);
  EXPECT_FALSE(Resample(unordered, 60, &out, &error));
  EXPECT_EQ(error, "input times must be strictly increasing (row 4)");
  EXPECT_EQ(out.step_s, -1);
  EXPECT_TRUE(Resample(in, 5, &out, &error)) << "same step is allowed";
  EXPECT_EQ(out.size(), in.size());
}

TEST(Resample, AWeekOfFiveSecondSamplesInOnePass) {
  const std::size_t n = 7 * 86400 / 5;
  const Series in = Ramp(0, n, 0.0, 1e-3);
  Series out;
  std::string error;
  ASSERT_TRUE(Resample(in, 60, &out, &error)) << error;
  EXPECT_EQ(out.size(), n / 12);
}

TEST(QcPaperCorrections, IrradianceGlitchesAboveFiveThousandBecomeZero) {
  Series s;
  s.time_s = {0, 60, 120};
  s[Channel::kGPoaWM2] = {5001, 5000, 800};
  s[Channel::kGhiWM2] = {65535, 0, std::nan("")};
  s[Channel::kDhiWM2] = {0, 1e9, 100};
  s[Channel::kGPoaDiffuseWM2] = {5000.5, 0, 0};
  s[Channel::kLwDownWM2] = {6000, 300, 300};  // long-wave: not corrected
  const QcCorrections counts = ApplyPaperCorrections(&s);
  EXPECT_EQ(counts.irradiance_zeroed, 3u);
  EXPECT_EQ(counts.Total(), 3u);
  EXPECT_EQ(s[Channel::kGPoaWM2], (std::vector<double>{0, 5000, 800}));
  EXPECT_EQ(s[Channel::kGhiWM2][0], 0.0);
  EXPECT_TRUE(std::isnan(s[Channel::kGhiWM2][2]));
  // 1e9 W/m² is no glitch of the paper's kind but a broken reading: left to
  // the physical limits, which make it missing rather than a plausible 0.
  EXPECT_EQ(s[Channel::kDhiWM2][1], 1e9);
  EXPECT_EQ(s[Channel::kGPoaDiffuseWM2][0], 0.0);
  EXPECT_EQ(s[Channel::kLwDownWM2][0], 6000.0);
}

TEST(QcPaperCorrections, SmallNegativeFlowsBecomeZeroLargeOnesMissing) {
  Series s;
  s.time_s = {0, 60, 120, 180, 240};
  s[Channel::kMdotKgS] = {-0.0004, -kNegativeFlowToleranceKgS, -0.0011, 0.03, std::nan("")};
  const QcCorrections counts = ApplyPaperCorrections(&s);
  EXPECT_EQ(counts.flow_zeroed, 2u);
  EXPECT_EQ(counts.flow_rejected, 1u);
  EXPECT_EQ(s[Channel::kMdotKgS][0], 0.0);
  EXPECT_EQ(s[Channel::kMdotKgS][1], 0.0);
  EXPECT_TRUE(std::isnan(s[Channel::kMdotKgS][2]));
  EXPECT_EQ(s[Channel::kMdotKgS][3], 0.03);
  EXPECT_TRUE(std::isnan(s[Channel::kMdotKgS][4]));
}

TEST(QcPaperCorrections, AbsentChannelsStayAbsent) {
  Series s;
  s.time_s = {0};
  s[Channel::kTAmbC] = {20};
  EXPECT_EQ(ApplyPaperCorrections(&s).Total(), 0u);
  EXPECT_FALSE(s.Has(Channel::kGPoaWM2));
  EXPECT_FALSE(s.Has(Channel::kMdotKgS));
}

TEST(QcPaperCorrections, CorrectBeforeResampling) {
  // A 5000+ W/m² glitch in one 5 s sample would add > 400 W/m² to a minute.
  Series in = Ramp(0, 12, 0.0, 0.0);
  in.Ensure(Channel::kGPoaWM2).assign(12, 0.0);
  in[Channel::kGPoaWM2][6] = 5001;
  ApplyPaperCorrections(&in);
  Series out;
  std::string error;
  ASSERT_TRUE(Resample(in, 60, &out, &error)) << error;
  EXPECT_EQ(out[Channel::kGPoaWM2][0], 0.0);
}

}  // namespace
}  // namespace pvtwin
