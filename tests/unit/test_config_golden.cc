// Config error cases as folders (STYLE.md, tests): tests/golden/config/<case>/
// holds config.toml and expected.txt, the exact lines `pvtwin check-config
// config.toml` prints to stderr (empty for a valid config). Cases named ok_*
// must load; all others must fail. After an intended change of the messages,
// re-record with the separate program pvtwin_golden_record and review the
// diff.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "tests/support/golden_reports.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using pvtwin::testing::kGoldenConfigDir;
using pvtwin::testing::ReadFile;

std::vector<std::string> ConfigCaseNames() {
  return pvtwin::testing::SubfolderNames(kGoldenConfigDir);
}

class ConfigGoldenTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ConfigGoldenTest, MessagesMatchExpected) {
  const fs::path dir = kGoldenConfigDir / GetParam();
  bool ok = false;
  const std::string actual = pvtwin::testing::ConfigCaseReport(dir, &ok);
  EXPECT_EQ(ok, actual.empty());
  EXPECT_EQ(ok, GetParam().starts_with("ok_")) << actual;
  EXPECT_EQ(actual, ReadFile(dir / "expected.txt"));
}

INSTANTIATE_TEST_SUITE_P(Config, ConfigGoldenTest, ::testing::ValuesIn(ConfigCaseNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

TEST(ConfigGolden, HasTheCatalogueOfCases) {
  const std::vector<std::string> names = ConfigCaseNames();
  for (const char* required :
       {"ok_minimal", "ok_full", "latitude_out_of_range", "several_errors_at_once", "unknown_key",
        "wrong_type", "missing_required", "unknown_section", "bad_toml_syntax",
        "bad_calibration_at"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
}

TEST(ConfigGolden, SeveralErrorsAreReportedTogether) {
  Config config;
  Diagnostics errors;
  EXPECT_FALSE(ParseConfig(ReadFile(kGoldenConfigDir / "several_errors_at_once" / "config.toml"),
                           "config.toml", &config, &errors));
  EXPECT_GE(errors.size(), 3u);
}

}  // namespace
}  // namespace pvtwin
