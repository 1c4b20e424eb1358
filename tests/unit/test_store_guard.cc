// What the store refuses and what the daemon does when its file is taken
// away, through real processes and real files: a damaged or foreign file is
// refused and left byte for byte as it was, a store the user cannot write is
// named as such, two daemons on one store are one too many, and a store
// deleted under the running daemon stops it (exit 1) with the content saved.
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include "core/common/clock.h"
#include "io/platform/child_process.h"
#include "io/store/store.h"
#include "tests/support/files.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/wait.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::RunCommand;
using testing::RunPvtwin;
using testing::ScratchDir;
using testing::WaitFor;

constexpr char kPlant[] =
    "[plant]\nlatitude_deg = 47.358\nlongitude_deg = 16.128\ntilt_deg = 20\n"
    "azimuth_deg = 180\narea_m2 = 1.8\n";

// A plain SQLite file with one table of someone else's.
void MakeForeignDb(const fs::path& path) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db,
                         "CREATE TABLE inventory(id INTEGER PRIMARY KEY, item TEXT);"
                         "INSERT INTO inventory(item) VALUES ('pump'), ('valve');",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
}

TEST(StoreGuard, AForeignDatabaseIsRefusedAndLeftUnchanged) {
  ScratchDir dir("guard_foreign");
  const fs::path path = dir / "other.db";
  MakeForeignDb(path);
  const std::string before = ReadFile(path);
  std::string error;
  EXPECT_EQ(Store::Open(path.string(), &error), nullptr);
  EXPECT_NE(error.find("not a pvtwin store (it holds inventory"), std::string::npos) << error;
  EXPECT_EQ(ReadFile(path), before) << "the file was changed (switched to WAL?)";
  EXPECT_FALSE(fs::exists(dir / "other.db-wal"));
}

TEST(StoreGuard, ADamagedDatabaseIsRefusedBeforeAnythingIsWritten) {
  ScratchDir dir("guard_damaged");
  const fs::path path = dir / "pvtwin.db";
  {
    std::string error;
    std::unique_ptr<Store> store = Store::Open(path.string(), &error);
    ASSERT_TRUE(store) << error;
    std::vector<Sample> samples(20000);  // most of the file, whatever tables the schema adds
    for (std::size_t i = 0; i < samples.size(); ++i) {
      samples[i].ts_s = 1717236000 + 5 * static_cast<std::int64_t>(i);
      samples[i].Set(Channel::kTAmbC, 20.0);
    }
    ASSERT_TRUE(store->InsertSamples(samples, &error)) << error;
  }
  // Overwrite part of a page in the middle of the file (sample_5s's rows,
  // which fill most of it) with garbage, past the page header.
  {
    const auto middle = static_cast<std::streamoff>(fs::file_size(path) / 2 / 4096 * 4096);
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(middle + 100);
    const std::string garbage(2000, '\x5A');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  const std::string before = ReadFile(path);
  std::string error;
  EXPECT_EQ(Store::Open(path.string(), &error), nullptr);
  EXPECT_NE(error.find("the database is damaged (PRAGMA quick_check"), std::string::npos) << error;
  EXPECT_EQ(ReadFile(path), before);
  // The command line says so too, with exit 1.
  std::ofstream(dir / "pvtwin.toml") << kPlant;
  const testing::ProcessResult run =
      RunPvtwin(dir.path(), "export --config pvtwin.toml --db pvtwin.db --from 0 --to 2000000000");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("damaged"), std::string::npos) << run.err;
}

TEST(StoreGuard, AStoreTheUserCannotWriteIsNamedAsSuch) {
  ScratchDir dir("guard_readonly");
  std::ofstream(dir / "pvtwin.toml") << kPlant;
  {
    std::string error;
    ASSERT_TRUE(Store::Open((dir / "pvtwin.db").string(), &error)) << error;
  }
  fs::permissions(dir / "pvtwin.db",
                  fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  fs::permissions(dir.path(), fs::perms::all);
  fs::permissions(dir / "pvtwin.toml", fs::perms::owner_read | fs::perms::others_read);
  // root may write anything: run as nobody then (setpriv, util-linux).
  const std::string as_user =
      ::geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : "";
  // A verb that writes (migrate opens the store as the daemon does).
  const testing::ProcessResult run = RunCommand(
      dir.path(), as_user + "'" + std::string(PVTWIN_BINARY) + "' migrate --db pvtwin.db");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("permission denied: the database file is read-only for uid"),
            std::string::npos)
      << run.err;
  // export only reads: it opens the store read-only and needs no write access.
  const testing::ProcessResult read =
      RunCommand(dir.path(), as_user + "'" + std::string(PVTWIN_BINARY) +
                                 "' export --config pvtwin.toml --db pvtwin.db --from 0 --to 1");
  EXPECT_EQ(read.exit_code, 0) << read.err;
}

class DaemonStoreGuard : public ::testing::Test {
 protected:
  void SetUp() override {
    std::ofstream(dir_ / "pvtwin.toml")
        << kPlant << "[storage]\npath = \"" << (dir_ / "pvtwin.db").string() << "\"\n";
  }
  bool Start(ChildProcess* daemon, const std::string& log) {
    std::string error;
    const bool started =
        daemon->Start({PVTWIN_BINARY, "run", "--config", (dir_ / "pvtwin.toml").string()},
                      (dir_ / log).string(), &error);
    EXPECT_TRUE(started) << error;
    return started;
  }
  ScratchDir dir_{"guard_daemon"};
};

TEST_F(DaemonStoreGuard, ASecondDaemonOnTheSameStoreExitsWithOne) {
  ChildProcess first, second;
  ASSERT_TRUE(Start(&first, "first.log"));
  ASSERT_TRUE(WaitFor(20, [&] {
    return ReadFile(dir_ / "first.log").find("ready") != std::string::npos;
  })) << ReadFile(dir_ / "first.log");
  ASSERT_TRUE(Start(&second, "second.log"));
  int exit_code = -100;
  ASSERT_TRUE(WaitFor(20, [&] { return second.Finished(&exit_code); }));
  EXPECT_EQ(exit_code, 1);
  EXPECT_NE(ReadFile(dir_ / "second.log").find("in use by another pvtwin run"), std::string::npos)
      << ReadFile(dir_ / "second.log");
  int first_code = -100;
  EXPECT_FALSE(first.Finished(&first_code)) << "the first daemon must keep running";
  EXPECT_EQ(first.Stop(SIGTERM, 10.0), 0);
}

TEST_F(DaemonStoreGuard, DeletingTheStoreStopsTheDaemonAndSavesItsContent) {
  ChildProcess daemon;
  ASSERT_TRUE(Start(&daemon, "daemon.log"));
  ASSERT_TRUE(WaitFor(
      20, [&] { return ReadFile(dir_ / "daemon.log").find("ready") != std::string::npos; }));
  fs::remove(dir_ / "pvtwin.db");
  int exit_code = -100;
  ASSERT_TRUE(WaitFor(20, [&] { return daemon.Finished(&exit_code); }))
      << ReadFile(dir_ / "daemon.log");
  EXPECT_EQ(exit_code, 1);
  const std::string log = ReadFile(dir_ / "daemon.log");
  EXPECT_NE(log.find("pvtwin.db was deleted while the daemon ran"), std::string::npos) << log;
  fs::path rescued;
  for (const fs::directory_entry& e : fs::directory_iterator(dir_.path())) {
    if (e.path().filename().string().starts_with("pvtwin.db.rescued-")) rescued = e.path();
  }
  ASSERT_FALSE(rescued.empty()) << log;
  std::string error;
  std::unique_ptr<Store> store = Store::Open(rescued.string(), &error);
  EXPECT_TRUE(store) << error;  // a complete pvtwin store
}

}  // namespace
}  // namespace pvtwin

namespace pvtwin {
namespace {

// The daemon's calibration child (`pvtwin calibrate --parent-pid`) dies with
// its parent. The parent here is a shell killed with SIGKILL; the child is
// held before it can finish by a FIFO as its CSV, which nobody writes.
TEST(CalibrationChild, DiesWhenItsParentIsKilled) {
  ScratchDir dir("guard_child");
  std::ofstream(dir / "pvtwin.toml") << kPlant;
  ASSERT_EQ(::mkfifo((dir / "never.csv").c_str(), 0600), 0);
  ChildProcess parent;
  std::string error;
  ASSERT_TRUE(parent.Start({"/bin/bash", "-c",
                            "cd \"$1\" || exit 1; \"$0\" calibrate --config pvtwin.toml --csv "
                            "never.csv --variant 1N --parent-pid $$ & echo $! > child.pid; wait",
                            PVTWIN_BINARY, dir.path().string()},
                           (dir / "parent.log").string(), &error))
      << error;
  pid_t child = 0;
  ASSERT_TRUE(WaitFor(10, [&] {
    std::ifstream in(dir / "child.pid");
    return static_cast<bool>(in >> child) && child > 0;
  }));
  // The child runs (blocked on the FIFO) until its parent goes.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_EQ(::kill(child, 0), 0) << "the calibrate child did not start";
  ::kill(parent.pid(), SIGKILL);
  int code = 0;
  ASSERT_TRUE(WaitFor(10, [&] { return parent.Finished(&code); }));
  // Gone, or a zombie waiting for whoever adopted it to reap it.
  const auto gone = [&] {
    std::ifstream stat("/proc/" + std::to_string(child) + "/stat");
    std::string pid, comm, state;
    return !(stat >> pid >> comm >> state) || state == "Z";
  };
  EXPECT_TRUE(WaitFor(10, gone)) << "calibrate outlived its parent";
}

}  // namespace
}  // namespace pvtwin
