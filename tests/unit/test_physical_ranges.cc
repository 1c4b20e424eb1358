// The physical range of every parameter (core/common/physical_ranges.h) and
// the diagnosis's re-fit in it (IdentifyInRanges): a synthetic plant whose
// long-wave emittance lies outside the paper's Table 3 range ends the
// Table 3 fit at its bound; the re-fit in the physical range finds it.
#include <gtest/gtest.h>

#include <cmath>

#include "core/common/physical_ranges.h"
#include "core/data/qc.h"
#include "core/diagnosis/stages.h"
#include "core/synth/synthetic_plant.h"

namespace pvtwin {
namespace {

// Every parameter: a source, and a widened range that holds Table 3's. The
// emittance reaches a glass front's 0.84-0.94 (Table 3 stops at 0.225).
TEST(PhysicalRanges, EveryParameterHasASourceAndNoNarrowerRangeThanTable3) {
  const Plant plant = DesignExamplePlant();
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const auto p = static_cast<Param>(i);
    const PhysicalRange range = PhysicalRangeOf(p, plant);
    const ParamInfo table = ResolvedInfo(p, plant);
    const ParamInfo wide = WidenedInfo(p, plant);
    EXPECT_FALSE(range.source.empty()) << Info(p).name;
    EXPECT_LE(range.lower, range.upper) << Info(p).name;
    EXPECT_LE(wide.lower, table.lower) << Info(p).name;
    EXPECT_GE(wide.upper, table.upper) << Info(p).name;
    if (Info(p).scale == ParamScale::kLog) {
      EXPECT_GT(wide.lower, 0.0) << Info(p).name;
    }
  }
  EXPECT_GE(PhysicalRangeOf(Param::kEpsPvt, plant).upper, 0.94);
  EXPECT_GT(WidenedInfo(Param::kEpsPvt, plant).upper, ResolvedInfo(Param::kEpsPvt, plant).upper);
}

// 1N1Cr on four synthetic days whose truth has ε_PVT = 0.6, far above Table
// 3's 0.075-0.225. Without the re-fit ε ends at 0.225; with it ε is
// re-fitted in the physical range, ends near the truth, and the training
// cost falls.
TEST(PhysicalRanges, TheRefitFindsAnEmittanceOutsideTable3) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions synth;
  std::string error;
  ASSERT_TRUE(DefaultSyntheticOptions(plant, "1N1Cr", 4, 3, &synth, &error)) << error;
  constexpr double kTrueEps = 0.6;
  synth.truth[static_cast<std::size_t>(Param::kEpsPvt)] = kTrueEps;
  Series s = MakeSyntheticPlantData(plant, synth);
  ApplyPaperCorrections(&s);
  ModelSpec spec;
  ASSERT_TRUE(ParseVariant("1N1Cr", &spec, &error)) << error;
  Drivers d;
  ASSERT_TRUE(PrepareDrivers(s, plant, spec, &d, &error)) << error;
  const Measurements m = MakeMeasurements(s, d);
  DiagnosisOptions options;
  options.refit_in_physical_ranges = false;
  const diagnosis_stages::RangedFit table =
      diagnosis_stages::IdentifyInRanges(d, m, StartParams(plant), options);
  ASSERT_TRUE(table.fit.ok) << table.fit.failure_reason;
  EXPECT_TRUE(table.refitted.empty());
  EXPECT_NEAR(ParamOf(table.fit.params, Param::kEpsPvt), 0.225, 1e-3);

  options.refit_in_physical_ranges = true;
  const diagnosis_stages::RangedFit wide =
      diagnosis_stages::IdentifyInRanges(d, m, StartParams(plant), options);
  ASSERT_TRUE(wide.fit.ok) << wide.fit.failure_reason;
  ASSERT_FALSE(wide.refitted.empty());
  const RefittedParam* eps = nullptr;
  for (const RefittedParam& r : wide.refitted) {
    if (r.param == Param::kEpsPvt) eps = &r;
  }
  ASSERT_NE(eps, nullptr);
  EXPECT_TRUE(eps->used);
  EXPECT_NEAR(eps->table_bound, 0.225, 1e-12);
  EXPECT_NEAR(eps->value, kTrueEps, 0.15);
  EXPECT_DOUBLE_EQ(ParamOf(wide.fit.params, Param::kEpsPvt), eps->value);
  EXPECT_LT(wide.fit.final_cost_w_m2, table.fit.final_cost_w_m2);
  EXPECT_NE(RefittedSentence(*eps).find("ε_PVT at its Table 3 bound 0.225"), std::string::npos)
      << RefittedSentence(*eps);
}

}  // namespace
}  // namespace pvtwin
