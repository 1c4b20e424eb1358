#include <gtest/gtest.h>

#include "core/effects/effects.h"
#include "core/model/variant.h"
#include "tests/support/effect_named.h"

namespace pvtwin {
namespace {

TEST(Variant, PaperVariantsParseAndRoundTrip) {
  for (const std::string& name : PaperVariants()) {
    ModelSpec spec;
    std::string error;
    ASSERT_TRUE(ParseVariant(name, &spec, &error)) << name << ": " << error;
    EXPECT_EQ(spec.Name(), name);
  }
}

TEST(Variant, LettersMapToStructure) {
  ModelSpec s;
  std::string e;
  ASSERT_TRUE(ParseVariant("2N1Ccolwr", &s, &e));
  EXPECT_EQ(s.nodes, 2);
  EXPECT_FALSE(s.c_pv);
  EXPECT_TRUE(s.c_coll);
  EXPECT_TRUE(s.wind_paper);
  EXPECT_TRUE(s.sky);
  EXPECT_FALSE(s.iam);
  ASSERT_TRUE(ParseVariant("1N1C", &s, &e));
  EXPECT_EQ(s.nodes, 1);
  EXPECT_TRUE(s.c_pv);
  EXPECT_FALSE(s.wind_paper || s.sky || s.iam);
  ASSERT_TRUE(ParseVariant("2N2CwrI", &s, &e));
  EXPECT_TRUE(s.c_pv && s.c_coll && s.iam);
}

TEST(Variant, GrammarCoversCombinationsBeyondTheTable) {
  ModelSpec s;
  std::string e;
  ASSERT_TRUE(ParseVariant("2N1Ccolr", &s, &e)) << e;
  EXPECT_FALSE(s.wind_paper);
  EXPECT_TRUE(s.sky);
  ASSERT_TRUE(ParseVariant("1N1Cwr+transport_delay", &s, &e)) << e;
  EXPECT_TRUE(HasEffect(s, testing::EffectNamed("transport_delay")));
  EXPECT_EQ(s.Name(), "1N1Cwr+transport_delay");
  ASSERT_TRUE(ParseVariant("1N1C+sky_radiation+wind", &s, &e)) << e;
  EXPECT_EQ(s.Name(), "1N1Cr+wind");
}

TEST(Variant, BadNamesSayWhy) {
  struct Case {
    const char* name;
    const char* expected;
  };
  for (const Case& c : {Case{"3N", "starts with 1N or 2N"}, Case{"2N1Cwr", "1Cpv or 1Ccol"},
                        Case{"1N2C", "unexpected '2C'"}, Case{"1Nwr+foo", "unknown effect 'foo'"},
                        Case{"1Nwr+wind", "exclude each other"}, Case{"1N+", "empty effect"},
                        Case{"2N1Ccolrw", "unexpected 'w'"}}) {
    ModelSpec s;
    std::string error;
    EXPECT_FALSE(ParseVariant(c.name, &s, &error)) << c.name;
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.name << ": " << error;
  }
}

TEST(Variant, UsedParamsFollowTheStructure) {
  auto used = [](const char* name, Param p) {
    ModelSpec s;
    std::string e;
    EXPECT_TRUE(ParseVariant(name, &s, &e));
    return UsedParams(s).test(static_cast<std::size_t>(p));
  };
  EXPECT_FALSE(used("1N", Param::kUCollWM2K));
  EXPECT_FALSE(used("1N", Param::kCPvJM2K));
  EXPECT_FALSE(used("1N", Param::kEpsPvt));
  EXPECT_FALSE(used("1N", Param::kRRefWind));
  EXPECT_TRUE(used("1N1C", Param::kCPvJM2K));
  EXPECT_TRUE(used("2Nwr", Param::kUCollWM2K));
  EXPECT_TRUE(used("2Nwr", Param::kEpsPvt));
  EXPECT_TRUE(used("2Nwr", Param::kNWind));
  EXPECT_FALSE(used("2N1Ccolwr", Param::kCPvJM2K));
  EXPECT_TRUE(used("2N1Ccolwr", Param::kCCollJM2K));
  EXPECT_TRUE(used("2N2Cwr", Param::kCPvJM2K));
  EXPECT_TRUE(used("1N1Cr+wind", Param::kUWindWM2K));
  EXPECT_FALSE(used("1N1Cr+wind", Param::kRRefWind));
  EXPECT_TRUE(used("1N1Cwr+transport_delay", Param::kTransportDelayS));
}

}  // namespace
}  // namespace pvtwin
