// The synthetic truth model of the gap diagnosis (core/synth/synthetic_plant.h):
// effects switched on by variant name, the paper's data defects and the
// uncatalogued disturbances, each checked for what it must do to the data.
#include <gtest/gtest.h>

#include <cmath>

#include "core/data/qc.h"
#include "core/effects/effects.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

SyntheticOptions Options(const std::string& variant, int days, std::uint64_t seed) {
  SyntheticOptions o;
  std::string error;
  EXPECT_TRUE(DefaultSyntheticOptions(DesignExamplePlant(), variant, days, seed, &o, &error))
      << error;
  return o;
}

double Sum(const Series& s, Channel c, std::int64_t from_s, std::int64_t to_s) {
  double sum = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double v = s[c][i];
    if (s.time_s[i] >= from_s && s.time_s[i] < to_s && std::isfinite(v)) sum += v;
  }
  return sum;
}

TEST(SyntheticTruth, TruthParamsCarryTheTypicalMagnitudeOfEachEffect) {
  const Plant plant = DesignExamplePlant();
  const ParamVector p = TruthParamsFor(plant, testing::SpecOf("1N1Cwr+pv_clipping+soiling"));
  EXPECT_EQ(p[static_cast<std::size_t>(Param::kPLimitWM2)], 120.0);
  EXPECT_EQ(p[static_cast<std::size_t>(Param::kSoilingPerDay)], 0.004);
  // Effects the spec lacks keep the reference values.
  EXPECT_EQ(p[static_cast<std::size_t>(Param::kR0FluidM2KW)],
            ReferenceTruthParams(plant)[static_cast<std::size_t>(Param::kR0FluidM2KW)]);
  SyntheticOptions o;
  std::string error;
  EXPECT_FALSE(DefaultSyntheticOptions(plant, "1N+dust", 3, 1, &o, &error));
  EXPECT_NE(error.find("unknown effect 'dust'"), std::string::npos) << error;
}

// The old entry point is the new one without defects or disturbances.
TEST(SyntheticTruth, OldSignatureIsTheDefectFreeCase) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions o = Options("2N1Ccolwr", 2, 21);
  o.defects = DataDefects{};
  const Series a = MakeSyntheticPlantData(plant, o);
  const Series b = MakeSyntheticPlantData(plant, o.weather, o.truth_spec, o.truth, o.noise);
  ASSERT_EQ(a.size(), b.size());
  for (Channel c : {Channel::kPElW, Channel::kQThW, Channel::kTOutC, Channel::kGPoaWM2}) {
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[c][i], b[c][i]);
  }
}

// The defects are those the paper's corrections know, in the stated numbers.
TEST(SyntheticTruth, DataDefectsAreThePapersAndQcCorrectsThem) {
  const SyntheticOptions o = Options("1N1Cwr", 4, 22);
  Series s = MakeSyntheticPlantData(DesignExamplePlant(), o);
  int glitches = 0, negative = 0, invalid = 0, dropouts = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    glitches += s[Channel::kGPoaWM2][i] > kIrradianceGlitchWM2;
    negative += s[Channel::kMdotKgS][i] < 0.0;
    invalid += s[Channel::kValid][i] == 0.0;
    dropouts += std::isnan(s[Channel::kTOutC][i]);
  }
  EXPECT_EQ(glitches, o.defects.irradiance_glitches);
  EXPECT_GT(negative, 1000);  // every row with the pump at rest
  EXPECT_GE(invalid, 30);
  EXPECT_LE(invalid, 30 * o.defects.invalid_blocks);
  EXPECT_GE(dropouts, 10);
  const QcCorrections fixed = ApplyPaperCorrections(&s);
  EXPECT_EQ(fixed.irradiance_zeroed, static_cast<std::size_t>(glitches));
  EXPECT_EQ(fixed.flow_zeroed, static_cast<std::size_t>(negative));
  EXPECT_EQ(fixed.flow_rejected, 0u);
}

// Operation like a real plant: the pump starts and stops every day, the flow
// varies while it runs, the inlet drifts with the tank, days differ.
TEST(SyntheticTruth, OperationHasPumpCyclesVariableFlowAndDriftingInlet) {
  const SyntheticOptions o = Options("1N1Cwr", 7, 23);
  const Series s = MakeSyntheticPlantData(DesignExamplePlant(), o);
  int starts = 0;
  double flow_min = 1e9, flow_max = 0.0, t_in_min = 1e9, t_in_max = -1e9;
  for (std::size_t i = 1; i < s.size(); ++i) {
    const double f = s[Channel::kMdotKgS][i];
    starts += f > 0.0 && !(s[Channel::kMdotKgS][i - 1] > 0.0);
    if (f > 0.0) {
      flow_min = std::min(flow_min, f);
      flow_max = std::max(flow_max, f);
    }
    t_in_min = std::min(t_in_min, s[Channel::kTInC][i]);
    t_in_max = std::max(t_in_max, s[Channel::kTInC][i]);
  }
  EXPECT_GE(starts, 7);
  EXPECT_GT(flow_max / flow_min, 2.0);
  EXPECT_GT(t_in_max - t_in_min, 5.0);
  const auto types = DayTypesFor(o.weather);
  EXPECT_NE(std::count(types.begin(), types.end(), types[0]), static_cast<long>(types.size()));
}

// Uncatalogued disturbances do what their names say on their days only.
TEST(SyntheticTruth, DisturbancesActOnTheirDaysOnly) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions clean = Options("1N1Cwr", 4, 24);
  clean.defects = DataDefects{};
  const Series base = MakeSyntheticPlantData(plant, clean);
  const std::int64_t day1 = base.time_s[0] + 86400;
  const std::int64_t day2 = day1 + 86400;
  for (DisturbanceKind kind : {DisturbanceKind::kFailingPump, DisturbanceKind::kStuckFlowReading,
                               DisturbanceKind::kSnowCover}) {
    SyntheticOptions o = clean;
    o.disturbances = {{kind, day1, day2, kind == DisturbanceKind::kFailingPump ? 0.3 : 0.0}};
    const Series s = MakeSyntheticPlantData(plant, o);
    const std::string name(DisturbanceName(kind));
    // Readings of weather and flow are untouched everywhere.
    for (std::size_t i = 0; i < s.size(); ++i) {
      ASSERT_EQ(s[Channel::kMdotKgS][i], base[Channel::kMdotKgS][i]) << name;
      ASSERT_EQ(s[Channel::kGPoaWM2][i], base[Channel::kGPoaWM2][i]) << name;
    }
    // Other days are unchanged (day 0, before the disturbance).
    EXPECT_EQ(Sum(s, Channel::kPElW, base.time_s[0], day1),
              Sum(base, Channel::kPElW, base.time_s[0], day1))
        << name;
    const double p_ratio =
        Sum(s, Channel::kPElW, day1, day2) / Sum(base, Channel::kPElW, day1, day2);
    const double q_ratio =
        Sum(s, Channel::kQThW, day1, day2) / Sum(base, Channel::kQThW, day1, day2);
    switch (kind) {
      case DisturbanceKind::kFailingPump:
        // 30 % of the flow: hotter collector, the heat meter over-reads.
        EXPECT_LT(p_ratio, 1.0) << name;
        EXPECT_GT(q_ratio, 1.3) << name;
        break;
      case DisturbanceKind::kStuckFlowReading:
        EXPECT_LT(p_ratio, 1.0) << name;  // stagnation: hot cells
        EXPECT_GT(q_ratio, 2.0) << name;  // reading × stagnation temperature rise
        break;
      case DisturbanceKind::kSnowCover:
        EXPECT_LT(p_ratio, 0.01) << name;
        EXPECT_LT(q_ratio, 0.05) << name;
        break;
      case DisturbanceKind::kInletSensorOffset:
      case DisturbanceKind::kOutletSensorOffset:
      case DisturbanceKind::kFlowMeterScale:
        break;  // sensor faults: their own tests below
    }
  }
}

// An inlet sensor offset is a reading: the logged t_in_c is high by the
// offset from its first day on, the heat meter reads ṁ·c_p·ΔT less while
// the pump runs, and P_el, the flow and the outlet are untouched.
TEST(SyntheticTruth, InletSensorOffsetIsAReadingFromItsDayOn) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions clean = Options("1N1Cwr", 4, 24);
  clean.defects = DataDefects{};
  const Series base = MakeSyntheticPlantData(plant, clean);
  const std::int64_t day2 = base.time_s[0] + 2 * 86400;
  SyntheticOptions o = clean;
  o.disturbances = {{DisturbanceKind::kInletSensorOffset, day2, base.time_s.back() + 1, 1.5}};
  const Series s = MakeSyntheticPlantData(plant, o);
  int flowing = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    ASSERT_EQ(s[Channel::kPElW][i], base[Channel::kPElW][i]);
    ASSERT_EQ(s[Channel::kTOutC][i], base[Channel::kTOutC][i]);
    const double dt = s[Channel::kTInC][i] - base[Channel::kTInC][i];
    const double dq = s[Channel::kQThW][i] - base[Channel::kQThW][i];
    if (s.time_s[i] < day2) {
      ASSERT_EQ(dt, 0.0);
      ASSERT_EQ(dq, 0.0);
      continue;
    }
    ASSERT_NEAR(dt, 1.5, 1e-9);
    const double flow = s[Channel::kMdotKgS][i];
    if (flow > 0.0) ++flowing;
    ASSERT_NEAR(dq, flow > 0.0 ? -flow * plant.fluid_cp_j_kgk * 1.5 : 0.0, 1e-6);
  }
  EXPECT_GT(flowing, 100);
}

// A logged outlet offset moves t_out_c only (the heat meter has its own
// pair); a flow meter scale moves the flow reading and the heat meter's
// q_th_w by the factor. Both from their first day on; the physics is untouched.
TEST(SyntheticTruth, OutletOffsetAndFlowScaleAreReadingsFromTheirDayOn) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions clean = Options("1N1Cwr", 4, 24);
  clean.defects = DataDefects{};
  const Series base = MakeSyntheticPlantData(plant, clean);
  const std::int64_t day2 = base.time_s[0] + 2 * 86400;
  SyntheticOptions o = clean;
  o.disturbances = {{DisturbanceKind::kOutletSensorOffset, day2, base.time_s.back() + 1, -0.8},
                    {DisturbanceKind::kFlowMeterScale, day2, base.time_s.back() + 1, 1.1}};
  const Series s = MakeSyntheticPlantData(plant, o);
  int flowing = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    ASSERT_EQ(s[Channel::kPElW][i], base[Channel::kPElW][i]);
    ASSERT_EQ(s[Channel::kTInC][i], base[Channel::kTInC][i]);
    const bool on = s.time_s[i] >= day2;
    ASSERT_NEAR(s[Channel::kTOutC][i] - base[Channel::kTOutC][i], on ? -0.8 : 0.0, 1e-9);
    ASSERT_NEAR(s[Channel::kMdotKgS][i], base[Channel::kMdotKgS][i] * (on ? 1.1 : 1.0), 1e-12);
    ASSERT_NEAR(s[Channel::kQThW][i], base[Channel::kQThW][i] * (on ? 1.1 : 1.0), 1e-9);
    flowing += on && base[Channel::kQThW][i] > 100.0;
  }
  EXPECT_GT(flowing, 100);
}

// irradiance_bias is a sensor error: the plane-of-array reading is scaled,
// the physics is not.
TEST(SyntheticTruth, IrradianceBiasScalesOnlyThePyranometer) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions with = Options("1N1Cwr+irradiance_bias", 2, 25);
  SyntheticOptions without = with;
  without.truth_spec = testing::SpecOf("1N1Cwr");
  with.defects = without.defects = DataDefects{};
  const Series a = MakeSyntheticPlantData(plant, with);
  const Series b = MakeSyntheticPlantData(plant, without);
  const double k = with.truth[static_cast<std::size_t>(Param::kIrradianceBias)];
  EXPECT_EQ(k, 0.06);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[Channel::kPElW][i], b[Channel::kPElW][i]);
    ASSERT_EQ(a[Channel::kGhiWM2][i], b[Channel::kGhiWM2][i]);
    ASSERT_NEAR(a[Channel::kGPoaWM2][i] * (1.0 + k), b[Channel::kGPoaWM2][i], 1e-9);
  }
}

}  // namespace
}  // namespace pvtwin
