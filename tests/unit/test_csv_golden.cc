// Canonical CSV cases as folders: tests/golden/csv/<case>/ holds input.csv and
// expected.txt, the report of tests/support/golden_reports.h. Cases named
// ok_* must read without errors. After an intended change, re-record with
// the separate program pvtwin_golden_record and review the diff.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "tests/support/golden_reports.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using pvtwin::testing::kGoldenCsvDir;
using pvtwin::testing::ReadFile;

std::vector<std::string> CsvCaseNames() { return pvtwin::testing::SubfolderNames(kGoldenCsvDir); }

class CsvGoldenTest : public ::testing::TestWithParam<std::string> {};

TEST_P(CsvGoldenTest, ReportMatchesExpected) {
  const fs::path dir = kGoldenCsvDir / GetParam();
  bool ok = false;
  const std::string actual = pvtwin::testing::CsvCaseReport(dir, &ok);
  EXPECT_EQ(ok, GetParam().starts_with("ok_")) << actual;
  EXPECT_EQ(actual, ReadFile(dir / "expected.txt"));
}

// The reading of a large file on two threads (io/files/csv.h), here made to take
// every case: the same series and the same diagnostics, errors included.
TEST_P(CsvGoldenTest, ReadOnTwoThreadsAsInOnePiece) {
  const fs::path dir = kGoldenCsvDir / GetParam();
  bool ok = false;
  const std::string split =
      pvtwin::testing::CsvCaseReport(dir, &ok, pvtwin::testing::CsvRead::kFileOnTwoThreads);
  EXPECT_EQ(ok, GetParam().starts_with("ok_")) << split;
  EXPECT_EQ(split, ReadFile(dir / "expected.txt"));
}

INSTANTIATE_TEST_SUITE_P(Csv, CsvGoldenTest, ::testing::ValuesIn(CsvCaseNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

TEST(CsvGolden, HasTheCatalogueOfCases) {
  const std::vector<std::string> names = CsvCaseNames();
  for (const char* required :
       {"bad_number", "wrong_field_count", "missing_required_column", "time_not_increasing",
        "bad_time", "ok_unknown_column_warning", "ok_flow_l_h_conversion", "ok_iso_offset_time",
        "ok_paper_corrections"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
}

}  // namespace
}  // namespace pvtwin
