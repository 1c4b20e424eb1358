// The forms the diagnosis fits for an effect (EffectModule::diagnosis_forms)
// and the broader candidate forms behind them: wind's physical "+wind"
// besides the paper's 'w', the sky's cloud offset beyond the logged
// long-wave, the IAM on the thermal absorption only besides both outputs,
// and the obstacle that stands on some days only; a diagnosis names the
// form on the output where the truth's IAM acts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/common/calendar.h"
#include "core/common/units.h"
#include "core/data/qc.h"
#include "core/diagnosis/diagnosis.h"
#include "core/effects/effects.h"
#include "core/effects/iam.h"
#include "core/effects/shading.h"
#include "core/effects/sky_radiation.h"
#include "core/model/thermal_model.h"
#include "core/model/variant.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/effect_named.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

std::vector<std::string> FormNames(const char* base, const char* effect) {
  std::vector<std::string> names;
  for (const NamedForm& f : DiagnosisForms(testing::SpecOf(base), testing::EffectNamed(effect))) {
    names.push_back(f.spec.Name());
  }
  return names;
}

TEST(DiagnosisForms, WindIsFittedInThePaperAndInThePhysicalForm) {
  EXPECT_EQ(FormNames("1N1Cr", "wind"), (std::vector<std::string>{"1N1Cwr", "1N1Cr+wind"}));
}

TEST(DiagnosisForms, SkyIsFittedWithAndWithoutTheCloudOffset) {
  EXPECT_EQ(FormNames("1N1Cw", "sky_radiation"),
            (std::vector<std::string>{"1N1Cwr", "1N1Cwr+sky_radiation"}));
  // The broader form's name parses back to it.
  EXPECT_EQ(testing::SpecOf("1N1Cwr+sky_radiation").Name(), "1N1Cwr+sky_radiation");
  EXPECT_TRUE(UsedParams(testing::SpecOf("1N1Cwr+sky_radiation"))
                  .test(static_cast<std::size_t>(Param::kSkyCloudOffset)));
  EXPECT_FALSE(
      UsedParams(testing::SpecOf("1N1Cwr")).test(static_cast<std::size_t>(Param::kSkyCloudOffset)));
}

std::vector<std::string> FormLabels(const char* base, const char* effect) {
  std::vector<std::string> labels;
  for (const NamedForm& f : DiagnosisForms(testing::SpecOf(base), testing::EffectNamed(effect))) {
    labels.push_back(f.form);
  }
  return labels;
}

TEST(DiagnosisForms, IamIsFittedAsThePaperWritesItAndWithAshraesB0Free) {
  EXPECT_EQ(FormNames("2N1Ccolwr", "iam"),
            (std::vector<std::string>{"2N1CcolwrI", "2N1CcolwrI+iam", "2N1CcolwrI+iam_thermal"}));
  EXPECT_EQ(FormLabels("2N1Ccolwr", "iam"),
            (std::vector<std::string>{"both_outputs", "both_outputs_fitted_b0", "thermal_only"}));
  EXPECT_EQ(testing::SpecOf("2N1CcolwrI+iam_thermal").Name(), "2N1CcolwrI+iam_thermal");
  EXPECT_EQ(testing::SpecOf("2N1CcolwrI+iam").Name(), "2N1CcolwrI+iam");
  EXPECT_EQ(testing::SpecOf("2N1Ccolwr+iam").Name(), "2N1CcolwrI");  // '+iam' adds 'I' first
  EXPECT_TRUE(UsedParams(testing::SpecOf("2N1CcolwrI+iam"))
                  .test(static_cast<std::size_t>(Param::kIamB0Fit)));
  EXPECT_FALSE(
      UsedParams(testing::SpecOf("2N1CcolwrI")).test(static_cast<std::size_t>(Param::kIamB0Fit)));
}

TEST(DiagnosisForms, TransportDelayIsAlsoFittedAsAPipeVolume) {
  EXPECT_EQ(FormNames("1N1Cwr", "transport_delay"),
            (std::vector<std::string>{"1N1Cwr+transport_delay", "1N1Cwr+pipe_volume"}));
  EXPECT_EQ(testing::SpecOf("1N1Cwr+pipe_volume").Name(), "1N1Cwr+pipe_volume");
  EXPECT_TRUE(
      HasEffect(testing::SpecOf("1N1Cwr+pipe_volume"), testing::EffectNamed("transport_delay")));
  // Two forms at one place of the name: the same canonical order whichever
  // is added first.
  EXPECT_EQ(testing::SpecOf("1N1Cwr+transport_delay+pipe_volume").Name(),
            testing::SpecOf("1N1Cwr+pipe_volume+transport_delay").Name());
}

// ASHRAE's modifier over the whole range, by hand: b0 = 0.05, K(60°) =
// 1 − 0.05·(2 − 1) = 0.95; K(80°) = 1 − 0.05·(5.758770 − 1) = 0.762061;
// at 88° 1/cos θ = 28.65 puts 1 − b0·e below 0: K = 0.
TEST(DiagnosisForms, AshraeIamByHand) {
  auto e = [](double deg) { return 1.0 / std::cos(deg * kPi / 180.0) - 1.0; };
  EXPECT_NEAR(IamAshraeFromExcess(e(60.0), 0.05), 0.95, 1e-12);
  EXPECT_NEAR(IamAshraeFromExcess(e(80.0), 0.05), 0.762061, 1e-6);
  EXPECT_EQ(IamAshraeFromExcess(e(88.0), 0.05), 0.0);
  EXPECT_EQ(IamAshraeFromExcess(std::numeric_limits<double>::infinity(), 0.05), 0.0);
  EXPECT_TRUE(std::isnan(IamAshraeFromExcess(std::nan(""), 0.05)));
}

TEST(DiagnosisForms, AnEffectWithOneFormHasOnlyIt) {
  EXPECT_EQ(FormNames("1N1Cwr", "shading"), (std::vector<std::string>{"1N1Cwr+shading"}));
  EXPECT_EQ(FormLabels("1N1Cwr", "shading"), (std::vector<std::string>{"standard"}));
  EXPECT_EQ(FormLabels("1N1Cwr", "transport_delay"),
            (std::vector<std::string>{"pure_delay", "pipe_with_mixing"}));
}

// "+iam_thermal": P_el = η(T_PV)·A·I_gt, as without the modifier: against
// the model without it, P_el / (1 + f_corr,T·(T_PV − T_PVref)) is the same
// on every row (only T_PV differs: the laminate absorbs I_at); with 'I'
// alone it is lower where the modifier acts. The heat follows I_at as with
// 'I'. Rows where the 'I' split leaves no absorbed irradiance are left out.
TEST(DiagnosisForms, IamOnTheThermalAbsorptionOnlyLeavesPelAtTheIrradianceBeforeIt) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions synth;
  std::string error;
  ASSERT_TRUE(DefaultSyntheticOptions(plant, "1N1Cwr", 2, 5, &synth, &error)) << error;
  const Series s = MakeSyntheticPlantData(plant, synth);
  const ParamVector p = TruthParamsFor(plant, testing::SpecOf("1N1CwrI"));
  auto run = [&](const char* variant) {
    Drivers d;
    std::string why;
    EXPECT_TRUE(PrepareDrivers(s, plant, testing::SpecOf(variant), &d, &why)) << why;
    SimOutputs out;
    Simulate(d, p, &out);
    return out;
  };
  const SimOutputs plain = run("1N1Cwr"), both = run("1N1CwrI");
  const SimOutputs thermal = run("1N1CwrI+iam_thermal");
  const double f_t = ParamOf(p, Param::kPvTempCoeffPerK);
  auto at_ref_temp = [&](const SimOutputs& o, std::size_t i) {
    return o.p_el_w[i] / (1.0 + f_t * (o.t_pv_c[i] - plant.pv_t_ref_c));
  };
  int rows = 0, lower_with_i = 0;
  double q_gap = 0.0, q_scale = 0.0;
  for (std::size_t i = 0; i < plain.p_el_w.size(); ++i) {
    if (!std::isfinite(thermal.p_el_w[i]) || !(both.p_el_w[i] > 1.0)) continue;
    ++rows;
    EXPECT_NEAR(at_ref_temp(thermal, i), at_ref_temp(plain, i), 1e-9 * at_ref_temp(plain, i))
        << "row " << i;
    lower_with_i += at_ref_temp(both, i) < at_ref_temp(plain, i) - 1e-6 ? 1 : 0;
    q_gap += std::fabs(thermal.q_th_w[i] - both.q_th_w[i]);
    q_scale += std::fabs(both.q_th_w[i] - plain.q_th_w[i]);
  }
  ASSERT_GT(rows, 500);
  EXPECT_GT(lower_with_i, rows / 2);
  // The heat: much nearer to 'I' than to no modifier (it differs from 'I'
  // by the electricity the laminate no longer loses to the modifier).
  EXPECT_LT(q_gap, 0.3 * q_scale);
}

// A plant whose IAM acts where the truth puts it: the diagnosis names iam,
// with the form on that output. 14 + 7 days at 1 min, base 1N1Cwr, the
// paper's b0; a competitor that any thermal gap could take (second_node).
DiagnosisResult DiagnoseIamTruth(const char* truth_variant) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions synth;
  std::string error;
  EXPECT_TRUE(DefaultSyntheticOptions(plant, truth_variant, 21, 2, &synth, &error)) << error;
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  synth.weather.start_time_s =
      SolarDayStartS(synth.weather.start_time_s, offset_s) + kSecondsPerDay;
  Series s = MakeSyntheticPlantData(plant, synth);
  ApplyPaperCorrections(&s);
  DiagnosisOptions o;
  o.train_days = 14;
  o.heldout_days = 7;
  o.effects = {"iam", "second_node"};
  o.max_ladder_steps = 1;
  DiagnosisResult r;
  EXPECT_TRUE(Diagnose(s, plant, testing::SpecOf("1N1Cwr"), o, &r, &error)) << error;
  return r;
}

const EffectTrial* TrialNamed(const DiagnosisResult& r, const std::string& name) {
  for (const EffectTrial& t : r.effects) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

TEST(DiagnosisForms, IamOnTheThermalAbsorptionOnlyIsNamedWithThatForm) {
  const DiagnosisResult r = DiagnoseIamTruth("1N1CwrI+iam_thermal");
  EXPECT_EQ(r.verdict, "iam") << r.verdict_sentence;
  const EffectTrial* t = TrialNamed(r, "iam");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->form, "thermal_only") << t->evidence;
  EXPECT_EQ(t->forms.size(), 3u);
  EXPECT_NE(t->evidence.find("form " + t->form), std::string::npos) << t->evidence;
}

TEST(DiagnosisForms, IamOnBothOutputsIsNamedWithThatForm) {
  const DiagnosisResult r = DiagnoseIamTruth("1N1CwrI");
  EXPECT_EQ(r.verdict, "iam") << r.verdict_sentence;
  const EffectTrial* t = TrialNamed(r, "iam");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->form.rfind("both_outputs", 0), 0u) << t->form << ": " << t->evidence;
}

TEST(DiagnosisForms, SkyCloudOffsetByHand) {
  const double t_sky_k = 270.0, t_amb_k = 290.0;
  const double t4 = std::pow(t_sky_k, 4);
  EXPECT_DOUBLE_EQ(SkyK4WithCloudOffset(t4, t_amb_k, 0.0), t4);
  // Δc = 0.1: a tenth of the way from the sky to the air,
  // 270⁴ + 0.1·(290⁴ − 270⁴) = 5.31441e9 + 0.1·1.75840e9 K⁴.
  EXPECT_NEAR(SkyK4WithCloudOffset(t4, t_amb_k, 0.1), 5.31441e9 + 1.75840e8, 1e4);
  // Δc = 1: the sky at air temperature.
  EXPECT_NEAR(SkyK4WithCloudOffset(t4, t_amb_k, 1.0), std::pow(t_amb_k, 4), 1e-3);
  // Floored at 0 for a sky far clearer than logged.
  EXPECT_DOUBLE_EQ(SkyK4WithCloudOffset(t4, t_amb_k, -5.0), 0.0);
}

TEST(DiagnosisForms, ObstacleDayFromTheMeasuredYieldDeficit) {
  // Rows fully shaded (s = 1) with 80 % beam, no mismatch: modelled deficit
  // 0.8 a row.
  ObstacleDayEvidence shaded, clear, undecided;
  for (int i = 0; i < 10; ++i) {
    shaded.Add(0.25, 1.0, 0.8, 0.0);  // measured deficit 0.75
    clear.Add(0.97, 1.0, 0.8, 0.0);   // 0.03: no obstacle that day
  }
  EXPECT_EQ(shaded.BeamVerdict(), 1);
  EXPECT_EQ(clear.BeamVerdict(), -1);
  // Rows the fitted obstacle does not reach (s < 0.5) or without a yield do
  // not count; fewer than 3 rows give no verdict.
  undecided.Add(0.97, 0.2, 0.8, 0.0);
  undecided.Add(std::nan(""), 1.0, 0.8, 0.0);
  undecided.Add(0.97, 1.0, 0.8, 0.0);
  EXPECT_EQ(undecided.rows, 1);
  EXPECT_EQ(undecided.BeamVerdict(), 0);
}

// A day without a beam verdict from its diffuse-lit yield Y against the
// obstacle-free days' median: the obstacle hides f_d = 5 % of the sky.
TEST(DiagnosisForms, ObstacleDayWithoutBeamFromItsDiffuseLitYield) {
  constexpr double kShare = 0.05;
  auto day = [](int verdict, double diffuse_yield) {
    ObstacleDayEvidence e;
    for (int i = 0; i < 10 && verdict != 0; ++i) e.Add(verdict > 0 ? 0.2 : 0.98, 1.0, 0.8, 0.0);
    e.diffuse_yield = diffuse_yield;
    return e;
  };
  const double nan = std::nan("");
  // Free days at Y = 0.30, 0.31 and 0.29 (median 0.30), two shaded days.
  std::vector<ObstacleDayEvidence> days = {day(-1, 0.30), day(-1, 0.31), day(-1, 0.29), day(1, nan),
                                           day(1, nan)};
  days.push_back(day(0, 0.30 * (1.0 - kShare)));        // D = f_d: stands
  days.push_back(day(0, 0.30 * (1.0 - 0.4 * kShare)));  // nearer 0 than f_d: free
  days.push_back(day(0, 0.30 * (1.0 - 0.6 * kShare)));  // nearer f_d: stands
  days.push_back(day(0, 0.30 * (1.0 - 1.4 * kShare)));  // still the obstacle's
  days.push_back(day(0, 0.02));  // snow: not the obstacle, the majority (3 free : 2)
  days.push_back(day(0, nan));   // no yield: the majority
  const std::vector<std::uint8_t> stands = ObstacleDays(days, kShare);
  EXPECT_EQ(stands, (std::vector<std::uint8_t>{0, 0, 0, 1, 1, 1, 0, 1, 1, 0, 0}));
  // An obstacle whose beam shows it on every day judged stands on every other
  // day too, whatever the yield: there is no free day to compare with.
  const std::vector<std::uint8_t> always =
      ObstacleDays({day(1, 0.28), day(1, 0.27), day(0, 0.30), day(0, 0.10), day(0, nan)}, kShare);
  EXPECT_EQ(always, (std::vector<std::uint8_t>{1, 1, 1, 1, 1}));
}

TEST(DiagnosisForms, DiffuseLitYieldIsTheDaysRatioOfSumsOnRowsWithoutMuchBeam) {
  std::vector<std::int64_t> time_s;
  std::vector<double> p_el, g_poa, beam, elevation;
  for (int i = 0; i < 40; ++i) {
    time_s.push_back(1'700'000'000 + 60 * i);
    elevation.push_back(0.3);
    g_poa.push_back(i < 20 ? 150.0 : 600.0);
    beam.push_back(i < 20 ? 30.0 : 500.0);  // the last 20 rows are beam-lit
    p_el.push_back(i < 20 ? 30.0 + (i % 2) * 6.0 : 100.0);
  }
  // Σ P_el / Σ I_gt over the 20 diffuse-lit rows: 660 / 3000.
  const std::vector<double> y = ShadingDiffuseYield(time_s, p_el, g_poa, beam, elevation, 0);
  EXPECT_NEAR(y[0], 0.22, 1e-12);
  EXPECT_NEAR(y[39], 0.22, 1e-12);  // the day's value on every row
  // Fewer than 10 diffuse-lit rows: none.
  for (int i = 9; i < 20; ++i) beam[static_cast<std::size_t>(i)] = 100.0;
  EXPECT_TRUE(std::isnan(ShadingDiffuseYield(time_s, p_el, g_poa, beam, elevation, 0)[0]));
}

TEST(DiagnosisForms, RelativeYieldIsOneForAConstantYieldAndDropsUnderTheObstacle) {
  std::vector<std::int64_t> time_s;
  std::vector<double> p_el, g_poa, elevation;
  for (int i = 0; i < 60; ++i) {
    time_s.push_back(1'700'000'000 + 60 * i);
    g_poa.push_back(600.0);
    elevation.push_back(0.5);
    p_el.push_back(i < 50 ? 90.0 : 45.0);  // the last 10 rows lose half
  }
  const std::vector<double> y = ShadingRelativeYield(time_s, p_el, g_poa, elevation, 0);
  EXPECT_NEAR(y[0], 1.0, 1e-12);
  EXPECT_NEAR(y[55], 0.5, 1e-12);
  // Night rows have none.
  elevation[3] = -0.1;
  EXPECT_TRUE(std::isnan(ShadingRelativeYield(time_s, p_el, g_poa, elevation, 0)[3]));
}

}  // namespace
}  // namespace pvtwin
