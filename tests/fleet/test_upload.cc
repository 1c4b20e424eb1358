// The upload into a central PostgreSQL (io/fleet/upload.h) against a real server
// (tests/support/pg_scratch_server.h) and the real pvtwin processes: daemons
// (`pvtwin run`, some polling `pvtwin sim` on loopback) and `pvtwin upload
// --once`. Every scenario ends by comparing the central rows with the
// plant's SQLite rows, value by value.
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "config/config_edit.h"
#include "core/common/clock.h"
#include "io/fleet/pg_client.h"
#include "io/fleet/upload.h"
#include "io/platform/child_process.h"
#include "tests/fleet/upload_fixture.h"
#include "tests/support/files.h"
#include "tests/support/pg_scratch_server.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/stop_timeout.h"
#include "tests/support/wait.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using testing::RawDb;
using testing::ReadFile;
using testing::RunCommand;
using testing::RunPvtwin;
using testing::UnitStopTimeoutS;
using testing::WaitFor;
using upload_test::Cell;
using upload_test::ExpectSameRows;
using upload_test::kMorning;
using upload_test::kSimPlant;
using upload_test::LocalRows;
using upload_test::Upload;

constexpr double kSpeed = 120.0;

int CountLines(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++n;
  }
  return n;
}

TEST_F(Upload, TwoDaemonsUploadTwoPlantsIntoOneDatabase) {
  // 1.5 days each: too little to calibrate, so each daemon records a
  // skipped calibration and no fit competes for the CPU.
  for (const auto& [name, seed] : {std::pair<std::string, int>{"north", 1}, {"south", 2}}) {
    WritePlant(name, "batch_rows = 700\n");
    Import(name, kMorning - 86400, 2, 60, seed, 2160);
  }
  ChildProcess north, south;
  ASSERT_TRUE(StartDaemon(&north, "north"));
  ASSERT_TRUE(StartDaemon(&south, "south"));
  for (const std::string name : {"north", "south"}) {
    ASSERT_TRUE(WaitFor(30, [&] {
      return Central("SELECT count(*) FROM calibration WHERE plant_id = '" + name + "'") >= 1 &&
             Pending(name) == 0;
    })) << Log(name);
  }
  EXPECT_EQ(north.Stop(SIGTERM, 10.0), 0) << Log("north");
  EXPECT_EQ(south.Stop(SIGTERM, 10.0), 0) << Log("south");
  EXPECT_EQ(Central("SELECT count(*) FROM measurement_1min"), 2 * 2160);
  ExpectPlantEqual("north");
  ExpectPlantEqual("south");
  // Different weather seeds: the plants' rows are their own.
  EXPECT_EQ(Central("SELECT count(*) FROM measurement_1min n JOIN measurement_1min s "
                    "USING (ts) WHERE n.plant_id = 'north' AND s.plant_id = 'south' "
                    "AND n.p_el_w IS NOT DISTINCT FROM s.p_el_w AND n.p_el_w > 0"),
            0);
  const auto latest =
      pg_.Query("SELECT plant_id, measurement_ts FROM plant_latest ORDER BY plant_id", "fleet");
  ASSERT_EQ(latest.size(), 2u);
  const std::string last_ts = std::to_string(kMorning - 86400 + 2160 * 60 - 60);
  EXPECT_EQ(latest[0], (std::vector<std::string>{"north", last_ts}));
  EXPECT_EQ(latest[1], (std::vector<std::string>{"south", last_ts}));
  EXPECT_NE(Log("north").find("upload: connected to"), std::string::npos) << Log("north");
}

TEST_F(Upload, AnUploaderKilledBetweenCentralCommitAndHighWaterMarkLeavesNoDuplicateAndNoGap) {
  WritePlant("plant", "batch_rows = 500\n");
  Import("plant", kMorning - 86400, 1, 60, 1);
  // An uploading process of its own that the second central COMMIT ends
  // before its mark moves: the injected after_central_commit.
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    UploadSettings settings;
    settings.store_path = Db("plant").string();
    settings.url = pg_.Conninfo("fleet");
    settings.password_file = (dir_ / "pgpassword").string();
    settings.plant_id = "plant";
    settings.batch_rows = 500;
    int commits = 0;
    settings.after_central_commit = [&commits] {
      if (++commits == 2) ::raise(SIGKILL);
    };
    std::string error;
    auto uploader = Uploader::Open(settings, &error);
    std::int64_t rows = 0;
    bool more = true;
    PgError pg_error;
    while (uploader && more && uploader->UploadBatches(&rows, &more, &pg_error)) {
    }
    ::_exit(3);  // not killed: the test fails below
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << status;
  EXPECT_EQ(WTERMSIG(status), SIGKILL);
  // The central database holds rows the store still counts as pending.
  const long long central = Central(
      "SELECT (SELECT count(*) FROM measurement_1min) + "
      "(SELECT count(*) FROM calibration)");
  double uploaded = 0;
  {
    RawDb db(Db("plant"));
    uploaded = db.Number("SELECT sum(rows_uploaded) FROM upload_state");
    EXPECT_EQ(db.Text("PRAGMA integrity_check"), "ok");
  }
  EXPECT_GT(central, static_cast<long long>(uploaded));
  ChildProcess daemon;
  ASSERT_TRUE(StartDaemon(&daemon, "plant"));
  // The daemon records a (skipped) calibration a loop pass after its start.
  ASSERT_TRUE(WaitFor(30, [&] {
    RawDb db(Db("plant"));
    return db.Number("SELECT count(*) FROM calibration") >= 1 &&
           Central("SELECT count(*) FROM calibration") ==
               static_cast<long long>(db.Number("SELECT count(*) FROM calibration")) &&
           Pending("plant") == 0 && Central("SELECT count(*) FROM measurement_1min") == 1440;
  })) << Log("plant");
  EXPECT_EQ(daemon.Stop(SIGTERM, 10.0), 0) << Log("plant");
  EXPECT_EQ(Central("SELECT count(*) FROM measurement_1min"), 1440);
  ExpectPlantEqual("plant");
}

TEST_F(Upload, ReaggregatedMinutesCalibrationStatusAndForecastsUpdateTheirCentralRows) {
  WritePlant("plant", "batch_rows = 400\nforecast_days = 2\n");
  const std::int64_t day = kMorning - 8 * 3600;  // 00:00 UTC
  Import("plant", day, 1, 60, 1);
  const std::int64_t issue = day + 12 * 3600;
  // From here on the store's triggers queue what changes.
  const auto init = RunPvtwin(dir_.path(), "upload --init --config plant.toml");
  ASSERT_EQ(init.exit_code, 0) << init.err;
  {
    RawDb db(Db("plant"));
    ASSERT_EQ(db.Exec("INSERT INTO calibration(run_at, variant, status, accepted) VALUES(" +
                      std::to_string(day) + ", '1N1Cwr', 'running', 0)"),
              SQLITE_OK);
    // Three issues: an old one (pruned centrally: more than forecast_days
    // before the newest), and two that overlap (the newer wins each ts).
    for (const std::int64_t at : {issue - 5 * 86400, issue - 3600, issue}) {
      for (int k = 0; k < 120; ++k) {
        const std::int64_t ts = at + 60 * k;
        // With the bands and the reference of schema 6: central columns
        // follow the store's (ExpectPlantEqual compares every column).
        ASSERT_EQ(db.Exec("INSERT INTO forecast(issued_at, ts, p_el_w, q_th_w, p_el_w_p10, "
                          "p_el_w_p90, q_th_w_p10, q_th_w_p90, p_el_w_ref, q_th_w_ref) VALUES(" +
                          std::to_string(at) + ", " + std::to_string(ts) + ", " +
                          std::to_string(at % 1000 + k) + ".25, 1.5, " + std::to_string(k) +
                          ".5, 300.5, -2.5, 4.5, 7.25, NULL)"),
                  SQLITE_OK);
      }
    }
  }
  {
    // One queue entry per ts: a later issue replaces the earlier one's.
    RawDb db(Db("plant"));
    EXPECT_EQ(db.Number("SELECT count(*) FROM upload_queue WHERE table_name = 'forecast'"),
              120 + 120 + 60);
  }
  auto run = UploadOnce("plant");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("rows/s, ETA"), std::string::npos) << run.err;  // the progress line
  ExpectPlantEqual("plant", 2);
  EXPECT_EQ(Central("SELECT count(*) FROM forecast"), 120 + 60);
  EXPECT_EQ(Central("SELECT count(*) FROM forecast WHERE issued_at = " + std::to_string(issue)),
            120);
  EXPECT_EQ(Central("SELECT count(*) FROM forecast WHERE p_el_w_p90 = 300.5 AND q_th_w_ref IS "
                    "NULL"),
            120 + 60);

  // Samples of another weather seed for 10 minutes at 12:00: the import
  // re-aggregates (replaces) those minutes in a new process.
  const auto exported =
      RunPvtwin(dir_.path(), "sim --config '" + kSimPlant.string() +
                                 "' --export samples.csv --days 1 --step 5 --start " +
                                 std::to_string(day) + " --seed 7");
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  {
    std::istringstream in(ReadFile(dir_ / "samples.csv"));
    std::ofstream out(dir_ / "noon.csv");
    std::string line;
    std::getline(in, line);
    out << line << "\n";
    for (int i = 0; std::getline(in, line); ++i) {
      if (i >= 12 * 720 && i < 12 * 720 + 120) out << line << "\n";
    }
  }
  const std::string noon = std::to_string(day + 12 * 3600);
  const std::string before =
      pg_.Text("SELECT t_out_c FROM measurement_1min WHERE ts = " + noon, "fleet");
  ImportCsv("plant", "noon.csv");
  {
    RawDb db(Db("plant"));
    ASSERT_EQ(db.Exec("UPDATE calibration SET status = 'accepted', accepted = 1"), SQLITE_OK);
    EXPECT_EQ(db.Number("SELECT sum(rows_pending) FROM upload_status"), 10 + 1);
  }
  run = UploadOnce("plant");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(pg_.Text("SELECT t_out_c FROM measurement_1min WHERE ts = " + noon, "fleet"), before);
  ExpectPlantEqual("plant", 2);
  EXPECT_EQ(pg_.Text("SELECT status FROM calibration", "fleet"), "accepted");
  EXPECT_EQ(pg_.Text("SELECT calibration_id FROM plant_latest", "fleet"), "1");
  EXPECT_EQ(Central("SELECT count(*) FROM measurement_1min"), 1440);
}

// The daemon with a simulated plant on loopback, on an accelerated clock.
class UploadLive : public Upload {
 protected:
  void SetUp() override {
    Upload::SetUp();
    if (IsSkipped() || HasFatalFailure()) return;
    fs::copy_file(kSimPlant, dir_ / "sim.toml");
    anchor_ = WallNowS();
    std::string error;
    ASSERT_TRUE(
        sim_.StartPiped({PVTWIN_BINARY, "sim", "--config", (dir_ / "sim.toml").string(),
                         "--ephemeral-ports", "--speed", std::to_string(kSpeed), "--start",
                         std::to_string(kMorning), "--wall-anchor", std::to_string(anchor_)},
                        (dir_ / "sim.log").string(), &error))
        << error;
    ASSERT_TRUE(sim_.ReadUntil("ready", 20.0, &listening_)) << ReadFile(dir_ / "sim.log");
  }
  void TearDown() override {
    sim_.SendLine("quit");
    sim_.Stop(0, 5.0);
    Upload::TearDown();
  }
  fs::path WriteLivePlant(const std::string& upload_extra) {
    DaemonSettings settings;
    settings.db_path = Db("plant").string();
    std::string text, error;
    EXPECT_TRUE(
        EditConfig(ReadFile(kSimPlant), ParseListeningLines(listening_), settings, &text, &error))
        << error;
    return WritePlant("plant", upload_extra, text);
  }
  std::vector<std::string> LiveArgs() const {
    return {"--speed",       std::to_string(kSpeed), "--sim-start", std::to_string(kMorning),
            "--wall-anchor", std::to_string(anchor_)};
  }

  ChildProcess sim_;
  std::vector<std::string> listening_;
  double anchor_ = 0.0;
};

TEST_F(UploadLive, ServerStoppedAndRestartedMidRunLosesAndDuplicatesNothing) {
  WriteLivePlant("batch_rows = 300\n");
  Import("plant", kMorning - 86400, 1, 60, 1);
  ChildProcess daemon;
  ASSERT_TRUE(StartDaemon(&daemon, "plant", LiveArgs()));
  const std::string live = " WHERE ts >= " + std::to_string(kMorning);
  ASSERT_TRUE(WaitFor(30, [&] {
    return Central("SELECT count(*) FROM measurement_1min" + live) >= 2;
  })) << Log("plant");
  pg_.Stop();
  double samples_at_stop = 0;
  {
    RawDb db(Db("plant"));
    samples_at_stop = db.Number("SELECT count(*) FROM sample_5s");
  }
  // The plant keeps polling while the server is away (2 simulated minutes a second).
  ASSERT_TRUE(WaitFor(20, [&] {
    RawDb db(Db("plant"));
    return db.Number("SELECT count(*) FROM sample_5s") > samples_at_stop + 60 &&
           db.Text("SELECT state FROM upload_connection") == "down";
  })) << Log("plant");
  std::string error;
  ASSERT_TRUE(pg_.Resume(&error)) << error;
  ASSERT_TRUE(WaitFor(30, [&] {
    RawDb db(Db("plant"));
    return db.Text("SELECT state FROM upload_connection") == "connected" &&
           Central("SELECT max(ts) FROM measurement_1min") >
               static_cast<long long>(kMorning) + 60 * 12;
  })) << Log("plant");
  EXPECT_EQ(daemon.Stop(SIGTERM, 10.0), 0) << Log("plant");
  const std::string log = Log("plant");
  EXPECT_EQ(CountLines(log, "upload: server down"), 1) << log;
  EXPECT_EQ(CountLines(log, "upload: recovered"), 1) << log;
  // The minutes aggregated at the stop follow with the next upload.
  const auto run = UploadOnce("plant");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ExpectPlantEqual("plant");
}

TEST_F(UploadLive, WrongPasswordIsOneLoggedErrorAndThePlantKeepsPollingAndForecasting) {
  WriteLivePlant("");
  std::ofstream(dir_ / "pgpassword") << "not-" << pg_.password() << "\n";
  // Two days: the daemon calibrates at once and then forecasts.
  Import("plant", kMorning - 2 * 86400, 2, 60, 1);
  ChildProcess daemon;
  ASSERT_TRUE(StartDaemon(&daemon, "plant", LiveArgs()));
  ASSERT_TRUE(WaitFor(90, [&] {
    RawDb db(Db("plant"));
    return db.Number("SELECT count(*) FROM forecast") > 0 &&
           db.Number("SELECT count(*) FROM sample_5s") > 60;
  })) << Log("plant");
  {
    RawDb db(Db("plant"));
    EXPECT_EQ(db.Text("SELECT DISTINCT state FROM upload_status"), "auth_failed");
    EXPECT_NE(db.Text("SELECT last_error FROM upload_connection").find("password authentication"),
              std::string::npos);
    EXPECT_GT(db.Number("SELECT sum(rows_pending) FROM upload_status"), 2880);
  }
  EXPECT_EQ(daemon.Stop(SIGTERM, 10.0), 0) << Log("plant");
  EXPECT_EQ(CountLines(Log("plant"), "upload: authentication failed"), 1) << Log("plant");
  EXPECT_EQ(Central("SELECT count(*) FROM plant"), -1);  // nothing reached the server
}

TEST_F(Upload, MissingSchemaPermissionIsAClearErrorAndInitLetsARestrictedRoleUpload) {
  WritePlant("admin", "");
  const std::string restricted_password = "r" + pg_.password();
  ASSERT_EQ(pg_.Text("CREATE ROLE plant LOGIN PASSWORD '" + restricted_password + "'"), "");
  std::ofstream(dir_ / "plant-password") << restricted_password << "\n";
  // The plant's config: the restricted role, which may not CREATE in public.
  std::string text = ReadFile(dir_ / "admin.toml");
  const std::string user = "user=postgres", file = (dir_ / "pgpassword").string();
  text.replace(text.find(user), user.size(), "user=plant");
  text.replace(text.find(file), file.size(), (dir_ / "plant-password").string());
  text.replace(text.find("plant_id = \"admin\""), 18, "plant_id = \"plant\"");
  text.replace(text.find("admin.db"), 8, "plant.db");
  std::ofstream(dir_ / "plant.toml") << text;
  Import("plant", kMorning - 86400, 1, 60, 1, 720);

  auto run = UploadOnce("plant");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("permission denied for schema public"), std::string::npos) << run.err;
  {
    RawDb db(Db("plant"));
    EXPECT_EQ(db.Text("SELECT state FROM upload_connection"), "refused");
    EXPECT_EQ(db.Number("SELECT sum(rows_pending) FROM upload_status"), 720);
  }
  // The administrator creates the schema; the role gets rights on the tables.
  const auto init = RunPvtwin(dir_.path(), "upload --init --config admin.toml");
  ASSERT_EQ(init.exit_code, 0) << init.err;
  EXPECT_NE(
      init.err.find("central schema version " + std::to_string(kCentralSchemaVersion) + " ready"),
      std::string::npos)
      << init.err;
  ASSERT_EQ(pg_.Text("GRANT SELECT, INSERT, UPDATE, DELETE ON ALL TABLES IN SCHEMA public TO plant",
                     "fleet"),
            "");
  run = UploadOnce("plant");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("upload: 720 rows"), std::string::npos) << run.err;
  ExpectPlantEqual("plant");
  // A central schema from a newer pvtwin is refused, not migrated back.
  ASSERT_EQ(pg_.Text("INSERT INTO pvtwin_schema(version) VALUES(" +
                         std::to_string(kCentralSchemaVersion + 1) + ")",
                     "fleet"),
            "");
  run = UploadOnce("plant");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("newer than this pvtwin knows"), std::string::npos) << run.err;
}

TEST_F(Upload, WithoutOnceItFollowsRowsOtherProcessesWriteUntilSigterm) {
  WritePlant("plant", "");
  Import("plant", kMorning - 86400, 1, 60, 1, 360);
  ChildProcess upload;
  std::string error;
  ASSERT_TRUE(upload.Start({PVTWIN_BINARY, "upload", "--config", (dir_ / "plant.toml").string()},
                           (dir_ / "plant.log").string(), &error))
      << error;
  ASSERT_TRUE(WaitFor(20, [&] { return Central("SELECT count(*) FROM measurement_1min") == 360; }))
      << Log("plant");
  // The next six hours, imported by another process while it runs.
  Import("plant", kMorning - 86400, 1, 60, 1, 720);
  ASSERT_TRUE(WaitFor(20, [&] { return Central("SELECT count(*) FROM measurement_1min") == 720; }))
      << Log("plant");
  EXPECT_EQ(upload.Stop(SIGTERM, 10.0), 0) << Log("plant");
  ExpectPlantEqual("plant");
}

TEST_F(Upload, UnreachableServerIsExitCodeOneAndBadConfigIsTwo) {
  WritePlant("plant", "");
  Import("plant", kMorning - 86400, 1, 60, 1, 360);
  pg_.Stop();
  auto run = UploadOnce("plant");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("upload: connect:"), std::string::npos) << run.err;
  {
    RawDb db(Db("plant"));
    EXPECT_EQ(db.Text("SELECT state FROM upload_connection"), "down");
    EXPECT_EQ(db.Number("SELECT sum(rows_pending) FROM upload_status"), 360);
  }
  // A password in the URL is refused at its line, without showing it.
  std::string text = ReadFile(dir_ / "plant.toml");
  text.replace(text.find("url = \""), 7, "url = \"password=hunter2 ");
  std::ofstream(dir_ / "bad.toml") << text;
  run = RunPvtwin(dir_.path(), "upload --once --config bad.toml");
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("url = (value not shown): holds a password"), std::string::npos)
      << run.err;
  EXPECT_EQ(run.err.find("hunter2"), std::string::npos) << run.err;
}

TEST_F(Upload, AStalledServerMidUploadEndsAtSigtermWithinSecondsAndTheRowsStayQueued) {
  WritePlant("plant", "batch_rows = 100\n");
  Import("plant", kMorning - 86400, 1, 60, 1, 360);
  ASSERT_EQ(UploadOnce("plant").exit_code, 0);
  Import("plant", kMorning - 86400, 1, 60, 1, 720);
  const double queued = Pending("plant");  // the import replaced the first 360 too
  ASSERT_GE(queued, 360);
  auto lock = LockTable("measurement_1min");
  ChildProcess upload;
  std::string error;
  ASSERT_TRUE(
      upload.Start({PVTWIN_BINARY, "upload", "--once", "--config", (dir_ / "plant.toml").string()},
                   (dir_ / "plant.log").string(), &error))
      << error;
  ASSERT_GT(StallUploadBackend(&lock), 0) << Log("plant");
  int exit_code = 0;
  // Stalled: it neither finishes nor fails on its own within seconds.
  EXPECT_FALSE(WaitFor(2, [&] { return upload.Finished(&exit_code); })) << Log("plant");
  const double sent = WallNowS();
  ::kill(upload.pid(), SIGTERM);
  ASSERT_TRUE(WaitFor(5, [&] { return upload.Finished(&exit_code); })) << Log("plant");
  EXPECT_LT(WallNowS() - sent, 3.0);
  EXPECT_EQ(exit_code, 1) << Log("plant");
  EXPECT_NE(Log("plant").find("interrupted by a stop request"), std::string::npos) << Log("plant");
  EXPECT_EQ(Pending("plant"), queued) << Log("plant");
  // The server back: the next run sends them, nothing lost or doubled.
  ::kill(stalled_, SIGCONT);
  stalled_ = 0;
  ASSERT_EQ(UploadOnce("plant").exit_code, 0);
  EXPECT_EQ(Central("SELECT count(*) FROM measurement_1min"), 720);
  ExpectPlantEqual("plant");
}

TEST_F(Upload, ADaemonWhoseServerStalledStopsWithinItsStopTimeout) {
  WritePlant("plant", "batch_rows = 100\n");
  Import("plant", kMorning - 86400, 1, 60, 1, 360);
  ChildProcess daemon;
  ASSERT_TRUE(StartDaemon(&daemon, "plant"));
  ASSERT_TRUE(WaitFor(30, [&] {
    return Central("SELECT count(*) FROM measurement_1min") == 360 && Pending("plant") == 0;
  })) << Log("plant");
  auto lock = LockTable("measurement_1min");
  Import("plant", kMorning - 86400, 1, 60, 1, 720);  // the next upload round waits
  ASSERT_GT(StallUploadBackend(&lock), 0) << Log("plant");
  const double sent = WallNowS();
  EXPECT_EQ(daemon.Stop(SIGTERM, UnitStopTimeoutS()), 0) << Log("plant");
  EXPECT_LT(WallNowS() - sent, UnitStopTimeoutS() / 2);
  EXPECT_EQ(Log("plant").find("upload: server down"), std::string::npos) << Log("plant");
  EXPECT_GE(Pending("plant"), 360);
}

TEST_F(Upload, ASecondStoreUnderTheSamePlantIdIsRefusedUntilItTakesOver) {
  WritePlant("site", "");
  Import("site", kMorning - 86400, 1, 60, 1, 720);
  ASSERT_EQ(UploadOnce("site").exit_code, 0);
  // The config copied to a second site: the same plant_id, its own store.
  std::string text = ReadFile(dir_ / "site.toml");
  text.replace(text.find("site.db"), 7, "copy.db");
  std::ofstream(dir_ / "copy.toml") << text;
  Import("copy", kMorning - 86400, 1, 60, 2, 720);
  auto run = UploadOnce("copy");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("plant_id site belongs centrally to another store"), std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("--takeover"), std::string::npos) << run.err;
  ExpectSameRows(pg_, Db("site"), "site", "measurement_1min", "", "ts");  // untouched
  {
    RawDb db(Db("copy"));
    EXPECT_EQ(db.Text("SELECT state FROM upload_connection"), "refused");
    EXPECT_NE(db.Text("SELECT last_error FROM upload_status LIMIT 1").find("another store"),
              std::string::npos);
    EXPECT_GT(db.Number("SELECT last_error_at FROM upload_status LIMIT 1"), 0.0);
    EXPECT_EQ(db.Number("SELECT sum(rows_pending) FROM upload_status"), 720);
  }
  // A deliberate move to new hardware.
  run = RunCommand(dir_.path(), "'" + std::string(PVTWIN_BINARY) +
                                    "' upload --once --takeover --config copy.toml");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(ExpectSameRows(pg_, Db("copy"), "site", "measurement_1min", "", "ts"), 720u);
  RawDb db(Db("copy"));
  EXPECT_EQ(pg_.Text("SELECT store_id FROM plant WHERE plant_id = 'site'", "fleet"),
            db.Text("SELECT store_id FROM store_identity"));
  // Now the first store is the stranger.
  EXPECT_EQ(UploadOnce("site").exit_code, 1);
}

TEST_F(Upload, ACentralTableRenamedByADbaIsAnErrorWithTheCountsNeverRecreatedEmpty) {
  WritePlant("plant", "batch_rows = 100\n");
  Import("plant", kMorning - 86400, 1, 60, 1, 360);
  ASSERT_EQ(UploadOnce("plant").exit_code, 0);
  ASSERT_EQ(pg_.Text("ALTER TABLE measurement_1min RENAME TO m1_old", "fleet"), "");
  Import("plant", kMorning - 86400, 1, 60, 1, 410);
  RawDb local(Db("plant"));
  const std::string queued =
      local.Text("SELECT rows_pending FROM upload_status WHERE table_name = 'measurement_1min'");
  auto run = UploadOnce("plant");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("central table measurement_1min is missing"), std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("360 rows of plant_id plant were uploaded into it and " + queued +
                         " are queued"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(Central("SELECT count(*) FROM measurement_1min"), -1);  // not re-created
  EXPECT_EQ(Central("SELECT count(*) FROM m1_old"), 360);
  EXPECT_EQ(local.Text("SELECT rows_pending FROM upload_status WHERE table_name = "
                       "'measurement_1min'"),
            queued);
  // Sending everything again into a new table, on purpose.
  run = RunCommand(dir_.path(), "'" + std::string(PVTWIN_BINARY) +
                                    "' upload --once --resend --config plant.toml");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(Central("SELECT count(*) FROM measurement_1min"), 410);
  ExpectPlantEqual("plant");
}

// A central table that lost its key columns is not pvtwin's.
TEST_F(Upload, ACentralTableWithoutItsKeyColumnsIsAnError) {
  WritePlant("plant", "");
  Import("plant", kMorning - 86400, 1, 60, 1, 60);
  ASSERT_EQ(UploadOnce("plant").exit_code, 0);
  ASSERT_EQ(pg_.Text("ALTER TABLE calibration RENAME COLUMN id TO calibration_no", "fleet"), "");
  const auto run = UploadOnce("plant");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("central table calibration"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("has no key column id"), std::string::npos) << run.err;
}

// The Grafana dashboards of doc/grafana: every panel's query, with Grafana's
// macros as the time picker fills them, runs on a real store that a daemon
// calibrated and forecast in, and on the fleet database it uploaded to.
std::string FillMacros(std::string sql, std::int64_t from, std::int64_t to) {
  for (const auto& [macro, value] :
       {std::pair<std::string, std::string>{"$__unixEpochFrom()", std::to_string(from)},
        {"$__unixEpochTo()", std::to_string(to)},
        {"$plant", "dash"}}) {
    for (std::size_t at = sql.find(macro); at != std::string::npos; at = sql.find(macro, at)) {
      sql.replace(at, macro.size(), value);
    }
  }
  return sql;
}

TEST_F(Upload, TheGrafanaDashboardsQueriesRunOnTheStoreAndTheFleetDatabase) {
  WritePlant("dash", "");
  Import("dash", kMorning - 2 * 86400, 2, 60, 1);
  ChildProcess daemon;
  // The daemon's clock at the end of the history.
  ASSERT_TRUE(StartDaemon(&daemon, "dash",
                          {"--speed", "60", "--sim-start", std::to_string(kMorning),
                           "--wall-anchor", std::to_string(WallNowS())}));
  // Calibrated at once (two days), a forecast issued, the day's checks done
  // (after the refit, which takes seconds under the sanitizers: the first
  // forecast, from the start values, comes before), everything uploaded.
  ASSERT_TRUE(WaitFor(90, [&] {
    RawDb db(Db("dash"));
    return db.Number("SELECT count(*) FROM forecast") > 0 &&
           db.Number("SELECT count(*) FROM performance_daily") > 0 && Pending("dash") == 0 &&
           Central("SELECT count(*) FROM forecast") > 0 &&
           Central("SELECT count(*) FROM performance_daily") > 0;
  })) << Log("dash");
  EXPECT_EQ(daemon.Stop(SIGTERM, 10.0), 0) << Log("dash");
  const std::int64_t from = kMorning - 2 * 86400;
  const std::int64_t to = kMorning + 2 * 86400;

  const auto store = nlohmann::json::parse(
      ReadFile(fs::path(PVTWIN_SOURCE_DIR) / "doc" / "grafana" / "pvtwin-plant-sqlite.json"));
  int queries = 0;
  RawDb db(Db("dash"));
  for (const auto& panel : store.at("panels")) {
    for (const auto& target : panel.at("targets")) {
      const std::string sql = FillMacros(target.at("rawQueryText"), from, to);
      const auto rows = db.Rows(sql);  // fails the test when it does not prepare
      ++queries;
      const std::string title = panel.at("title");
      if (title.starts_with("Electrical power") || title.starts_with("Events")) {
        EXPECT_FALSE(rows.empty()) << title << ": " << sql;
      }
    }
  }
  EXPECT_GE(queries, 8);

  const auto fleet = nlohmann::json::parse(
      ReadFile(fs::path(PVTWIN_SOURCE_DIR) / "doc" / "grafana" / "pvtwin-fleet-postgresql.json"));
  queries = 0;
  for (const auto& variable : fleet.at("templating").at("list")) {
    const auto rows = pg_.Query(variable.at("query"), "fleet");
    ASSERT_FALSE(rows.empty());
    EXPECT_FALSE(rows[0][0].starts_with("ERROR")) << rows[0][0];
    EXPECT_EQ(rows[0][0], "dash");
  }
  for (const auto& panel : fleet.at("panels")) {
    for (const auto& target : panel.at("targets")) {
      const std::string sql = FillMacros(target.at("rawSql"), from, to);
      const auto rows = pg_.Query(sql, "fleet");
      ++queries;
      ASSERT_FALSE(rows.empty()) << panel.at("title") << ": " << sql;
      EXPECT_FALSE(rows[0][0].starts_with("ERROR")) << sql << ": " << rows[0][0];
    }
  }
  EXPECT_GE(queries, 6);
  // The central event view holds the calibration the store's does.
  EXPECT_GE(Central("SELECT count(*) FROM event WHERE plant_id = 'dash' AND kind LIKE "
                    "'calibration_%'"),
            1);
}

// The central forecast_skill view scores as the store's view does: with one
// issue made before the day began, its row of the day equals the store's,
// column for column. A later issue of some minutes replaces the earlier one
// in the central forecast (the newest issue of each ts) but, made during
// the day, is no day-ahead forecast: forecast_day_ahead keeps the earlier
// one, and the row still equals the store's.
TEST_F(Upload, TheCentralForecastSkillViewScoresAsTheStoresView) {
  WritePlant("skill", "");
  const std::int64_t day = kMorning - 8 * 3600;  // 00:00 UTC
  Import("skill", day, 1, 60, 3);
  const std::string d = std::to_string(day);
  {
    RawDb db(Db("skill"));
    // A day-ahead issue at 00:00 UTC: forecast, band and reference made
    // from the measurement, so that every column has a value.
    ASSERT_EQ(db.Exec("INSERT INTO forecast(issued_at, ts, p_el_w, q_th_w, p_el_w_p10, p_el_w_p90, "
                      "q_th_w_p10, q_th_w_p90, p_el_w_ref, q_th_w_ref) SELECT " +
                      d +
                      ", ts, p_el_w * 1.1 + 5, q_th_w * 0.9 - 3, p_el_w * 1.1 - 15, "
                      "p_el_w * 1.1 + 8, q_th_w * 0.9 - 40, q_th_w * 0.9 + 2, p_el_w * 0.7, "
                      "q_th_w * 0.6 + 10 FROM measurement_1min WHERE ts >= " +
                      d + " AND ts < " + d + " + 86400"),
              SQLITE_OK);
  }
  auto run = UploadOnce("skill");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const char* kColumns =
      "day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, skill_p_el, skill_q_th, "
      "coverage_p10_p90, minutes, coverage_p_el, coverage_q_th";
  const auto expect_equal_rows = [&](const std::string& what) {
    const auto local = LocalRows(
        Db("skill"), std::string("SELECT ") + kColumns + " FROM forecast_skill ORDER BY day");
    const auto central = pg_.Query(std::string("SELECT ") + kColumns +
                                       " FROM forecast_skill WHERE plant_id = 'skill' ORDER BY day",
                                   "fleet");
    ASSERT_EQ(local.size(), 1u) << what;
    ASSERT_EQ(central.size(), 1u) << what << ": " << (central.empty() ? "" : central[0][0]);
    for (std::size_t c = 0; c < local[0].size(); ++c) {
      ASSERT_NE(local[0][c].type, SQLITE_NULL) << what << ": local column " << c << " is NULL";
      const double x =
          local[0][c].type == SQLITE_INTEGER ? static_cast<double>(local[0][c].i) : local[0][c].x;
      EXPECT_NEAR(std::strtod(central[0][c].c_str(), nullptr), x, 1e-9 * (1.0 + std::fabs(x)))
          << what << ": column " << c << " central " << central[0][c];
    }
  };
  expect_equal_rows("one day-ahead issue");
  EXPECT_EQ(Central("SELECT minutes FROM forecast_skill WHERE plant_id = 'skill'"), 1440);

  // An issue at 12:00 for the afternoon's 600 minutes.
  const std::string noon = std::to_string(day + 12 * 3600);
  {
    RawDb db(Db("skill"));
    ASSERT_EQ(db.Exec("INSERT INTO forecast(issued_at, ts, p_el_w, q_th_w) SELECT " + noon +
                      ", ts, p_el_w, q_th_w FROM measurement_1min WHERE ts >= " + noon +
                      " AND ts < " + noon + " + 600 * 60"),
              SQLITE_OK);
    EXPECT_EQ(db.Number("SELECT minutes FROM forecast_skill"), 1440.0);
  }
  run = UploadOnce("skill");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // The day-ahead issue stays in forecast_day_ahead: still the store's row.
  EXPECT_EQ(Central("SELECT count(*) FROM forecast WHERE issued_at = " + noon), 600);
  expect_equal_rows("an intra-day issue after the day-ahead one");
}

}  // namespace
}  // namespace pvtwin
