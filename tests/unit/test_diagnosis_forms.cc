// The forms the diagnosis fits for an effect (EffectModule::diagnosis_forms)
// and the broader candidate forms behind them: wind's physical "+wind"
// besides the paper's 'w', the sky's cloud offset beyond the logged
// long-wave, and the obstacle that stands on some days only.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/common/units.h"
#include "core/effects/effects.h"
#include "core/effects/iam.h"
#include "core/effects/shading.h"
#include "core/effects/sky_radiation.h"
#include "core/model/variant.h"
#include "tests/support/effect_named.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

std::vector<std::string> FormNames(const char* base, const char* effect) {
  std::vector<std::string> names;
  for (const ModelSpec& s : DiagnosisForms(testing::SpecOf(base), testing::EffectNamed(effect))) {
    names.push_back(s.Name());
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

TEST(DiagnosisForms, IamIsFittedAsThePaperWritesItAndWithAshraesB0Free) {
  EXPECT_EQ(FormNames("2N1Ccolwr", "iam"),
            (std::vector<std::string>{"2N1CcolwrI", "2N1CcolwrI+iam"}));
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
  EXPECT_TRUE(shaded.Present());
  EXPECT_FALSE(clear.Present());
  // Rows the fitted obstacle does not reach (s < 0.5) or without a yield do
  // not count; fewer than 3 rows keep the obstacle.
  undecided.Add(0.97, 0.2, 0.8, 0.0);
  undecided.Add(std::nan(""), 1.0, 0.8, 0.0);
  undecided.Add(0.97, 1.0, 0.8, 0.0);
  EXPECT_EQ(undecided.rows, 1);
  EXPECT_TRUE(undecided.Present());
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
