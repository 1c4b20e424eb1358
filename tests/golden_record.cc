// pvtwin_golden_record: re-records tests/golden/{config,csv}/*/expected.txt
// after an intended change of the messages or of the reader. Not part of the
// test run: run it by hand, then read `git diff tests/golden` line by line
// before committing, since whatever it writes the tests will accept.
//
//   cmake --build build --target pvtwin_golden_record && ./build/tests/pvtwin_golden_record
#include <cstdio>
#include <fstream>

#include "tests/support/golden_reports.h"

int main() {
  using namespace pvtwin::testing;
  int written = 0;
  for (const std::string& name : SubfolderNames(kGoldenConfigDir)) {
    bool ok = false;
    std::ofstream(kGoldenConfigDir / name / "expected.txt", std::ios::binary)
        << ConfigCaseReport(kGoldenConfigDir / name, &ok);
    ++written;
  }
  for (const std::string& name : SubfolderNames(kGoldenCsvDir)) {
    bool ok = false;
    std::ofstream(kGoldenCsvDir / name / "expected.txt", std::ios::binary)
        << CsvCaseReport(kGoldenCsvDir / name, &ok);
    ++written;
  }
  std::printf("re-recorded %d golden cases under %s: review `git diff` before committing\n",
              written, PVTWIN_GOLDEN_DIR);
  return 0;
}
