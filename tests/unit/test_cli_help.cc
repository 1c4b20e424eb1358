// Every verb's --help, as a user reads it: the defaults of its options, one
// example, and, where a variant is taken, the variant grammar with every
// effect of the library.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "core/diagnosis/effect_candidates.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

TEST(CliHelp, EveryVerbShowsAnExampleAndItsDefaults) {
  const std::string verbs[] = {"check-config", "calibrate", "simulate", "backtest",
                               "import",       "export",    "sim",      "run",
                               "demo",         "diagnose",  "diagnose-selftest",
                               "import-weather", "upload", "poll", "migrate"};
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

// A mistyped verb is named with the verb meant, not "a subcommand is required".
TEST(CliHelp, AnUnknownVerbIsNamedWithItsNearestMatch) {
  const testing::ProcessResult r = testing::RunPvtwin(".", "calbrate");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown command calbrate; did you mean calibrate?"), std::string::npos)
      << r.err;
  const testing::ProcessResult prefix = testing::RunPvtwin(".", "check");
  EXPECT_EQ(prefix.exit_code, 2);
  EXPECT_NE(prefix.err.find("did you mean check-config?"), std::string::npos) << prefix.err;
  const testing::ProcessResult far = testing::RunPvtwin(".", "frobnicate");
  EXPECT_EQ(far.exit_code, 2);
  EXPECT_NE(far.err.find("unknown command frobnicate"), std::string::npos) << far.err;
  EXPECT_EQ(far.err.find("did you mean"), std::string::npos) << far.err;
}

// A mistyped option is named, not reported as the required one it stands for.
TEST(CliHelp, AnUnknownOptionIsNamedWithItsNearestMatch) {
  const testing::ProcessResult r = testing::RunPvtwin(".", "run --conifg x");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown option --conifg of `pvtwin run`; did you mean --config?"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("is required"), std::string::npos) << r.err;
  const testing::ProcessResult eq = testing::RunPvtwin(".", "export --tabel=forecast");
  EXPECT_EQ(eq.exit_code, 2);
  EXPECT_NE(eq.err.find("unknown option --tabel of `pvtwin export`; did you mean --table?"),
            std::string::npos)
      << eq.err;
  // Hidden options are accepted but never suggested.
  const testing::ProcessResult hidden = testing::RunPvtwin(".", "calibrate --parent-pi 1");
  EXPECT_EQ(hidden.exit_code, 2);
  EXPECT_EQ(hidden.err.find("--parent-pid"), std::string::npos) << hidden.err;
}

TEST(CliHelp, EveryMissingRequiredOptionIsNamedAtOnce) {
  const testing::ProcessResult r = testing::RunPvtwin(".", "calibrate --csv x.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("`pvtwin calibrate` is missing --config, --variant"), std::string::npos)
      << r.err;
  const testing::ProcessResult none = testing::RunPvtwin(".", "");
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.err.find("a command is required"), std::string::npos) << none.err;
}

TEST(CliHelp, HelpVerbAndVersionFlagWorkLikeTheOptions) {
  const testing::ProcessResult help = testing::RunPvtwin(".", "help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_EQ(help.out, testing::RunPvtwin(".", "--help").out);
  const testing::ProcessResult verb = testing::RunPvtwin(".", "help calibrate");
  EXPECT_EQ(verb.exit_code, 0);
  EXPECT_EQ(verb.out, testing::RunPvtwin(".", "calibrate --help").out);
  EXPECT_NE(verb.out.find("--variant"), std::string::npos);
  const testing::ProcessResult unknown = testing::RunPvtwin(".", "help calbrate");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("did you mean calibrate?"), std::string::npos) << unknown.err;
  for (const char* flag : {"-v", "--version"}) {
    const testing::ProcessResult v = testing::RunPvtwin(".", flag);
    EXPECT_EQ(v.exit_code, 0) << flag;
    EXPECT_EQ(v.out.rfind("pvtwin ", 0), 0u) << flag << ": " << v.out;
  }
}

// The top-level help is a list: one line per verb.
TEST(CliHelp, TopLevelHelpHasOneLinePerVerb) {
  const std::string help = testing::RunPvtwin(".", "--help").out;
  std::istringstream lines(help);
  std::string line;
  int count = 0;
  while (std::getline(lines, line)) ++count;
  EXPECT_LE(count, 30) << help;
  for (const char* verb : {"calibrate", "run", "export", "diagnose-selftest", "upload"}) {
    EXPECT_NE(help.find(std::string("\n  ") + verb + " "), std::string::npos) << verb << ":\n"
                                                                              << help;
  }
}

// Plumbing options of the daemon's children and of the tests are accepted
// but not shown.
TEST(CliHelp, InternalOptionsAreHiddenButAccepted) {
  const std::pair<const char*, const char*> hidden[] = {
      {"calibrate", "--parent-pid"}, {"diagnose", "--parent-pid"}, {"diagnose", "--run-at"},
      {"run", "--sim-start"},        {"run", "--wall-anchor"},     {"run", "--speed"},
      {"sim", "--wall-anchor"}};
  for (const auto& [verb, option] : hidden) {
    const std::string help = testing::RunPvtwin(".", std::string(verb) + " --help").out;
    EXPECT_EQ(help.find("\n  " + std::string(option) + " "), std::string::npos)
        << verb << " " << option;
  }
  // Accepted: the run fails on its missing config (2), not on the option.
  const testing::ProcessResult r =
      testing::RunPvtwin(".", "run --config missing.toml --sim-start 0 --wall-anchor 1 --speed 2");
  EXPECT_EQ(r.err.find("unknown option"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("missing.toml"), std::string::npos) << r.err;
}

// The default shown is the one used: never a value the option rejects.
TEST(CliHelp, DefaultsShownAreTheOnesUsed) {
  const std::string help = testing::RunPvtwin(".", "calibrate --help").out;
  EXPECT_NE(help.find("--threads INT:INT in [1 - 2]=auto"), std::string::npos) << help;
  EXPECT_NE(help.find("--ftol FLOAT:POSITIVE=1e-3"), std::string::npos) << help;
  EXPECT_NE(help.find("--max-evaluations INT=4000"), std::string::npos) << help;
  EXPECT_EQ(help.find("--step FLOAT=0"), std::string::npos) << help;
  const std::string diagnose = testing::RunPvtwin(".", "diagnose --help").out;
  EXPECT_NE(diagnose.find("--train-days INT:NONNEGATIVE=auto"), std::string::npos) << diagnose;
}

}  // namespace
}  // namespace pvtwin
