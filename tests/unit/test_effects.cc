// The effect library's catalogue: names, variant grammar, WithEffect and
// CanAddEffect (core/effects/effects.h).
#include <gtest/gtest.h>

#include <cmath>

#include "core/effects/effects.h"
#include "core/effects/irradiance_bias.h"
#include "core/model/thermal_model.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/effect_named.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

TEST(EffectVariants, EveryEffectParsesAndPrintsOnEveryBase) {
  for (const char* base : {"1N", "1N1Cwr", "2Nwr", "2N1Ccolwr"}) {
    for (const EffectModule* effect : EffectRegistry()) {
      const EffectModule& info = *effect;
      const ModelSpec spec = testing::SpecOf(base);
      std::string why;
      if (!CanAddEffect(spec, info, &why)) {
        EXPECT_FALSE(why.empty());
        continue;
      }
      const ModelSpec with = WithEffect(spec, info);
      EXPECT_TRUE(HasEffect(with, info)) << base << " + " << info.name;
      EXPECT_FALSE(HasEffect(spec, info) && &info != &testing::EffectNamed("capacitance"));
      // The "+name" spelling parses to the same model (wind: "+wind" is the
      // physical form, WithEffect adds the paper's 'w'), and Name() round-trips.
      ModelSpec parsed;
      std::string error;
      ASSERT_TRUE(ParseVariant(std::string(base) + "+" + std::string(info.name), &parsed, &error))
          << error;
      EXPECT_TRUE(HasEffect(parsed, info));
      if (&info != &testing::EffectNamed("wind")) {
        EXPECT_EQ(parsed.Name(), with.Name());
      }
      ModelSpec again;
      ASSERT_TRUE(ParseVariant(with.Name(), &again, &error)) << error;
      EXPECT_EQ(again.Name(), with.Name());
    }
  }
}

TEST(EffectVariants, BaseLetterEffectsMapToTheTable6Grammar) {
  auto with = [](const char* base, const EffectModule& e) {
    return WithEffect(testing::SpecOf(base), e).Name();
  };
  EXPECT_EQ(with("1N", testing::EffectNamed("capacitance")), "1N1C");
  EXPECT_EQ(with("2Nwr", testing::EffectNamed("capacitance")), "2N1Ccolwr");
  EXPECT_EQ(with("2N1Ccolwr", testing::EffectNamed("capacitance")), "2N2Cwr");
  EXPECT_EQ(with("1N1Cwr", testing::EffectNamed("second_node")), "2N1Cpvwr");
  EXPECT_EQ(with("1N1C", testing::EffectNamed("wind")), "1N1Cw");
  EXPECT_EQ(with("1N1Cw", testing::EffectNamed("sky_radiation")), "1N1Cwr");
  EXPECT_EQ(with("2N1Ccolwr", testing::EffectNamed("iam")), "2N1CcolwrI");
  EXPECT_EQ(with("1N1Cwr", testing::EffectNamed("shading")), "1N1Cwr+shading");
  EXPECT_EQ(testing::SpecOf("1N1Cwr+shading+pv_clipping").Name(), "1N1Cwr+pv_clipping+shading");
}

TEST(EffectVariants, CannotAddWhatIsThereOrWhatTheDataCannotIdentify) {
  std::string why;
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("2N2Cwr"), testing::EffectNamed("capacitance"), &why));
  EXPECT_NE(why.find("already has a capacitance"), std::string::npos) << why;
  EXPECT_TRUE(
      CanAddEffect(testing::SpecOf("2N1Ccolwr"), testing::EffectNamed("capacitance"), &why));
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("1Nwr"), testing::EffectNamed("wind"), &why));
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("1N+wind"), testing::EffectNamed("wind"), &why));
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("1N+soiling"), testing::EffectNamed("soiling"), &why));
  EXPECT_NE(why.find("already has soiling"), std::string::npos) << why;

  Series poa_only = testing::MakeConstantSeries(10, 60.0, {});
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("1N1Cwr"), testing::EffectNamed("irradiance_bias"),
                            poa_only, &why));
  EXPECT_EQ(why, "not identifiable without a second irradiance source (ghi_w_m2 + dhi_w_m2)");
  Series both = poa_only;
  both.Ensure(Channel::kGhiWM2);
  both.Ensure(Channel::kDhiWM2);
  EXPECT_TRUE(
      CanAddEffect(testing::SpecOf("1N1Cwr"), testing::EffectNamed("irradiance_bias"), both, &why));
}

}  // namespace
}  // namespace pvtwin

namespace pvtwin {
namespace {

// Every signature is defined on the drivers of a base model without the
// effect (what the diagnosis has), with the sign its explanation implies.
TEST(EffectSignature, DefinedOnBaseDriversWithTheExpectedSign) {
  const Plant plant = DesignExamplePlant();
  SyntheticOptions o;
  std::string error;
  ASSERT_TRUE(DefaultSyntheticOptions(plant, "1N1Cwr", 2, 31, &o, &error)) << error;
  o.defects = DataDefects{};
  const Series s = MakeSyntheticPlantData(plant, o);
  Drivers d;
  ASSERT_TRUE(PrepareDrivers(s, plant, testing::SpecOf("1N"), &d, &error)) << error;
  SimOutputs base;
  Simulate(d, o.truth, &base);
  for (const EffectModule* effect : EffectRegistry()) {
    const EffectModule& info = *effect;
    const std::vector<double> sig = EffectSignature(info, d, base);
    ASSERT_EQ(sig.size(), d.size()) << info.name;
    std::size_t finite = 0;
    for (double v : sig) finite += std::isfinite(v);
    EXPECT_GT(finite, d.size() / 10) << info.name;
  }
  const auto at = [&](const EffectModule& e, std::size_t i) {
    return EffectSignature(e, d, base)[i];
  };
  for (std::size_t i = 1; i + 1 < d.size(); ++i) {
    EXPECT_DOUBLE_EQ(at(testing::EffectNamed("pv_clipping"), i), base.p_el_w[i] / plant.area_m2);
    EXPECT_DOUBLE_EQ(at(testing::EffectNamed("soiling"), i),
                     static_cast<double>(i) * 60.0 / 86400.0);
    if (i > 100) break;
  }
  // The sky is colder than the air on average; the generated data's two
  // irradiance sources agree (no bias).
  double deficit = 0.0;
  for (double v : EffectSignature(testing::EffectNamed("sky_radiation"), d, base)) deficit += v;
  EXPECT_GT(deficit, 0.0);
  EXPECT_NEAR(EstimateIrradianceBias(d), 0.0, 0.01);
}

}  // namespace
}  // namespace pvtwin
