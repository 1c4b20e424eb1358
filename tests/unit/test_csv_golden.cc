// Canonical CSV cases as folders: tests/golden/csv/<case>/ holds input.csv and
// expected.txt with
//   error: <diagnostic>      every error, in order
//   warning: <diagnostic>    every warning, in order
// and, if the file was read, "step_s = <median step>" followed by the series
// as WriteCsv writes it (time and every channel present, in channel order),
// which shows unit conversions and corrections. Cases named ok_* must read
// without errors. Read with CsvReadOptions{} (fluid density 1040 kg/m³).
//
// To re-record after an intended change, run the tests with
// PVTWIN_UPDATE_GOLDEN=1 and review the diff.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "io/csv.h"
#include "tests/support/files.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;

const fs::path kCasesDir = fs::path(PVTWIN_GOLDEN_DIR) / "csv";

using pvtwin::testing::ReadFile;

std::vector<std::string> CaseNames() { return pvtwin::testing::SubfolderNames(kCasesDir); }

// The report described at the top of this file.
std::string Report(const fs::path& input, bool* ok) {
  std::ifstream in(input, std::ios::binary);
  Series series;
  Diagnostics errors;
  Diagnostics warnings;
  *ok = ParseCanonicalCsv(in, "input.csv", CsvReadOptions{}, &series, &errors, &warnings);
  std::ostringstream out;
  for (const Diagnostic& d : errors) out << "error: " << d.ToString() << "\n";
  for (const Diagnostic& d : warnings) out << "warning: " << d.ToString() << "\n";
  if (*ok) {
    std::vector<Channel> present;
    for (const ChannelInfo& info : kChannels) {
      if (series.Has(info.channel)) present.push_back(info.channel);
    }
    out << "step_s = " << series.step_s << "\n";
    WriteCsv(out, series, present);
  }
  return out.str();
}

class CsvGoldenTest : public ::testing::TestWithParam<std::string> {};

TEST_P(CsvGoldenTest, ReportMatchesExpected) {
  const fs::path dir = kCasesDir / GetParam();
  bool ok = false;
  const std::string actual = Report(dir / "input.csv", &ok);
  if (std::getenv("PVTWIN_UPDATE_GOLDEN") != nullptr) {
    std::ofstream(dir / "expected.txt", std::ios::binary) << actual;
  }
  EXPECT_EQ(ok, GetParam().starts_with("ok_")) << actual;
  EXPECT_EQ(actual, ReadFile(dir / "expected.txt"));
}

INSTANTIATE_TEST_SUITE_P(Csv, CsvGoldenTest, ::testing::ValuesIn(CaseNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

TEST(CsvGolden, HasTheCatalogueOfCases) {
  const std::vector<std::string> names = CaseNames();
  for (const char* required :
       {"bad_number", "wrong_field_count", "missing_required_column", "time_not_increasing",
        "bad_time", "ok_unknown_column_warning", "ok_flow_l_h_conversion", "ok_iso_offset_time",
        "ok_paper_corrections"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
}

}  // namespace
}  // namespace pvtwin
