// Interval data through the store (issue 53): rows of a 2-, 10- or 15-min
// logger that `pvtwin import` put into measurement_interval are read at their
// own step by the window reader of the daemon's jobs
// (daemon/service/window_data.h) and by `pvtwin diagnose --db`, whose
// --record also puts their sensor faults into qc_event. Real data: the two
// htw saar days (tests/data/htwsaar-pvt/PROVENANCE.md, 2-min steps), whose
// pyrgeometer puts the sky 14–17 K above the air in full sun.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "config/plant_config.h"
#include "core/model/variant.h"
#include "daemon/service/monitor.h"
#include "daemon/service/window_data.h"
#include "io/store/store.h"
#include "tests/support/fixtures.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/sqlite_db.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using testing::ProcessResult;
using testing::RawDb;
using testing::RunPvtwin;

using testing::kHtwSaarDir;
// The htw saar days: day 3 is 2017-07-25, day 1 2017-08-07 (UTC).
const std::string kWindow = " --from 2017-07-25 --to 2017-08-08";

std::string Data(const std::string& name) { return "'" + (kHtwSaarDir / name).string() + "'"; }

// n rows of step_s from t0 with a P_el of `p_el_w`.
Series Flat(std::int64_t t0, std::size_t n, double step_s, double p_el_w) {
  Series s;
  s.step_s = step_s;
  for (std::size_t i = 0; i < n; ++i) {
    s.time_s.push_back(t0 + static_cast<std::int64_t>(i) * static_cast<std::int64_t>(step_s));
  }
  s[Channel::kPElW].assign(n, p_el_w);
  s[Channel::kTAmbC].assign(n, 20.0);
  return s;
}

using testing::kJune1Noon2024UtcS;

TEST(WindowData, OneMinuteRowsFirstElseTheIntervalRowsAtTheirStep) {
  const fs::path dir = fs::temp_directory_path() / ("pvtwin_window_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string error;
  std::unique_ptr<Store> store = Store::Open((dir / "t.db").string(), &error);
  ASSERT_TRUE(store) << error;
  // An hour of 2-min rows, and 1-min rows in its second half only.
  ASSERT_TRUE(store->WriteIntervalRows(Flat(kJune1Noon2024UtcS, 30, 120.0, 200.0), &error))
      << error;
  ASSERT_TRUE(store->WriteMinutes(Flat(kJune1Noon2024UtcS + 1800, 30, 60.0, 100.0), &error))
      << error;
  cli::WindowData w;
  ASSERT_TRUE(
      cli::ReadWindowData(*store, kJune1Noon2024UtcS, kJune1Noon2024UtcS + 1800, &w, &error))
      << error;
  EXPECT_EQ(w.source, cli::WindowSource::kIntervals);
  EXPECT_STREQ(w.Table(), "measurement_interval");
  EXPECT_EQ(w.Describe(), "2-min rows of measurement_interval");
  ASSERT_EQ(w.rows.size(), 15u);
  EXPECT_EQ(w.rows.step_s, 120.0);
  EXPECT_EQ(w.rows.At(Channel::kPElW, 0), 200.0);
  // A window with 1-min rows reads those only.
  ASSERT_TRUE(
      cli::ReadWindowData(*store, kJune1Noon2024UtcS, kJune1Noon2024UtcS + 3600, &w, &error))
      << error;
  EXPECT_EQ(w.source, cli::WindowSource::kMinutes);
  ASSERT_EQ(w.rows.size(), 30u);
  EXPECT_EQ(w.rows.step_s, 60.0);
  EXPECT_EQ(w.rows.At(Channel::kPElW, 0), 100.0);
  // Neither.
  ASSERT_TRUE(
      cli::ReadWindowData(*store, kJune1Noon2024UtcS - 7200, kJune1Noon2024UtcS, &w, &error))
      << error;
  EXPECT_EQ(w.source, cli::WindowSource::kNone);
  EXPECT_EQ(w.rows.size(), 0u);
  EXPECT_STREQ(w.Table(), "");
  store.reset();
  fs::remove_all(dir);
}

TEST(WindowData, TheModelStepIsAMultipleOfTheDataStep) {
  EXPECT_EQ(cli::StepForData(60.0, 120.0), 120.0);   // finer than the data: the data's
  EXPECT_EQ(cli::StepForData(300.0, 120.0), 120.0);  // no multiple: the data's
  EXPECT_EQ(cli::StepForData(600.0, 120.0), 600.0);  // averaged to it
  EXPECT_EQ(cli::StepForData(120.0, 120.0), 120.0);
  EXPECT_EQ(cli::StepForData(0.0, 600.0), 600.0);  // 0: the data's own
  EXPECT_EQ(cli::StepForData(60.0, 60.0), 60.0);
}

class IntervalStore : public testing::TempDirTest {
 protected:
  // Both htw saar days imported into a fresh store t.db.
  void ImportHtwDays() {
    for (const char* day : {"day3_clear_medium_dT.csv", "day1_clear_low_dT.csv"}) {
      const ProcessResult run = RunPvtwin(
          dir_, "import --config " + Data("plant.toml") + " --csv " + Data(day) + " --db t.db");
      ASSERT_EQ(run.exit_code, 0) << run.err;
      ASSERT_NE(run.err.find("measurement_interval"), std::string::npos) << run.err;
    }
    RawDb db(dir_ / "t.db");
    ASSERT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 0.0);
    ASSERT_GT(db.Number("SELECT COUNT(*) FROM measurement_interval WHERE step_s = 120"), 500.0);
  }
  // `pvtwin diagnose` of the imported days with the paper's model, one day
  // to train and one held out, plus `extra`.
  ProcessResult DiagnoseDb(const std::string& extra) {
    return RunPvtwin(dir_, kDiagnose + " --db t.db" + kWindow + " " + extra);
  }
  const std::string kDiagnose = "diagnose --config " + Data("plant.toml") +
                                " --variant 2N1CcolwrI --train-days 1 --heldout-days 1"
                                " --effects iam --threads 2";
  // The htw saar days in time order as one CSV, as `diagnose --csv` reads them.
  void WriteHtwCsv(const fs::path& csv) {
    std::ofstream out(csv);
    out << testing::ReadFile(kHtwSaarDir / "day3_clear_medium_dT.csv");
    const std::string day1 = testing::ReadFile(kHtwSaarDir / "day1_clear_low_dT.csv");
    out << day1.substr(day1.find('\n') + 1);
  }
};

// Done when of issue 53 item 5: `diagnose --db` runs on the imported days (it
// exited 2, "no measurement_1min rows"), at the data's 2-min step, and finds
// what the same diagnosis of the CSV finds: the rows went through the store
// unchanged.
TEST_F(IntervalStore, DiagnoseDbRunsOnTheImportedHtwSaarDaysAsOnTheirCsv) {
  ImportHtwDays();
  WriteHtwCsv(dir_ / "htw.csv");
  const ProcessResult db_run = DiagnoseDb("--report db");
  ASSERT_EQ(db_run.exit_code, 0) << db_run.err;
  EXPECT_NE(db_run.err.find("2-min rows of measurement_interval"), std::string::npos)
      << db_run.err;
  EXPECT_NE(db_run.out.find("verdict: "), std::string::npos) << db_run.out;
  const ProcessResult csv_run = RunPvtwin(dir_, kDiagnose + " --csv htw.csv --report csv");
  ASSERT_EQ(csv_run.exit_code, 0) << csv_run.err;
  const nlohmann::json db = nlohmann::json::parse(testing::ReadFile(dir_ / "db" / "report.json"));
  const nlohmann::json csv =
      nlohmann::json::parse(testing::ReadFile(dir_ / "csv" / "report.json"));
  EXPECT_EQ(db.at("step_s").get<double>(), 120.0);
  EXPECT_EQ(db.at("verdict"), csv.at("verdict"));
  for (const char* mae : {"mae_p_el_w", "mae_q_th_w"}) {
    const double a = db.at("gap").at(mae).get<double>();
    const double b = csv.at("gap").at(mae).get<double>();
    EXPECT_NEAR(a, b, 1e-6 * b) << mae;
  }
  // The pyrgeometer's fault is a sensor finding of the store's rows too.
  bool sky = false;
  for (const auto& f : db.at("sensors")) {
    sky = sky || (f.at("channel") == "lw_down_w_m2" && f.at("kind") == "sky_warmer_than_air");
  }
  EXPECT_TRUE(sky) << db.at("sensors").dump();
}

// The daemon's nightly diagnosis passes --record and its [calibration]
// step_s (60 s, finer than the rows): the diagnosis runs at 120 s, its row
// goes to the diagnosis table, and the sensor checks of the daily monitor
// put the long-wave channel into qc_event — the only channel they name on
// these days (tests/unit/test_monitoring.cc, SensorFaults.*).
TEST_F(IntervalStore, RecordPutsTheLongWaveChannelIntoQcEvent) {
  ImportHtwDays();
  const ProcessResult run = DiagnoseDb("--step 60 --record --calibration-id 7");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("diagnosing at their step of 120 s"), std::string::npos) << run.err;
  RawDb db(dir_ / "t.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM diagnosis WHERE calibration_id = 7"), 1.0);
  const auto rows = db.Rows("SELECT DISTINCT channel, kind FROM qc_event ORDER BY channel");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0][0], "lw_down_w_m2");
  EXPECT_EQ(rows[0][1], "sky_warmer_than_air");
  // On both days, for hours each, as the daily checks write it.
  EXPECT_GE(db.Number("SELECT COUNT(DISTINCT start_ts / 86400) FROM qc_event"), 2.0);
  EXPECT_GE(db.Number("SELECT SUM(end_ts - start_ts) FROM qc_event"), 4.0 * 3600);
  // The event view shows them to an operator.
  EXPECT_GE(db.Number("SELECT COUNT(*) FROM event WHERE message LIKE '%lw_down_w_m2%'"), 1.0);
  // Recording again adds no second row for the same fault.
  const double n = db.Number("SELECT COUNT(*) FROM qc_event");
  const ProcessResult again = DiagnoseDb("--record");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM qc_event"), n);
}

// Without --record the store is only read: no qc_event rows, no diagnosis.
TEST_F(IntervalStore, WithoutRecordNothingIsWritten) {
  ImportHtwDays();
  const ProcessResult run = DiagnoseDb("");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  RawDb db(dir_ / "t.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM qc_event"), 0.0);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM diagnosis"), 0.0);
}

// The daemon's daily checks (daemon/service/monitor.h) on a store that holds
// the interval rows only, the night after day 1 (2017-08-07): the sensor
// checks of the last two days run on those rows and name the long-wave
// channel in qc_event and the log.
TEST_F(IntervalStore, TheDailyChecksRecordTheLongWaveChannelOfIntervalRows) {
  ImportHtwDays();
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(LoadConfig((kHtwSaarDir / "plant.toml").string(), &config, &errors));
  std::string error;
  std::unique_ptr<Store> store = Store::Open((dir_ / "t.db").string(), &error);
  ASSERT_TRUE(store) << error;
  cli::DailyCheckInputs in;
  in.config = &config;
  ASSERT_TRUE(ParseVariant("2N1CcolwrI", &in.spec, &error)) << error;
  in.now_s = 1502150400;  // 2017-08-08T00:00:00Z
  bool logged = false;
  for (const auto& line : cli::RunDailyChecks(*store, in)) {
    logged = logged || line.second.find("sensor lw_down_w_m2: sky_warmer_than_air") == 0;
  }
  EXPECT_TRUE(logged);
  RawDb db(dir_ / "t.db");
  const auto rows = db.Rows("SELECT DISTINCT channel, kind FROM qc_event");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0][0], "lw_down_w_m2");
  EXPECT_EQ(rows[0][1], "sky_warmer_than_air");
  // Day 1 only: day 3 lies before the two days the check looks at.
  EXPECT_EQ(db.Number("SELECT MIN(start_ts) >= 1502064000 FROM qc_event"), 1.0);
}

// A window with no rows in either table is still bad input, naming both.
TEST_F(IntervalStore, AnEmptyWindowNamesBothTables) {
  ImportHtwDays();
  const ProcessResult run = RunPvtwin(
      dir_, "diagnose --config " + Data("plant.toml") +
                " --db t.db --from 2018-01-01 --to 2018-01-15 --variant 2N1CcolwrI");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("no measurement_1min or measurement_interval rows"), std::string::npos)
      << run.err;
}

}  // namespace
}  // namespace pvtwin
