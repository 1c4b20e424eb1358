// End to end through real processes: `pvtwin sim` serving the example plant
// over Modbus TCP on loopback, `pvtwin run` polling it into a real SQLite
// file, both on one accelerated clock (120 simulated seconds per second).
// The history comes from `pvtwin sim --export` through `pvtwin import`.
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <thread>

#include "config/config_edit.h"
#include "core/common/clock.h"
#include "io/platform/child_process.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/stop_timeout.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::RunPvtwin;
using testing::ScratchDir;
using testing::UnitStopTimeoutS;

using testing::kExamplePlantConfig;
constexpr double kSpeed = 120.0;
// 2024-06-01 08:00 UTC: a June morning at the example plant (47° N, 16° E).
constexpr std::int64_t kMorning = 1717228800;
// 2024-06-01 23:40 UTC: forecast_skill scores a day with the newest forecast
// issued before it began, so the run crosses midnight.
constexpr std::int64_t kBeforeMidnight = 1717285200;

// One connection to the daemon's database, as a dashboard would hold it.
class E2eDb {
 public:
  explicit E2eDb(const fs::path& path) {
    sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE, nullptr);
    sqlite3_busy_timeout(db_, 5000);
  }
  ~E2eDb() { sqlite3_close(db_); }
  // First column of the first row as text ("" when there is none).
  std::string Text(const std::string& sql) const {
    sqlite3_stmt* st = nullptr;
    std::string result;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &st, nullptr) == SQLITE_OK &&
        sqlite3_step(st) == SQLITE_ROW && sqlite3_column_text(st, 0) != nullptr) {
      result = reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
    }
    sqlite3_finalize(st);
    return result;
  }
  long long Count(const std::string& sql) const {
    const std::string t = Text(sql);
    return t.empty() ? -1 : std::stoll(t);
  }
  void Exec(const std::string& sql) const {
    sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr);
  }

 private:
  sqlite3* db_ = nullptr;
};

class DaemonE2E : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(kExamplePlantConfig)) << kExamplePlantConfig;
    fs::copy_file(kExamplePlantConfig, dir_ / "sim.toml");
    const std::string truth = truth_variant_.empty() ? "" : " --truth-variant " + truth_variant_;
    if (history_days_ > 0) {
      const auto exported = RunPvtwin(
          dir_.path(), "sim --config sim.toml --export history.csv --days " +
                           std::to_string(history_days_) + " --step 60 --start " +
                           std::to_string(t0_ - history_days_ * 86400) + truth);
      ASSERT_EQ(exported.exit_code, 0) << exported.err;
      const auto imported =
          RunPvtwin(dir_.path(), "import --config sim.toml --csv history.csv --db " + E2eDb());
      ASSERT_EQ(imported.exit_code, 0) << imported.err;
    }
    anchor_ = WallNowS();
    std::string error;
    std::vector<std::string> sim_args = {PVTWIN_BINARY,
                                         "sim",
                                         "--config",
                                         (dir_ / "sim.toml").string(),
                                         "--ephemeral-ports",
                                         "--speed",
                                         std::to_string(speed_),
                                         "--start",
                                         std::to_string(t0_),
                                         "--wall-anchor",
                                         std::to_string(anchor_)};
    if (!truth_variant_.empty())
      sim_args.insert(sim_args.end(), {"--truth-variant", truth_variant_});
    for (const std::string& f : faults_) sim_args.insert(sim_args.end(), {"--fault", f});
    ASSERT_TRUE(sim_.StartPiped(sim_args, (dir_ / "sim.log").string(), &error)) << error;
    std::vector<std::string> lines;
    ASSERT_TRUE(sim_.ReadUntil("ready", 20.0, &lines)) << ReadFile(dir_ / "sim.log");
    settings_.db_path = E2eDb();
    DaemonSettings& settings = settings_;
    std::string text;
    ASSERT_TRUE(EditConfig(ReadFile(kExamplePlantConfig), ParseListeningLines(lines), settings,
                           &text, &error))
        << error;
    std::ofstream(dir_ / "pvtwin.toml") << text;
  }
  void TearDown() override {
    daemon_.Stop(SIGTERM, UnitStopTimeoutS() / 2);
    sim_.SendLine("quit");
    sim_.Stop(0, 5.0);
  }

  std::string E2eDb() const { return (dir_ / "pvtwin.db").string(); }

  // exe: the pvtwin binary to run (a copy, to delete under the running daemon).
  void StartDaemon(const std::string& exe = PVTWIN_BINARY) {
    std::string error;
    ASSERT_TRUE(daemon_.Start({exe, "run", "--config", (dir_ / "pvtwin.toml").string(),
                               "--speed", std::to_string(speed_), "--sim-start",
                               std::to_string(t0_), "--wall-anchor", std::to_string(anchor_)},
                              (dir_ / "daemon.log").string(), &error))
        << error;
  }

  // Polls `done` every 100 ms for at most timeout_s of wall time.
  bool WaitFor(double timeout_s, const std::function<bool()>& done) const {
    const double deadline = WallNowS() + timeout_s;
    while (WallNowS() < deadline) {
      if (done()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return done();
  }
  std::string DaemonLog() const { return ReadFile(dir_ / "daemon.log"); }

  ScratchDir dir_{"e2e"};
  std::int64_t t0_ = kMorning;       // simulated time at which live polling starts
  int history_days_ = 14;            // imported before t0_; 0: a new, empty store
  double speed_ = kSpeed;            // simulated seconds per wall second
  std::string truth_variant_;        // of `pvtwin sim`; empty: its default
  std::vector<std::string> faults_;  // `pvtwin sim --fault` specs
  DaemonSettings settings_;          // of the daemon's config
  double anchor_ = 0.0;
  ChildProcess sim_;
  ChildProcess daemon_;
};

class DaemonE2EOverMidnight : public DaemonE2E {
 protected:
  DaemonE2EOverMidnight() { t0_ = kBeforeMidnight; }
};

TEST_F(DaemonE2EOverMidnight, PollsAggregatesCalibratesForecastsAndScores) {
  StartDaemon();
  const class E2eDb db(E2eDb());
  const std::string live = " WHERE ts >= " + std::to_string(t0_);
  ASSERT_TRUE(WaitFor(60, [&] {
    return db.Count("SELECT count(*) FROM calibration WHERE status = 'accepted'") >= 1;
  })) << DaemonLog();
  // Every parameter of the accepted calibration is a calibration_param row,
  // with the value of its parameters file and the status calibrate prints.
  EXPECT_GE(db.Count("SELECT count(*) FROM parameter_history WHERE accepted = 1"), 10);
  EXPECT_EQ(db.Count("SELECT count(*) FROM parameter_history h JOIN calibration c ON c.id = "
                     "h.calibration_id WHERE h.value IS NOT json_extract(c.params_json, "
                     "'$.params.' || h.name)"),
            0);
  EXPECT_GE(db.Count("SELECT count(*) FROM calibration_param WHERE status = 'identified' AND "
                     "std_error > 0"),
            3);
  // The daily checks after the calibration scored the days of the imported
  // history with the accepted model (the simulator's own plant: near 1).
  // They run after the refit and its forecast, which take 10 s and more
  // under the sanitizers on two loaded cores: the wait is generous, and it
  // ends as soon as the rows are there.
  ASSERT_TRUE(WaitFor(90, [&] {
    return db.Count("SELECT count(*) FROM performance_daily WHERE pi_el IS NOT NULL") >= 7;
  })) << DaemonLog();
  EXPECT_EQ(db.Count("SELECT count(*) FROM performance_daily WHERE pi_el NOT BETWEEN 0.9 AND 1.1"),
            0);
  EXPECT_GE(db.Count("SELECT count(*) FROM event WHERE kind = 'calibration_accepted'"), 1);
  // A full day ahead (the refit's issue may start a minute later and reach
  // a minute further).
  ASSERT_TRUE(WaitFor(30, [&] { return db.Count("SELECT count(*) FROM forecast_latest") >= 1440; }))
      << DaemonLog();
  ASSERT_TRUE(WaitFor(30, [&] {
    return db.Count("SELECT count(*) FROM measurement_1min" + live) >= 5;
  })) << DaemonLog();
  EXPECT_GT(db.Count("SELECT count(*) FROM sample_5s" + live), 50);
  // One row per minute, every minute averaged from the samples of that minute.
  EXPECT_EQ(db.Count("SELECT count(*) FROM measurement_1min" + live + " AND ts % 60 != 0"), 0);
  EXPECT_EQ(db.Count("SELECT count(*) FROM (SELECT issued_at FROM forecast GROUP BY issued_at "
                     "HAVING count(*) != 1440)"),
            0);
  // Two weeks of history: the first fit starts at once, and no forecast
  // from the start values is issued while it runs.
  EXPECT_EQ(db.Count("SELECT count(*) FROM forecast WHERE basis IS NOT 'calibrated' OR "
                     "calibration_id IS NULL"),
            0);
  // The forecast issued before midnight is scored once the new day's
  // measurements exist (20 simulated minutes after the start: 10 s here).
  ASSERT_TRUE(WaitFor(60, [&] { return db.Count("SELECT count(*) FROM forecast_skill") >= 1; }))
      << DaemonLog();
  EXPECT_EQ(daemon_.Stop(SIGTERM, UnitStopTimeoutS() / 2), 0) << DaemonLog();
  EXPECT_NE(DaemonLog().find("stopping"), std::string::npos);
}

// Two simulated nights of the twin watching a plant whose inverter clips
// (the simulator's truth has +pv_clipping, the configured model does not)
// and whose weather station freezes for two hours on the first day: each
// night the daemon calibrates, diagnoses its window and checks the days;
// the diagnosis names the missing effect, the frozen channels are QC
// events, and the operator's `event` view holds all of it.
class DaemonE2ETwoNights : public DaemonE2E {
 protected:
  DaemonE2ETwoNights() {
    t0_ = kFirstNight;
    speed_ = 720.0;  // a simulated day in two minutes
    truth_variant_ = "2N2CrI+wind+transport_delay+pv_clipping";
    // The weather device repeats its last registers from 10:00 to 12:00 UTC.
    faults_ = {"weather:freeze:from=" + std::to_string(kFreezeFrom - kFirstNight) + ":for=7200"};
    settings_.variant = "2N2CrI+wind+transport_delay";
    settings_.poll_period_s = 30;
    settings_.calibrate_at = "02:00";
  }
  // 2024-06-01 23:00 UTC: the first calibration runs at the start, the
  // second at 02:00 UTC of June 3, the second night.
  static constexpr std::int64_t kFirstNight = 1717282800;
  static constexpr std::int64_t kFreezeFrom = kFirstNight + 11 * 3600;  // June 2, 10:00
};

TEST_F(DaemonE2ETwoNights, DiagnosesTheMissingEffectAndRecordsTheFrozenSensor) {
  std::ofstream(dir_ / "pvtwin.toml", std::ios::app) << "\n[diagnosis]\nevery_days = 1\n";
  // The daemon runs from a file that a package upgrade deletes under it once
  // the first calibration is in: the nights after it still start their
  // calibration and diagnosis (the daemon's own image, not the file's path).
  const fs::path exe = dir_ / "pvtwin-upgraded-away";
  fs::copy_file(PVTWIN_BINARY, exe);
  StartDaemon(exe.string());
  const class E2eDb db(E2eDb());
  ASSERT_TRUE(WaitFor(120, [&] {
    return db.Count("SELECT count(*) FROM calibration WHERE status = 'accepted'") >= 1;
  })) << DaemonLog();
  fs::remove(exe);
  ASSERT_TRUE(WaitFor(300, [&] { return db.Count("SELECT count(*) FROM diagnosis") >= 2; }))
      << DaemonLog();
  // Each night's diagnosis names the clipping the configured model lacks.
  EXPECT_EQ(db.Count("SELECT count(*) FROM diagnosis WHERE verdict = 'pv_clipping' AND "
                     "base_variant = '2N2CrI+wind+transport_delay' AND shrink_pct > 20"),
            2)
      << db.Text("SELECT group_concat(verdict || ' ' || shrink_pct, '; ') FROM diagnosis");
  // Each names the accepted calibration whose parameters were in use.
  EXPECT_EQ(db.Count("SELECT count(*) FROM diagnosis d JOIN calibration c ON c.id = "
                     "d.calibration_id WHERE c.accepted = 1"),
            2);
  EXPECT_EQ(db.Count("SELECT count(*) FROM diagnosis WHERE run_at - (SELECT min(run_at) FROM "
                     "diagnosis) >= 23 * 3600"),
            1);
  // Both nights' reports are kept (default keep), named by the UTC date of
  // their run (the row's run_at). The first night's diagnosis starts after
  // the first calibration and its refit, a few simulated minutes before or
  // after midnight depending on how fast this machine runs them (under the
  // sanitizers it was 00:00 of June 2), so the dates come from the rows.
  const std::string first = db.Text("SELECT date(min(run_at), 'unixepoch') FROM diagnosis");
  const std::string second = db.Text("SELECT date(max(run_at), 'unixepoch') FROM diagnosis");
  EXPECT_TRUE(first == "2024-06-01" || first == "2024-06-02") << first;
  EXPECT_EQ(second, "2024-06-03");
  EXPECT_TRUE(fs::exists(dir_ / "reports" / ("diagnosis-" + first + ".html"))) << DaemonLog();
  // (the daemon files the child's report once the child has ended)
  EXPECT_TRUE(WaitFor(30, [&] {
    return fs::exists(dir_ / "reports" / ("diagnosis-" + second + ".html"));
  })) << DaemonLog();
  // The parameter history of every night's calibration (accepted or
  // not), and scored days.
  EXPECT_GE(db.Count("SELECT count(DISTINCT calibration_id) FROM parameter_history"), 3);
  EXPECT_GE(db.Count("SELECT count(*) FROM parameter_history WHERE accepted = 1"), 10);
  EXPECT_GE(db.Count("SELECT count(*) FROM performance_daily WHERE pi_th IS NOT NULL"), 7);
  // The frozen weather station: the poller rejects a device whose every
  // register stands still, so its channels are QC events inside the freeze
  // (missing, or frozen where a stuck value got through), found by the
  // second night's checks.
  const std::string faulty = "kind IN ('frozen', 'missing') AND channel IN ('t_amb_c', 'wind_m_s')";
  ASSERT_TRUE(WaitFor(30, [&] {
    return db.Count("SELECT count(*) FROM qc_event WHERE " + faulty) >= 1;
  })) << DaemonLog();
  const std::string window =
      std::to_string(kFreezeFrom - 600) + " AND " + std::to_string(kFreezeFrom + 7200 + 600);
  EXPECT_GE(db.Count("SELECT count(*) FROM qc_event WHERE " + faulty + " AND start_ts BETWEEN " +
                     window + " AND end_ts BETWEEN " + window),
            2)
      << db.Text(
             "SELECT group_concat(channel || ' ' || kind || ' ' || start_ts || '-' || end_ts, "
             "'; ') FROM qc_event");
  // What the operator reads first.
  for (const char* kind : {"diagnosis", "qc", "calibration_accepted"}) {
    EXPECT_GE(db.Count(std::string("SELECT count(*) FROM event WHERE kind LIKE '") + kind + "%'"),
              1)
        << kind << ": " << db.Text("SELECT group_concat(DISTINCT kind) FROM event");
  }
  EXPECT_EQ(db.Count("SELECT count(*) FROM calibration WHERE status = 'failed'"), 0)
      << db.Text("SELECT group_concat(reason, '; ') FROM calibration WHERE status = 'failed'");
  int code = 0;
  EXPECT_FALSE(daemon_.Finished(&code)) << DaemonLog();
  EXPECT_EQ(daemon_.Stop(SIGTERM, UnitStopTimeoutS() / 2), 0) << DaemonLog();
}

TEST_F(DaemonE2E, KillNineLosesNoCommittedRowAndCorruptsNothing) {
  StartDaemon();
  const std::string live = " WHERE ts >= " + std::to_string(t0_);
  long long samples = 0, minutes = 0;
  {
    const class E2eDb db(E2eDb());
    ASSERT_TRUE(WaitFor(30, [&] {
      return db.Count("SELECT count(*) FROM measurement_1min" + live) >= 3;
    })) << DaemonLog();
    samples = db.Count("SELECT count(*) FROM sample_5s");
    minutes = db.Count("SELECT count(*) FROM measurement_1min");
  }
  ::kill(daemon_.pid(), SIGKILL);
  EXPECT_EQ(daemon_.Stop(0, 5.0), -SIGKILL);
  {
    const class E2eDb db(E2eDb());
    EXPECT_EQ(db.Text("PRAGMA integrity_check"), "ok");
    EXPECT_GE(db.Count("SELECT count(*) FROM sample_5s"), samples);
    EXPECT_GE(db.Count("SELECT count(*) FROM measurement_1min"), minutes);
  }
  StartDaemon();
  const class E2eDb db(E2eDb());
  ASSERT_TRUE(WaitFor(30, [&] {
    return db.Count("SELECT count(*) FROM sample_5s") > samples + 24;
  })) << DaemonLog();
  // No minute is counted twice after the restart.
  EXPECT_EQ(db.Count("SELECT count(*) FROM (SELECT ts FROM measurement_1min GROUP BY ts HAVING "
                     "count(*) > 1)"),
            0);
  EXPECT_EQ(daemon_.Stop(SIGTERM, UnitStopTimeoutS() / 2), 0) << DaemonLog();
  EXPECT_EQ(db.Text("PRAGMA integrity_check"), "ok");
}

TEST_F(DaemonE2E, AReaderHoldingATransactionDoesNotStopIngestion) {
  StartDaemon();
  const class E2eDb reader(E2eDb());
  const class E2eDb observer(E2eDb());
  ASSERT_TRUE(WaitFor(30, [&] { return observer.Count("SELECT count(*) FROM sample_5s") > 0; }))
      << DaemonLog();
  reader.Exec("BEGIN");
  const long long seen = reader.Count("SELECT count(*) FROM sample_5s");
  // While the reader's snapshot stands the daemon goes on writing: 36 more
  // poll periods (3 s of wall time are 360 simulated seconds, 72 periods;
  // under the sanitizers on two loaded cores the daemon has polled half as
  // many, so the wait is generous and ends as soon as the rows are there).
  EXPECT_TRUE(WaitFor(30, [&] {
    return observer.Count("SELECT count(*) FROM sample_5s") > seen + 36;
  })) << DaemonLog();
  EXPECT_EQ(reader.Count("SELECT count(*) FROM sample_5s"), seen);  // its snapshot
  // Live samples carry the simulator's values: irradiance on a June morning.
  EXPECT_GT(observer.Count("SELECT count(*) FROM sample_5s WHERE g_poa_w_m2 > 100 AND ts >= " +
                           std::to_string(t0_)),
            0);
  reader.Exec("COMMIT");
  EXPECT_EQ(daemon_.Stop(SIGTERM, UnitStopTimeoutS() / 2), 0) << DaemonLog();
}

// A new plant: an empty store, the simulator's plant polled live from 08:00
// UTC. Within the first simulated hour the store holds a forecast from the
// start values, banded, flagged basis = 'start_values'; the wait for two days
// of history is one info line, one info event and a state, not a warning per
// hourly attempt (issue 53).
class DaemonE2EDayOne : public DaemonE2E {
 protected:
  DaemonE2EDayOne() {
    history_days_ = 0;
    speed_ = 360.0;  // a simulated hour in 10 s
  }
};

TEST_F(DaemonE2EDayOne, ForecastsFromTheStartValuesAndWaitsWithoutAWarning) {
  StartDaemon();
  // The daemon creates the store: a connection opened before would see none.
  ASSERT_TRUE(WaitFor(30, [&] { return fs::exists(E2eDb()); })) << DaemonLog();
  const class E2eDb db(E2eDb());
  ASSERT_TRUE(WaitFor(60, [&] {
    return db.Count("SELECT count(*) FROM forecast WHERE basis = 'start_values'") >= 1440;
  })) << DaemonLog();
  EXPECT_LT(db.Count("SELECT min(issued_at) FROM forecast"), t0_ + 3600) << DaemonLog();
  EXPECT_EQ(db.Count("SELECT count(*) FROM forecast WHERE basis IS NOT 'start_values' OR "
                     "calibration_id IS NOT NULL"),
            0);
  EXPECT_EQ(db.Count("SELECT count(*) FROM forecast_latest WHERE basis IS NOT 'start_values'"), 0);
  // Every row's band holds its point, whose median it is; the day's band
  // has a width.
  EXPECT_EQ(db.Count("SELECT count(*) FROM forecast_latest WHERE NOT (p_el_w_p10 <= p_el_w AND "
                     "p_el_w <= p_el_w_p90 AND q_th_w_p10 <= q_th_w AND q_th_w <= q_th_w_p90 AND "
                     "p_el_w_p50 = p_el_w AND q_th_w_p50 = q_th_w)"),
            0);
  EXPECT_GT(db.Count("SELECT count(*) FROM forecast_latest WHERE p_el_w_p90 > p_el_w_p10 + 1"), 300);
  EXPECT_NE(db.Text("SELECT inputs FROM forecast LIMIT 1").find("start values (Table 3"),
            std::string::npos);
  // Two hourly attempts: both recorded, the second with the history grown.
  ASSERT_TRUE(WaitFor(60, [&] {
    return db.Count("SELECT count(*) FROM calibration WHERE status = 'skipped'") >= 2;
  })) << DaemonLog();
  EXPECT_EQ(db.Count("SELECT count(*) FROM calibration WHERE status != 'skipped' OR reason NOT "
                     "LIKE 'waiting for history: % h of 48 h%'"),
            0)
      << db.Text("SELECT group_concat(reason, ' | ') FROM calibration");
  EXPECT_NE(db.Text("SELECT reason FROM calibration ORDER BY id DESC LIMIT 1")
                .rfind("waiting for history: 0.0 h", 0),
            0u);
  EXPECT_EQ(db.Count("SELECT count(*) FROM event WHERE severity != 'info'"), 0)
      << db.Text("SELECT group_concat(message, ' | ') FROM event");
  EXPECT_EQ(db.Count("SELECT count(*) FROM event WHERE kind = 'calibration_waiting'"), 1);
  EXPECT_EQ(daemon_.Stop(SIGTERM, UnitStopTimeoutS() / 2), 0) << DaemonLog();
  const std::string log = DaemonLog();
  EXPECT_EQ(log.find(" warning: "), std::string::npos) << log;
  std::size_t announced = 0;
  for (std::size_t at = log.find("info: waiting for history"); at != std::string::npos;
       at = log.find("info: waiting for history", at + 1)) {
    ++announced;
  }
  EXPECT_EQ(announced, 1u) << log;
}

// The second day's end: 47.5 h of history at the start, so the first
// attempt waits and the start values forecast; an hour later the first fit
// is accepted and the forecasts are calibrated from then on.
class DaemonE2EDayTwo : public DaemonE2E {
 protected:
  DaemonE2EDayTwo() {
    history_days_ = 2;
    speed_ = 360.0;
  }
};

TEST_F(DaemonE2EDayTwo, TheFirstAcceptedCalibrationTurnsTheForecastsCalibrated) {
  {
    const class E2eDb setup(E2eDb());
    setup.Exec("DELETE FROM measurement_1min WHERE ts < " + std::to_string(t0_ - 171000));
  }
  StartDaemon();
  const class E2eDb db(E2eDb());
  ASSERT_TRUE(WaitFor(120, [&] {
    return db.Count("SELECT count(*) FROM forecast WHERE basis = 'calibrated'") >= 1440;
  })) << DaemonLog();
  const std::string accepted_at =
      db.Text("SELECT run_at FROM calibration WHERE status = 'accepted' ORDER BY id LIMIT 1");
  ASSERT_FALSE(accepted_at.empty()) << DaemonLog();
  EXPECT_GE(db.Count("SELECT count(*) FROM forecast WHERE basis = 'start_values' AND issued_at < " +
                     accepted_at),
            1440)
      << DaemonLog();
  // The fit runs for simulated minutes; the first calibrated issue follows
  // it, and no forecast from the start values comes after.
  const std::string first_calibrated =
      db.Text("SELECT min(issued_at) FROM forecast WHERE basis = 'calibrated'");
  EXPECT_EQ(db.Count("SELECT count(*) FROM forecast WHERE basis = 'start_values' AND issued_at >= " +
                     first_calibrated),
            0);
  EXPECT_EQ(db.Count("SELECT count(*) FROM forecast f WHERE basis = 'calibrated' AND "
                     "calibration_id IS NOT (SELECT id FROM calibration WHERE accepted = 1 ORDER "
                     "BY id LIMIT 1)"),
            0);
  EXPECT_EQ(db.Count("SELECT count(*) FROM forecast_latest WHERE ts >= " + first_calibrated +
                     " AND basis IS NOT 'calibrated'"),
            0);
  EXPECT_EQ(db.Count("SELECT count(*) FROM event WHERE kind = 'calibration_skipped'"), 0);
  EXPECT_EQ(daemon_.Stop(SIGTERM, UnitStopTimeoutS() / 2), 0) << DaemonLog();
}

}  // namespace
}  // namespace pvtwin
