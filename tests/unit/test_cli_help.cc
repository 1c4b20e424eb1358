// Every verb's --help, as a user reads it: the defaults of its options, one
// example, and, where a variant is taken, the variant grammar with every
// effect of the library.
#include <gtest/gtest.h>

#include <string>

#include "core/diagnosis/effect_candidates.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

TEST(CliHelp, EveryVerbShowsAnExampleAndItsDefaults) {
  const std::string verbs[] = {"check-config", "calibrate", "simulate", "backtest",
                               "import",       "export",    "sim",      "run",
                               "demo",         "diagnose",  "diagnose-selftest",
                               "import-weather", "upload"};
  for (const std::string& verb : verbs) {
    const testing::ProcessResult r = testing::RunPvtwin(".", verb + " --help");
    EXPECT_EQ(r.exit_code, 0) << verb;
    EXPECT_NE(r.out.find("\nExample:\n  pvtwin " + verb + " "), std::string::npos) << verb << ":\n"
                                                                                   << r.out;
  }
  // Defaults, as CLI11 shows them ("=value").
  EXPECT_NE(testing::RunPvtwin(".", "demo --help").out.find("--speed FLOAT:FLOAT in [1 - 600]=60"),
            std::string::npos);
  EXPECT_NE(testing::RunPvtwin(".", "export --help").out.find("--to TEXT=now"), std::string::npos);
}

// The benchmarks are an executable of their own, never part of the product.
TEST(CliHelp, TheInstalledBinaryHasNoBenchmarks) {
  const testing::ProcessResult r = testing::RunPvtwin(".", "bench sim");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(testing::RunPvtwin(".", "--help").out.find("bench"), std::string::npos);
}

TEST(CliHelp, VerbsTakingAVariantExplainTheGrammarAndListEveryEffect) {
  for (const char* verb : {"calibrate", "simulate", "backtest", "diagnose"}) {
    const std::string help = testing::RunPvtwin(".", std::string(verb) + " --help").out;
    EXPECT_NE(help.find("paper's Table 6"), std::string::npos) << verb;
    EXPECT_NE(help.find("w wind-dependent front loss"), std::string::npos) << verb;
    for (const std::string& effect : EffectNames()) {
      EXPECT_NE(help.find(effect), std::string::npos) << verb << ": " << effect;
    }
  }
}

}  // namespace
}  // namespace pvtwin
