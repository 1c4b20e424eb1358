// systemd/pvtwin.service: systemd's own checker accepts it without a warning,
// and its offline security analysis rates the sandbox as tight.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <string>

#include "tests/support/files.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::RunCommand;
using testing::ScratchDir;

const fs::path kUnit = fs::path(PVTWIN_SOURCE_DIR) / "systemd" / "pvtwin.service";

// The unit with ExecStart pointing at the built binary: `verify` checks that
// the executable exists.
fs::path UnitWithBuiltBinary(const ScratchDir& dir) {
  const std::string text = std::regex_replace(ReadFile(kUnit), std::regex("/usr/bin/pvtwin"),
                                              std::string(PVTWIN_BINARY));
  const fs::path path = dir / "pvtwin.service";
  std::ofstream(path) << text;
  return path;
}

TEST(SystemdUnit, VerifiesWithoutWarnings) {
  ASSERT_EQ(RunCommand(".", "command -v systemd-analyze >/dev/null").exit_code, 0)
      << "systemd-analyze is missing (Debian package systemd)";
  const ScratchDir dir("unit");
  const testing::ProcessResult r =
      RunCommand(dir.path(), "systemd-analyze verify '" + UnitWithBuiltBinary(dir).string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

TEST(SystemdUnit, OfflineSecurityExposureIsLow) {
  const ScratchDir dir("unit");
  const testing::ProcessResult r =
      RunCommand(dir.path(), "systemd-analyze security --offline=yes --no-pager '" +
                                 UnitWithBuiltBinary(dir).string() + "'");
  // "→ Overall exposure level for pvtwin.service: 1.6 OK"; 0 = fully
  // sandboxed, 10 = not at all. Below 2 is systemd's "OK" band's lower part.
  std::smatch m;
  const std::string all = r.out + r.err;
  ASSERT_TRUE(std::regex_search(all, m, std::regex("exposure level for [^:]+: ([0-9.]+)"))) << all;
  EXPECT_LT(std::stod(m[1].str()), 2.0) << all;
}

TEST(SystemdUnit, IsNotifyTypeWithAWatchdogAndADedicatedUser) {
  const std::string text = ReadFile(kUnit);
  for (const char* line : {"Type=notify", "WatchdogSec=", "User=pvtwin", "DynamicUser=yes",
                           "StateDirectory=pvtwin", "ProtectSystem=strict", "NoNewPrivileges=yes",
                           "CapabilityBoundingSet=\n", "MemoryDenyWriteExecute=yes"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line;
  }
}

}  // namespace
}  // namespace pvtwin
