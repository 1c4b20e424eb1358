// The effect library's catalogue: names, variant grammar, WithEffect and
// CanAddEffect (core/effects/effects.h).
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/effects/effects.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

TEST(EffectTable, EveryEffectOnceInEnumOrderWithExplanationAndKnownParams) {
  const auto& table = EffectTable();
  ASSERT_EQ(table.size(), kNumEffects);
  std::set<std::string_view> names;
  for (std::size_t i = 0; i < table.size(); ++i) {
    const EffectInfo& info = table[i];
    EXPECT_EQ(static_cast<std::size_t>(info.effect), i);
    EXPECT_TRUE(names.insert(info.name).second) << info.name;
    EXPECT_GT(info.explanation.size(), 100u) << info.name;
    EXPECT_FALSE(info.signature.empty()) << info.name;
    ASSERT_TRUE(EffectFromName(info.name).has_value()) << info.name;
    EXPECT_EQ(*EffectFromName(info.name), info.effect);
    for (const auto& [param, value] : info.typical_truth) {
      const ParamInfo& p = Info(param);
      EXPECT_GE(value, p.lower) << info.name << " " << p.name;
      EXPECT_LE(value, p.upper) << info.name << " " << p.name;
    }
  }
  // DESIGN.md's vocabulary, spelled as there.
  for (const char* name : {"capacitance", "second_node", "wind", "sky_radiation", "iam",
                           "flow_dependent_u", "transport_delay", "pv_clipping", "shading",
                           "soiling", "clock_offset", "irradiance_bias"}) {
    EXPECT_TRUE(names.count(name)) << name;
  }
  EXPECT_FALSE(EffectFromName("none").has_value());
}

TEST(EffectVariants, EveryEffectParsesAndPrintsOnEveryBase) {
  for (const char* base : {"1N", "1N1Cwr", "2Nwr", "2N1Ccolwr"}) {
    for (const EffectInfo& info : EffectTable()) {
      const ModelSpec spec = testing::SpecOf(base);
      std::string why;
      if (!CanAddEffect(spec, info.effect, &why)) {
        EXPECT_FALSE(why.empty());
        continue;
      }
      const ModelSpec with = WithEffect(spec, info.effect);
      EXPECT_TRUE(HasEffect(with, info.effect)) << base << " + " << info.name;
      EXPECT_FALSE(HasEffect(spec, info.effect) && info.effect != Effect::kCapacitance);
      // The "+name" spelling parses to the same model (wind: "+wind" is the
      // physical form, WithEffect adds the paper's 'w'), and Name() round-trips.
      ModelSpec parsed;
      std::string error;
      ASSERT_TRUE(ParseVariant(std::string(base) + "+" + std::string(info.name), &parsed, &error))
          << error;
      EXPECT_TRUE(HasEffect(parsed, info.effect));
      if (info.effect != Effect::kWind) {
        EXPECT_EQ(parsed.Name(), with.Name());
      }
      ModelSpec again;
      ASSERT_TRUE(ParseVariant(with.Name(), &again, &error)) << error;
      EXPECT_EQ(again.Name(), with.Name());
    }
  }
}

TEST(EffectVariants, BaseLetterEffectsMapToTheTable6Grammar) {
  auto with = [](const char* base, Effect e) {
    return WithEffect(testing::SpecOf(base), e).Name();
  };
  EXPECT_EQ(with("1N", Effect::kCapacitance), "1N1C");
  EXPECT_EQ(with("2Nwr", Effect::kCapacitance), "2N1Ccolwr");
  EXPECT_EQ(with("2N1Ccolwr", Effect::kCapacitance), "2N2Cwr");
  EXPECT_EQ(with("1N1Cwr", Effect::kSecondNode), "2N1Cpvwr");
  EXPECT_EQ(with("1N1C", Effect::kWind), "1N1Cw");
  EXPECT_EQ(with("1N1Cw", Effect::kSkyRadiation), "1N1Cwr");
  EXPECT_EQ(with("2N1Ccolwr", Effect::kIam), "2N1CcolwrI");
  EXPECT_EQ(with("1N1Cwr", Effect::kShading), "1N1Cwr+shading");
  EXPECT_EQ(testing::SpecOf("1N1Cwr+shading+pv_clipping").Name(), "1N1Cwr+pv_clipping+shading");
}

TEST(EffectVariants, CannotAddWhatIsThereOrWhatTheDataCannotIdentify) {
  std::string why;
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("2N2Cwr"), Effect::kCapacitance, &why));
  EXPECT_NE(why.find("already has a capacitance"), std::string::npos) << why;
  EXPECT_TRUE(CanAddEffect(testing::SpecOf("2N1Ccolwr"), Effect::kCapacitance, &why));
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("1Nwr"), Effect::kWind, &why));
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("1N+wind"), Effect::kWind, &why));
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("1N+soiling"), Effect::kSoiling, &why));
  EXPECT_NE(why.find("already has soiling"), std::string::npos) << why;

  Series poa_only = testing::MakeConstantSeries(10, 60.0, {});
  EXPECT_FALSE(CanAddEffect(testing::SpecOf("1N1Cwr"), Effect::kIrradianceBias, poa_only, &why));
  EXPECT_EQ(why, "not identifiable without a second irradiance source (ghi_w_m2 + dhi_w_m2)");
  Series both = poa_only;
  both.Ensure(Channel::kGhiWM2);
  both.Ensure(Channel::kDhiWM2);
  EXPECT_TRUE(CanAddEffect(testing::SpecOf("1N1Cwr"), Effect::kIrradianceBias, both, &why));
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
  for (const EffectInfo& info : EffectTable()) {
    const std::vector<double> sig = EffectSignature(info.effect, d, base);
    ASSERT_EQ(sig.size(), d.size()) << info.name;
    std::size_t finite = 0;
    for (double v : sig) finite += std::isfinite(v);
    EXPECT_GT(finite, d.size() / 10) << info.name;
  }
  const auto at = [&](Effect e, std::size_t i) { return EffectSignature(e, d, base)[i]; };
  for (std::size_t i = 1; i + 1 < d.size(); ++i) {
    EXPECT_DOUBLE_EQ(at(Effect::kPvClipping, i), base.p_el_w[i] / plant.area_m2);
    EXPECT_DOUBLE_EQ(at(Effect::kSoiling, i), static_cast<double>(i) * 60.0 / 86400.0);
    if (i > 100) break;
  }
  // The sky is colder than the air on average; the generated data's two
  // irradiance sources agree (no bias).
  double deficit = 0.0;
  for (double v : EffectSignature(Effect::kSkyRadiation, d, base)) deficit += v;
  EXPECT_GT(deficit, 0.0);
  EXPECT_NEAR(EstimateIrradianceBias(d), 0.0, 0.01);
}

}  // namespace
}  // namespace pvtwin
