// Config error cases as folders (STYLE.md, tests): tests/golden/config/<case>/
// holds config.toml and expected.txt, the exact lines `pvtwin check-config
// config.toml` prints to stderr (empty for a valid config). Cases named ok_*
// must load; all others must fail.
//
// To re-record after an intended change of the messages, run the tests with
// PVTWIN_UPDATE_GOLDEN=1 and review the diff.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "config/plant_config.h"
#include "tests/support/files.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;

const fs::path kCasesDir = fs::path(PVTWIN_GOLDEN_DIR) / "config";

using pvtwin::testing::ReadFile;

std::vector<std::string> CaseNames() { return pvtwin::testing::SubfolderNames(kCasesDir); }

class ConfigGoldenTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ConfigGoldenTest, MessagesMatchExpected) {
  const fs::path dir = kCasesDir / GetParam();
  Config config;
  Diagnostics errors;
  const bool ok = ParseConfig(ReadFile(dir / "config.toml"), "config.toml", &config, &errors);
  std::string actual;
  for (const Diagnostic& d : errors) actual += d.ToString() + "\n";

  if (std::getenv("PVTWIN_UPDATE_GOLDEN") != nullptr) {
    std::ofstream(dir / "expected.txt", std::ios::binary) << actual;
  }
  EXPECT_EQ(ok, errors.empty());
  EXPECT_EQ(ok, GetParam().starts_with("ok_")) << actual;
  EXPECT_EQ(actual, ReadFile(dir / "expected.txt"));
}

INSTANTIATE_TEST_SUITE_P(Config, ConfigGoldenTest, ::testing::ValuesIn(CaseNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

TEST(ConfigGolden, HasTheCatalogueOfCases) {
  const std::vector<std::string> names = CaseNames();
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
  EXPECT_FALSE(ParseConfig(ReadFile(kCasesDir / "several_errors_at_once" / "config.toml"),
                           "config.toml", &config, &errors));
  EXPECT_GE(errors.size(), 3u);
}

}  // namespace
}  // namespace pvtwin
