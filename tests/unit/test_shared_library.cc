// Client libraries loaded when first used (config/shared_library.h): the
// loader's errors, and which pvtwin commands map libpq and libcurl at all.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "config/shared_library.h"
#include "tests/support/files.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

std::string ErrorOf(const auto& action) {
  try {
    action();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(SharedLibrary, BindsAFunctionThatThenComputes) {
  const SharedLibrary libm("libm.so.6", "libc6");
  double (*cosine)(double) = nullptr;
  libm.Bind(&cosine, "cos");
  ASSERT_NE(cosine, nullptr);
  EXPECT_EQ(cosine(0.25), std::cos(0.25));
}

TEST(SharedLibrary, AMissingLibraryNamesItselfAndItsPackage) {
  const std::string why =
      ErrorOf([] { const SharedLibrary missing("libpvtwin-absent.so.9", "pvtwin-absent9"); });
  EXPECT_NE(why.find("libpvtwin-absent.so.9 could not be loaded"), std::string::npos) << why;
  EXPECT_NE(why.find("Debian package pvtwin-absent9"), std::string::npos) << why;
}

TEST(SharedLibrary, AMissingFunctionIsNamed) {
  const SharedLibrary libm("libm.so.6", "libc6");
  double (*absent)(double) = nullptr;
  const std::string why = ErrorOf([&] { libm.Bind(&absent, "pvtwin_no_such_function"); });
  EXPECT_NE(why.find("libm.so.6 has no function pvtwin_no_such_function"), std::string::npos)
      << why;
  EXPECT_EQ(absent, nullptr);
}

// glibc's loader lists every library it maps under LD_DEBUG=files.
bool Maps(const testing::ProcessResult& run, const std::string& soname) {
  return run.err.find("file=" + soname + " [0];") != std::string::npos;
}

TEST(SharedLibrary, PvtwinMapsItsOptionalLibrariesOnlyWhenACommandNeedsThem) {
  const testing::ProcessResult traced =
      testing::RunCommand(".", "LD_DEBUG=files '" + std::string(PVTWIN_BINARY) + "' --version");
  ASSERT_EQ(traced.exit_code, 0);
  ASSERT_TRUE(Maps(traced, "libc.so.6")) << "LD_DEBUG gave no list of mapped files";
  EXPECT_FALSE(Maps(traced, "libpq.so.5"));
  EXPECT_FALSE(Maps(traced, "libcurl.so.4"));
  // libsystemd: loaded by `pvtwin run` under systemd only
  // (DaemonPaths.TellsSystemdReadyWatchdogReloadingAndStopping).
  EXPECT_FALSE(Maps(traced, "libsystemd.so.0"));

  // A config with an [upload] section is checked by libpq itself, which is
  // then loaded: the lazy path is the one the upload takes.
  const testing::ScratchDir dir("shared_library");
  std::string config =
      testing::ReadFile(std::filesystem::path(PVTWIN_SOURCE_DIR) / "config/examples/pvtwin.toml");
  for (const std::string line : {"url = ", "plant_id = "}) {
    const std::size_t at = config.find("# " + line);
    ASSERT_NE(at, std::string::npos) << line;
    config.erase(at, 2);
  }
  const std::size_t section = config.find("# [upload]");
  ASSERT_NE(section, std::string::npos);
  config.erase(section, 2);
  std::ofstream(dir.path() / "upload.toml") << config;
  const testing::ProcessResult check = testing::RunCommand(
      dir.path(), "LD_DEBUG=files '" + std::string(PVTWIN_BINARY) + "' check-config upload.toml");
  EXPECT_EQ(check.exit_code, 0) << check.out;
  EXPECT_TRUE(Maps(check, "libpq.so.5"));
  EXPECT_FALSE(Maps(check, "libcurl.so.4"));
}

}  // namespace
}  // namespace pvtwin
