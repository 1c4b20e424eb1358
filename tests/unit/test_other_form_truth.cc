// The other-form truths of the effect modules (EffectModule::other_truth,
// issue 11 item 2): each form against a hand calculation from its published
// equation, a check that it differs from the candidate's form and acts only
// where it should, and the other-form battery of diagnose-selftest end to end
// (structure only: the decision logic is judged by the full battery).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "core/common/calendar.h"
#include "core/common/units.h"
#include "core/diagnosis/diagnosis_selftest.h"
#include "core/effects/clock_offset.h"
#include "core/effects/effects.h"
#include "core/effects/iam.h"
#include "core/effects/irradiance_bias.h"
#include "core/effects/pv_clipping.h"
#include "core/effects/shading.h"
#include "core/effects/sky_radiation.h"
#include "core/effects/soiling.h"
#include "core/effects/transport_delay.h"
#include "core/effects/wind.h"
#include "core/physics/iam.h"
#include "core/synth/synthetic_plant.h"

namespace pvtwin {
namespace {

// --- Hand calculations from the published equations ---

TEST(OtherFormTruth, FresnelCoverAtNormalIncidenceAnd60Degrees) {
  // τ(0) = exp(−K·L)·(1 − ((n − 1)/(n + 1))²), n = 1.526, K·L = 0.008:
  // exp(−0.008) = 0.992032, (0.526/2.526)² = 0.043362 → 0.949016.
  EXPECT_NEAR(FresnelCoverTransmittance(0.0, kOtherTruthCover), 0.949016, 1e-6);
  // 60°: θ_r = asin(sin 60°/1.526) = 34.578°; r_⊥ = sin²(−25.422°)/sin²(94.578°)
  // = 0.18550, r_∥ = tan²(−25.422°)/tan²(94.578°) = 0.00145; absorption
  // exp(−0.008/cos 34.578°) = 0.990330 → τ = 0.897772, K = 0.946003.
  EXPECT_NEAR(FresnelCoverTransmittance(DegToRad(60.0), kOtherTruthCover), 0.897772, 2e-6);
  EXPECT_NEAR(FresnelIam(DegToRad(60.0), kOtherTruthCover), 0.946003, 2e-6);
  EXPECT_EQ(FresnelIam(DegToRad(90.0), kOtherTruthCover), 0.0);
}

TEST(OtherFormTruth, FresnelIamIsNoSoukaSafwatCurve) {
  // The b0 that matches the Fresnel cover at 60° (1 − b0 = K(60°)) misses it
  // at 80° by far: the candidate's form cannot fit the truth exactly.
  const double k60 = FresnelIam(DegToRad(60.0), kOtherTruthCover);
  const double b0 = 1.0 - k60;
  EXPECT_NEAR(IamSoukaSafwat(DegToRad(60.0), b0), k60, 1e-12);
  EXPECT_GT(
      std::fabs(IamSoukaSafwat(DegToRad(80.0), b0) - FresnelIam(DegToRad(80.0), kOtherTruthCover)),
      0.2);
}

TEST(OtherFormTruth, HorizonSoftEdgeAtAKnownSunPosition) {
  const HorizonObstacle& o = OtherTruthObstacle();
  // Between the vertices (258°, 45°) and (272°, 40°): h(265°) = 42.5°.
  const double az = DegToRad(265.0);
  EXPECT_NEAR(RadToDeg(HorizonElevationRad(o.profile, az)), 42.5, 1e-9);
  // Linear penumbra of 1.5°: s = (42.5 − α)/1.5 + 1/2.
  EXPECT_NEAR(HorizonBeamShare(o.profile, az, DegToRad(42.5), o.edge_width_rad), 0.5, 1e-9);
  EXPECT_NEAR(HorizonBeamShare(o.profile, az, DegToRad(42.875), o.edge_width_rad), 0.25, 1e-9);
  EXPECT_NEAR(HorizonBeamShare(o.profile, az, DegToRad(43.25), o.edge_width_rad), 0.0, 1e-9);
  EXPECT_NEAR(HorizonBeamShare(o.profile, az, DegToRad(41.75), o.edge_width_rad), 1.0, 1e-9);
  EXPECT_EQ(HorizonBeamShare(o.profile, az, DegToRad(44.0), o.edge_width_rad), 0.0);
  EXPECT_EQ(HorizonBeamShare(o.profile, az, DegToRad(41.0), o.edge_width_rad), 1.0);
  // Outside the obstacle's azimuths and with the sun down: nothing.
  EXPECT_EQ(HorizonBeamShare(o.profile, DegToRad(180.0), DegToRad(5.0), o.edge_width_rad), 0.0);
  EXPECT_EQ(HorizonBeamShare(o.profile, az, DegToRad(-1.0), o.edge_width_rad), 0.0);
}

TEST(OtherFormTruth, HorizonDiffuseShareByDozierFrew) {
  // A wall of constant 30° over 90° of azimuth: (1/2π)·(π/2)·sin²30° = 0.0625.
  HorizonProfile wall;
  wall.azimuth_rad = {DegToRad(180.0), DegToRad(180.0), DegToRad(270.0), DegToRad(270.0)};
  wall.elevation_rad = {0.0, DegToRad(30.0), DegToRad(30.0), 0.0};
  EXPECT_NEAR(HorizonDiffuseShare(wall), 0.0625, 1e-12);
  // A ramp from 0 to 30° over 30°: ∫ sin²γ dγ = π/12 − sin 60°/4 = 0.045293 → /2π.
  HorizonProfile ramp;
  ramp.azimuth_rad = {DegToRad(200.0), DegToRad(230.0)};
  ramp.elevation_rad = {0.0, DegToRad(30.0)};
  EXPECT_NEAR(HorizonDiffuseShare(ramp), 0.0072086107, 1e-9);
  // The candidate's box is that wall: the same share from its width and edge.
  EXPECT_NEAR(BoxDiffuseShare(DegToRad(90.0), DegToRad(30.0)), HorizonDiffuseShare(wall), 1e-12);
  EXPECT_EQ(BoxDiffuseShare(0.0, DegToRad(30.0)), 0.0);
  EXPECT_NEAR(BoxDiffuseShare(DegToRad(400.0), DegToRad(120.0)), 1.0, 1e-12);  // clamped
}

TEST(OtherFormTruth, SaturatingSoilingBeforeAndAfterARainReset) {
  // L(5 d) = 0.1·(1 − exp(−5/8)) = 0.0464739; rain washes 60 %: 0.0185895;
  // two days later: 0.1 − (0.1 − 0.0185895)·exp(−2/8) = 0.0365975.
  const SoilingWithRain& s = kOtherTruthSoiling;
  const double before = SaturatingSoilingLoss(0.0, 5.0, s.max_loss, s.time_constant_days);
  EXPECT_NEAR(before, 0.0464739, 1e-7);
  const double after = SoilingLossAfterRain(before, s.cleaned_share);
  EXPECT_NEAR(after, 0.0185895, 1e-7);
  EXPECT_NEAR(SaturatingSoilingLoss(after, 2.0, s.max_loss, s.time_constant_days), 0.0365975, 1e-7);
}

TEST(OtherFormTruth, SoilingSeriesFallsBetweenRainsAndRisesAtEachRain) {
  // Hourly rows over 20 days; find a seed with rain in them.
  std::vector<std::int64_t> t;
  const std::int64_t t0 = 1717200000;  // 2024-06-01 00:00 UTC
  for (int h = 0; h < 20 * 24; ++h) t.push_back(t0 + 3600 * h);
  for (std::uint64_t seed = 1; seed < 50; ++seed) {
    int rains = 0;
    for (std::int64_t day = t0 / kSecondsPerDay + 1; day < t0 / kSecondsPerDay + 20; ++day) {
      rains += RainOnDay(seed, day, kOtherTruthSoiling);
    }
    if (rains == 0) continue;
    const std::vector<double> tau = SoilingTransmittanceWithRain(t, kOtherTruthSoiling, seed);
    EXPECT_EQ(tau.front(), 1.0);
    int rises = 0;
    for (std::size_t i = 1; i < t.size(); ++i) {
      const bool rain =
          t[i] % kSecondsPerDay == 0 && RainOnDay(seed, t[i] / kSecondsPerDay, kOtherTruthSoiling);
      if (rain) {
        // At the rain: 1 − τ = 0.4·(the loss evolved to the day's start).
        const double loss_before =
            SaturatingSoilingLoss(1.0 - tau[i - 1], 1.0 / 24.0, kOtherTruthSoiling.max_loss,
                                  kOtherTruthSoiling.time_constant_days);
        EXPECT_NEAR(1.0 - tau[i], 0.4 * loss_before, 1e-12);
        ++rises;
      } else {
        EXPECT_LT(tau[i], tau[i - 1]);
      }
    }
    EXPECT_EQ(rises, rains);
    return;
  }
  FAIL() << "no seed with rain in 20 days";
}

TEST(OtherFormTruth, InverterKneeAndDerating) {
  // P_ac = P_dc/(1 + (P_dc/P_lim)^8)^(1/8): at P_lim 2^(−1/8) = 0.917004;
  // at P_lim/2: 0.5/(1 + 2^−8)^(1/8) = 0.499756; at 2·P_lim: 2/257^(1/8) = 0.999513.
  EXPECT_NEAR(SoftKneeAcPowerW(200.0, 200.0, 8.0), 200.0 * 0.9170040, 1e-4);
  EXPECT_NEAR(SoftKneeAcPowerW(100.0, 200.0, 8.0), 200.0 * 0.4997564, 1e-4);
  EXPECT_NEAR(SoftKneeAcPowerW(400.0, 200.0, 8.0), 200.0 * 0.9995128, 1e-4);
  EXPECT_EQ(SoftKneeAcPowerW(0.0, 200.0, 8.0), 0.0);
  // Derating 1 %/K above 25 °C: 35 °C → 90 %; below 25 °C none.
  EXPECT_NEAR(DeratedLimitW(216.0, 35.0, 25.0, 0.01), 194.4, 1e-9);
  EXPECT_EQ(DeratedLimitW(216.0, 20.0, 25.0, 0.01), 216.0);
  // No hard clip min(P_dc, L') follows the knee within 5 % of P_lim over
  // P_dc in [0, 2·P_lim] (the best L' = 188.8 W still misses by 11.1 W).
  for (double limit = 100.0; limit <= 300.0; limit += 0.5) {
    double worst = 0.0;
    for (double p_dc = 0.0; p_dc <= 400.0; p_dc += 0.5) {
      worst =
          std::max(worst, std::fabs(std::min(p_dc, limit) - SoftKneeAcPowerW(p_dc, 200.0, 8.0)));
    }
    EXPECT_GT(worst, 10.0) << "limit " << limit;
  }
}

TEST(OtherFormTruth, MixedTankStepResponse) {
  // 1 kg tank, 0.036 kg/s, no loss, 60 s: a·dt = 2.16, e^−2.16 = 0.115325;
  // from 20 °C towards 30 °C: end 28.846749, row mean 30 − 10·(1 − e^−2.16)/2.16 = 25.904283.
  const TankStep step = MixedTankStep(20.0, 30.0, 10.0, 0.036, 3650.0, 1.0, 0.0, 60.0);
  EXPECT_NEAR(step.t_end_c, 28.846749, 1e-6);
  EXPECT_NEAR(step.t_mean_c, 25.904283, 1e-6);
  // Without flow and loss the tank holds.
  EXPECT_EQ(MixedTankStep(20.0, 30.0, 10.0, 0.0, 3650.0, 1.0, 0.0, 60.0).t_end_c, 20.0);
  // Without flow it cools towards ambient with M·c_p/UA.
  EXPECT_NEAR(MixedTankStep(20.0, 30.0, 10.0, 0.0, 3650.0, 1.0, 3.65, 1000.0).t_end_c,
              10.0 + 10.0 * std::exp(-1.0), 1e-9);
}

TEST(OtherFormTruth, CubicClockInterpolationIsExactForQuadratics) {
  std::vector<std::int64_t> t;
  std::vector<double> v;
  for (int k = 0; k < 10; ++k) {
    t.push_back(60 * k);
    v.push_back(static_cast<double>(60 * k) * (60 * k));
  }
  // 97 s: between rows 1 and 2, 97² = 9409 exactly (Catmull–Rom on a uniform grid).
  EXPECT_NEAR(CubicAt(t, v, 97.0), 9409.0, 1e-9);
  EXPECT_NEAR(CubicAt(t, v, 301.5), 301.5 * 301.5, 1e-9);
  // Held at the ends.
  EXPECT_EQ(CubicAt(t, v, -5.0), 0.0);
  EXPECT_EQ(CubicAt(t, v, 1e6), v.back());
  // 97 s is no whole number of 60-s rows.
  EXPECT_NE(std::fmod(kOtherTruthClock.offset_s, 60.0), 0.0);
}

TEST(OtherFormTruth, PyranometerCosineErrorAndOffset) {
  // f(80°) = 1 − 0.11; f(60°) = 1 − 0.11·0.75³ = 0.95359375.
  EXPECT_NEAR(PyranometerCosineResponse(DegToRad(80.0), 0.11), 0.89, 1e-12);
  // B = 600, D = 200 W/m², θ = 60°, k = 0.06, a = −8 W/m²:
  // (0.95359375·600 + 200)/1.06 − 8 = 720.449292.
  EXPECT_NEAR(PyranometerReadingWM2(600.0, 200.0, DegToRad(60.0), 0.06, kOtherTruthPyranometer),
              720.449292, 1e-6);
  // At night the sensor reads what it sees (no daytime offset).
  EXPECT_EQ(PyranometerReadingWM2(0.0, 0.0, DegToRad(100.0), 0.06, kOtherTruthPyranometer), 0.0);
}

TEST(OtherFormTruth, TestEtAlConvectionAndSwinbankSky) {
  EXPECT_DOUBLE_EQ(ConvectionTestEtAlWM2K(0.0), 8.55);
  EXPECT_NEAR(ConvectionTestEtAlWM2K(3.0), 16.23, 1e-12);
  EXPECT_NEAR(FrontConductanceTestWM2K(14.0, 3.0), 21.68, 1e-12);
  // Swinbank at 20 °C: 5.31e-13·293.15²/σ = 0.804753.
  EXPECT_NEAR(SwinbankClearSkyEmissivity(293.15), 0.804753, 1e-6);
  EXPECT_DOUBLE_EQ(CloudySkyEmissivity(0.8, 0.5), 0.9);
  EXPECT_NEAR(LongWaveOnPlaneWM2(0.8, 20.0, 0.0),
              0.8 * kStefanBoltzmannW_m2k4 * std::pow(293.15, 4), 1e-9);
  EXPECT_EQ(CloudFractionFromDiffuseFraction(0.1), 0.0);
  EXPECT_EQ(CloudFractionFromDiffuseFraction(1.0), 1.0);
}

// --- The forms in the synthetic plant ---

// 3 days at 5 min of truth `truth`; with kOtherForm the effect `other` (may
// be null) in its other form.
SyntheticOptions Options(const ModelSpec& truth, TruthForm form, std::uint64_t seed,
                         const EffectModule* other = nullptr) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions o;
  std::string error;
  EXPECT_TRUE(DefaultSyntheticOptions(plant, truth.Name(), 3, seed, &o, &error)) << error;
  o.weather.step_s = 300.0;
  o.truth_form = form;
  if (other != nullptr) o.other_form_effects = {other};
  return o;
}

double MaxAbsDiff(const Series& a, const Series& b, Channel c) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double x = a[c][i], y = b[c][i];
    if (std::isfinite(x) && std::isfinite(y)) worst = std::max(worst, std::fabs(x - y));
  }
  return worst;
}

TEST(OtherFormTruth, EveryOtherFormDiffersFromTheSameFormAndFromNoEffect) {
  const Plant plant = DesignExamplePlant();
  int forms = 0;
  for (const SelftestCase& c : SelftestCases(plant)) {
    const EffectModule* m = FindEffect(c.expected);
    if (m == nullptr || m->other_truth == nullptr) continue;
    ++forms;
    const Series same = MakeSyntheticPlantData(plant, Options(c.truth, TruthForm::kSameForm, 3));
    const Series other =
        MakeSyntheticPlantData(plant, Options(c.truth, TruthForm::kOtherForm, 3, m));
    const Series none = MakeSyntheticPlantData(plant, Options(c.base, TruthForm::kSameForm, 3));
    // A sensor error shows in the plane sensor, the rest in the outputs.
    const bool sensor = m->apply_sensor_error != nullptr;
    double d_same = 0.0, d_none = 0.0;
    for (Channel ch : sensor ? std::vector<Channel>{Channel::kGPoaWM2}
                             : std::vector<Channel>{Channel::kPElW, Channel::kQThW}) {
      d_same = std::max(d_same, MaxAbsDiff(same, other, ch));
      d_none = std::max(d_none, MaxAbsDiff(none, other, ch));
    }
    EXPECT_GT(d_same, 1.0) << c.name << ": the other form equals the candidate's";
    EXPECT_GT(d_none, 1.0) << c.name << ": the other form does nothing";
  }
  EXPECT_EQ(forms, 9);
}

TEST(OtherFormTruth, ObstacleFreeDaysEqualTheEffectFreeTruth) {
  const Plant plant = DesignExamplePlant();
  const ModelSpec base = SelftestCases(plant).front().base;  // any base without shading
  const EffectModule* shading = FindEffect("shading");
  ModelSpec with = WithEffect(base, *shading);
  // Seeds whose three days hold both kinds.
  for (std::uint64_t seed = 1; seed < 40; ++seed) {
    SyntheticOptions o = Options(with, TruthForm::kOtherForm, seed, shading);
    const std::int64_t first_day = o.weather.start_time_s / kSecondsPerDay;
    int on = 0;
    for (int k = 0; k < 3; ++k) on += ObstacleOnDay(seed, first_day + k);
    if (on == 0 || on == 3) continue;
    const Series other = MakeSyntheticPlantData(plant, o);
    const Series none = MakeSyntheticPlantData(plant, Options(base, TruthForm::kSameForm, seed));
    double on_days = 0.0, off_days = 0.0;
    for (std::size_t i = 0; i < other.size(); ++i) {
      const double d = std::fabs(other[Channel::kPElW][i] - none[Channel::kPElW][i]);
      if (!std::isfinite(d)) continue;
      const std::int64_t day = other.time_s[i] / kSecondsPerDay;
      // The collector's heat capacity carries a shaded afternoon a little way.
      const bool after_midnight = other.time_s[i] % kSecondsPerDay < 4 * 3600;
      if (ObstacleOnDay(seed, day)) {
        on_days = std::max(on_days, d);
      } else if (!after_midnight) {
        off_days = std::max(off_days, d);
      }
    }
    EXPECT_LT(off_days, 1e-6) << "seed " << seed;
    if (on_days > 20.0) return;  // else the obstacle's days were overcast: another seed
  }
  FAIL() << "no seed with sunny obstacle days among days without it";
}

TEST(OtherFormTruth, SensorFormLeavesTheOutputsAlone) {
  // The pyranometer's errors change what it reads, not what the plant does.
  const Plant plant = DesignExamplePlant();
  for (const SelftestCase& c : SelftestCases(plant)) {
    const EffectModule* m = FindEffect(c.expected);
    if (m == nullptr || m->other_truth == nullptr || m->other_truth->measured == nullptr) continue;
    const Series other =
        MakeSyntheticPlantData(plant, Options(c.truth, TruthForm::kOtherForm, 5, m));
    const Series none = MakeSyntheticPlantData(plant, Options(c.base, TruthForm::kSameForm, 5));
    EXPECT_EQ(MaxAbsDiff(other, none, Channel::kPElW), 0.0) << c.name;
    EXPECT_EQ(MaxAbsDiff(other, none, Channel::kQThW), 0.0) << c.name;
    EXPECT_EQ(MaxAbsDiff(other, none, Channel::kGhiWM2), 0.0) << c.name;
  }
}

TEST(OtherFormTruth, LoggedWeatherStaysWhatTheStationLogged) {
  // Clock and sky forms change the plant's weather, not the logged channels.
  const Plant plant = DesignExamplePlant();
  for (const SelftestCase& c : SelftestCases(plant)) {
    const EffectModule* m = FindEffect(c.expected);
    if (m == nullptr || m->other_truth == nullptr || m->other_truth->weather == nullptr) continue;
    const Series other =
        MakeSyntheticPlantData(plant, Options(c.truth, TruthForm::kOtherForm, 2, m));
    const Series same = MakeSyntheticPlantData(plant, Options(c.truth, TruthForm::kSameForm, 2));
    for (Channel ch : {Channel::kGPoaWM2, Channel::kTAmbC, Channel::kWindMS, Channel::kLwDownWM2}) {
      if (!other.Has(ch)) continue;
      EXPECT_EQ(MaxAbsDiff(other, same, ch), 0.0) << c.name;
    }
  }
}

// --- The other-form battery end to end (structure, not its hit rate) ---

TEST(OtherFormBattery, RunsEndToEndAndReportsBothTables) {
  const Plant plant = DesignExamplePlant();
  SelftestOptions options;
  options.train_days = 4;
  options.heldout_days = 2;
  options.step_s = 600.0;
  options.diagnosis.threads = 1;
  std::vector<SelftestOutcome> outcomes;
  const std::vector<SelftestCase> other = OtherFormSelftestCases(plant);
  for (const SelftestCase& c : other) {
    EXPECT_EQ(c.form, TruthForm::kOtherForm);
    if (c.name != "pv_clipping" && c.name != "null" && c.name != "snow_cover") continue;
    EXPECT_EQ(OtherFormChangesData(c), c.name == "pv_clipping") << c.name;
    outcomes.push_back(RunSelftestCase(plant, c, 1, options));
  }
  ASSERT_EQ(outcomes.size(), 3u);
  for (const SelftestOutcome& o : outcomes) {
    EXPECT_EQ(o.form, TruthForm::kOtherForm);
    EXPECT_NE(o.verdict, "error") << o.case_name << ": " << o.why;
    EXPECT_FALSE(o.verdict.empty());
    EXPECT_TRUE(std::isfinite(o.heldout_truth_w_m2)) << o.case_name;
    EXPECT_GT(o.heldout_before_w_m2, 0.0) << o.case_name;
  }
  // A same-form outcome as well: both tables, each with its confusion table
  // and hit rate.
  SelftestCase same = SelftestCases(plant).back();
  outcomes.push_back(RunSelftestCase(plant, same, 1, options));
  const std::string report = FormatSelftestBatteries(outcomes);
  const std::size_t same_at = report.find("=== same-form battery");
  const std::size_t other_at = report.find("=== other-form battery");
  ASSERT_NE(same_at, std::string::npos) << report;
  ASSERT_NE(other_at, std::string::npos) << report;
  EXPECT_LT(same_at, other_at);
  EXPECT_NE(report.find("confusion", other_at), std::string::npos);
  EXPECT_NE(report.find("hit rate:", other_at), std::string::npos);
  for (const char* name : {"pv_clipping", "null", "snow_cover"}) {
    EXPECT_NE(report.find(name, other_at), std::string::npos) << name;
  }
  std::cout << report;
}

}  // namespace
}  // namespace pvtwin
