// `pvtwin check-config` as a real process: exit codes, stdout summary and the
// stderr messages of a golden config case.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;

using testing::ProcessResult;
using testing::ReadFile;
using testing::RunPvtwin;

const fs::path kCases = fs::path(PVTWIN_GOLDEN_DIR) / "config";

TEST(CheckConfig, BadConfigExitsTwoWithEveryProblemOnStderr) {
  const fs::path dir = kCases / "several_errors_at_once";
  const ProcessResult run = RunPvtwin(dir, "check-config config.toml");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "");
  EXPECT_EQ(run.err, ReadFile(dir / "expected.txt"));
  EXPECT_NE(run.err.find("config.toml:3: longitude_deg = 190.5: must be within [-180, 180]\n"),
            std::string::npos);
}

TEST(CheckConfig, GoodConfigExitsZeroWithASummary) {
  const ProcessResult run = RunPvtwin(kCases / "ok_minimal", "check-config config.toml");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  EXPECT_EQ(run.out,
            "config.toml: ok (plant 1.8 m² at 47.358°N 16.128°E, tilt 20°, azimuth 180°; "
            "calibration 2N1Ccolwr daily at 02:00 Europe/Vienna)\n");
}

TEST(CheckConfig, SouthWestSiteIsSummarisedWithSAndW) {
  const ProcessResult run = RunPvtwin(kCases / "ok_full", "check-config config.toml");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out,
            "config.toml: ok (plant 16.2 m² at 33.9°S 70.6°W, tilt 35°, azimuth 0°; "
            "calibration 1N1Cwr+transport_delay daily at 03:30 America/Santiago)\n");
}

TEST(CheckConfig, MissingFileExitsTwo) {
  const ProcessResult run = RunPvtwin(kCases, "check-config no_such_file.toml");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.err, "no_such_file.toml: cannot open: No such file or directory\n");
}

TEST(CheckConfig, MissingArgumentIsBadUsage) {
  const ProcessResult run = RunPvtwin(kCases, "check-config");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("FILE"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace pvtwin
