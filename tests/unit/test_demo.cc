// `pvtwin demo` as a newcomer runs it, a real process: it ends with exit 0
// once forecasts are written, says how many, and says so too when its wall
// time limit cuts the live part short (it once wrote 19 forecasts, then
// said "stopped ... without a forecast" and exited 1).
#include <gtest/gtest.h>

#include <regex>

#include "tests/support/files.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

TEST(Demo, ALiveRunCutShortByItsTimeLimitStillSucceedsAndCountsItsForecasts) {
  testing::ScratchDir dir("demo");
  const testing::ProcessResult run =
      testing::RunPvtwin(dir.path(), "demo --speed 600 --live-minutes 1100 --max-wall 15 --dir '" +
                                         (dir / "d").string() + "'");
  EXPECT_EQ(run.exit_code, 0) << run.out << run.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(run.out, m, std::regex(R"(with (\d+) forecasts? written)")))
      << run.out;
  EXPECT_GE(std::stoi(m[1]), 2) << "600x for 15 s spans more than one hourly refresh";
  EXPECT_NE(run.out.find("Stopped at the wall-time limit (--max-wall 15 s)"), std::string::npos)
      << run.out;
  EXPECT_EQ(run.err.find("without a forecast"), std::string::npos) << run.err;
  EXPECT_EQ(run.out.find("| forecast written"), std::string::npos)
      << "status lines count the forecasts";
}

}  // namespace
}  // namespace pvtwin
