// pvtwin import and export as real processes on real files: 5 s and 1-min
// CSV, idempotent re-import of overlapping data, --db, progress, errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/common/units.h"
#include "io/files/csv.h"
#include "io/platform/time_format.h"
#include "io/store/store.h"
#include "tests/support/fixtures.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/sqlite_db.h"

namespace pvtwin {
namespace {

using testing::ProcessResult;
using testing::RawDb;
using testing::RunPvtwin;

using testing::kJune1Noon2024UtcS;

// rows at step_s from t0; p_el_w = 100 + i for row i (i counted from
// kJune1Noon2024UtcS in steps of step_s), so minute means are known by hand.
Series MinuteRows(std::int64_t t0, std::size_t n, double step_s) {
  Series s;
  s.step_s = step_s;
  for (std::size_t i = 0; i < n; ++i) {
    s.time_s.push_back(t0 + static_cast<std::int64_t>(static_cast<double>(i) * step_s));
  }
  auto fill = [&s, n](Channel c, double v) { s[c].assign(n, v); };
  fill(Channel::kTInC, 20.0);
  fill(Channel::kTOutC, 30.0);
  fill(Channel::kMdotKgS, 0.02);
  fill(Channel::kGPoaWM2, 800.0);
  fill(Channel::kTAmbC, 18.0);
  fill(Channel::kAoiRad, DegToRad(40.0));
  std::vector<double>& p = s.Ensure(Channel::kPElW);
  for (std::size_t i = 0; i < n; ++i) {
    p[i] = 100.0 + static_cast<double>(s.time_s[i] - kJune1Noon2024UtcS) / step_s;
  }
  return s;
}

const Channel kWritten[] = {Channel::kTInC,  Channel::kTOutC,  Channel::kMdotKgS, Channel::kGPoaWM2,
                            Channel::kTAmbC, Channel::kAoiRad, Channel::kPElW};

class StoreCli : public testing::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    std::ofstream(dir_ / "pvtwin.toml")
        << "[plant]\nlatitude_deg = 47.358\nlongitude_deg = 16.128\ntilt_deg = 20\n"
           "azimuth_deg = 180\narea_m2 = 1.8\nfluid_cp_j_kgk = 3600\n"
           "[storage]\npath = \""
        << (dir_ / "configured.db").string() << "\"\n";
  }
  void WriteRows(const std::string& name, const Series& s) {
    std::string error;
    ASSERT_TRUE(WriteCsv((dir_ / name).string(), s, kWritten, &error)) << error;
  }
  ProcessResult Pvtwin(const std::string& args) {
    return RunPvtwin(dir_, args + " --config pvtwin.toml");
  }
};

TEST_F(StoreCli, FiveSecondImportAggregatesAndReimportingOverlapsChangesNothing) {
  WriteRows("a.csv", MinuteRows(kJune1Noon2024UtcS, 36, 5.0));        // minutes 0, 1, 2
  WriteRows("b.csv", MinuteRows(kJune1Noon2024UtcS + 120, 24, 5.0));  // minutes 2, 3
  ProcessResult run = Pvtwin("import --csv a.csv --db t.db");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("imported 36 samples"), std::string::npos) << run.err;
  RawDb db(dir_ / "t.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s"), 36.0);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 3.0);
  // Minute 1 holds p_el_w = 112 … 123: mean 117.5 W.
  const std::string minute1 = std::to_string(kJune1Noon2024UtcS + 60);
  EXPECT_EQ(db.Number("SELECT p_el_w FROM measurement_1min WHERE ts = " + minute1), 117.5);
  // Q_u = 0.02 kg/s · 3600 J/(kg·K) (the config's c_p) · 10 K = 720 W.
  EXPECT_NEAR(db.Number("SELECT q_th_w FROM measurement_1min WHERE ts = " + minute1), 720.0, 1e-9);
  EXPECT_NEAR(db.Number("SELECT aoi_deg FROM sample_5s LIMIT 1"), 40.0, 1e-9);

  for (const char* csv : {"a.csv", "b.csv", "a.csv", "b.csv"}) {
    run = Pvtwin(std::string("import --csv ") + csv + " --db t.db");
    ASSERT_EQ(run.exit_code, 0) << run.err;
  }
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s"), 48.0);
  EXPECT_EQ(db.Rows("SELECT ts - " + std::to_string(kJune1Noon2024UtcS) +
                    ", n_samples, p_el_w FROM measurement_1min ORDER BY ts"),
            (std::vector<std::vector<std::string>>{{"0", "12", "105.5"},
                                                   {"60", "12", "117.5"},
                                                   {"120", "12", "129.5"},
                                                   {"180", "12", "141.5"}}));
}

TEST_F(StoreCli, OneMinuteImportExportsBackToTheSameCsvValues) {
  Series minutes = MinuteRows(kJune1Noon2024UtcS + 1, 5, 60.0);  // a logger writing hh:mm:01
  WriteRows("m.csv", minutes);
  ProcessResult run = Pvtwin("import --csv m.csv --db t.db");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("5 rows not at a minute start were moved"), std::string::npos) << run.err;
  run = Pvtwin("import --csv m.csv --db t.db");  // idempotent
  ASSERT_EQ(run.exit_code, 0) << run.err;
  RawDb db(dir_ / "t.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 5.0);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s"), 0.0);
  EXPECT_EQ(db.Number("SELECT MIN(ts) FROM measurement_1min"),
            static_cast<double>(kJune1Noon2024UtcS));

  run = Pvtwin("export --db t.db --from 2024-06-01T12:01:00Z --to " +
               std::to_string(kJune1Noon2024UtcS + 240) + " --out e.csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  Series back;
  Diagnostics errors;
  ASSERT_TRUE(ReadCanonicalCsv((dir_ / "e.csv").string(), {}, &back, &errors, nullptr))
      << (errors.empty() ? "" : errors[0].ToString());
  ASSERT_EQ(back.size(), 3u);  // [12:01, 12:04)
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.time_s[i], kJune1Noon2024UtcS + 60 * static_cast<std::int64_t>(i + 1));
    for (const Channel c : kWritten) {
      EXPECT_NEAR(back[c][i], minutes[c][i + 1], 1e-12) << ChannelName(c);
    }
  }
}

// A disk that fills up during the export (a file size limit, with SIGXFSZ
// ignored so that the write fails with EFBIG as on a full disk): exit 1, and
// neither a truncated e.csv nor the partial file is left behind.
TEST_F(StoreCli, ExportToAFullDiskLeavesNoPartialFile) {
  WriteRows("m.csv", MinuteRows(kJune1Noon2024UtcS, 5000, 60.0));  // about 400 kB as CSV
  ASSERT_EQ(Pvtwin("import --csv m.csv --db t.db").exit_code, 0);
  const ProcessResult run =
      testing::RunCommand(dir_, "trap '' XFSZ; ulimit -f 128; '" + std::string(PVTWIN_BINARY) +
                                    "' export --db t.db --out e.csv --from 2024-01-01T00:00:00Z "
                                    "--to 2025-01-01T00:00:00Z --config pvtwin.toml");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("cannot write"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "e.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "e.csv.partial"));
}

// After its rows are stored, import materialises forecast_skill again for
// the closed days they changed (store schema 11): here the day a forecast
// written by another program had made dirty.
TEST_F(StoreCli, ImportMaterialisesTheForecastSkillOfTheDaysItChanged) {
  WriteRows("m.csv", MinuteRows(kJune1Noon2024UtcS, 360, 60.0));  // 12:00 to 18:00 of 2024-06-01
  ASSERT_EQ(Pvtwin("import --csv m.csv --db t.db").exit_code, 0);
  RawDb db(dir_ / "t.db");
  const std::int64_t day = kJune1Noon2024UtcS - 12 * 3600;
  EXPECT_GT(db.Number("SELECT done_before FROM forecast_skill_state"), static_cast<double>(day))
      << "the day is over, and materialised (without a score: no forecast yet)";
  ASSERT_EQ(db.Exec("WITH RECURSIVE t(ts) AS (SELECT " + std::to_string(kJune1Noon2024UtcS) +
                    " UNION ALL SELECT ts + 60 FROM t WHERE ts + 60 < " +
                    std::to_string(kJune1Noon2024UtcS + 360 * 60) +
                    ") INSERT INTO forecast(issued_at, ts, p_el_w) SELECT " +
                    std::to_string(day - 3600) + ", ts, 150 FROM t"),
            SQLITE_OK);
  EXPECT_EQ(db.Rows("SELECT day FROM forecast_skill_dirty"),
            (std::vector<std::vector<std::string>>{{std::to_string(day)}}));
  EXPECT_EQ(db.Number("SELECT minutes FROM forecast_skill"), 360.0) << "computed live";
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_day"), 0.0);
  ASSERT_EQ(Pvtwin("import --csv m.csv --db t.db").exit_code, 0);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_dirty"), 0.0);
  EXPECT_EQ(db.Rows("SELECT * FROM forecast_skill_day"), db.Rows("SELECT * FROM forecast_skill"));
  // p_el_w = 100 … 459 W against 150 W: MAE = mean |150 − p|.
  double mae_w = 0.0;
  for (int i = 0; i < 360; ++i) mae_w += std::abs(150.0 - (100.0 + i)) / 360.0;
  EXPECT_NEAR(db.Number("SELECT mae_p_el_w FROM forecast_skill_day"), mae_w, 1e-9);
}

TEST_F(StoreCli, FiveSecondTableExportsTheRawSamples) {
  WriteRows("a.csv", MinuteRows(kJune1Noon2024UtcS, 24, 5.0));
  ASSERT_EQ(Pvtwin("import --csv a.csv --db t.db").exit_code, 0);
  const ProcessResult run =
      Pvtwin("export --db t.db --table 5s --from " + std::to_string(kJune1Noon2024UtcS) + " --to " +
             std::to_string(kJune1Noon2024UtcS + 60));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream csv(run.out);
  Series back;
  Diagnostics errors;
  ASSERT_TRUE(ParseCanonicalCsv(csv, "stdout", {}, &back, &errors, nullptr));
  ASSERT_EQ(back.size(), 12u);
  EXPECT_EQ(back.step_s, 5.0);
  EXPECT_EQ(back[Channel::kPElW][11], 111.0);
}

TEST_F(StoreCli, WithoutDbTheConfiguredPathIsUsed) {
  WriteRows("a.csv", MinuteRows(kJune1Noon2024UtcS, 12, 5.0));
  ASSERT_EQ(Pvtwin("import --csv a.csv").exit_code, 0);
  RawDb db(dir_ / "configured.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 1.0);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "t.db"));
}

// export needs no config when --db names the store, and takes a date or a
// time relative to now; the 5 s table's period then comes from the samples.
TEST_F(StoreCli, ExportWithOnlyTheDbADateAndARelativeTime) {
  WriteRows("a.csv", MinuteRows(kJune1Noon2024UtcS, 36, 5.0));  // three minutes of 5 s samples
  ASSERT_EQ(Pvtwin("import --csv a.csv --db t.db").exit_code, 0);
  const std::string day = FormatIsoUtc(kJune1Noon2024UtcS).substr(0, 10);  // YYYY-MM-DD
  ProcessResult run = RunPvtwin(dir_, "export --db t.db --from " + day + " --out m.csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("exported 3 rows of measurement_1min"), std::string::npos) << run.err;
  run = RunPvtwin(dir_, "export --db t.db --table 5s --from " + day + " --to now --out s.csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("exported 36 rows of sample_5s"), std::string::npos) << run.err;
  // Relative to now: the data lie years back, so the last day holds none.
  run = RunPvtwin(dir_, "export --db t.db --from -1d --out none.csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("exported 0 rows"), std::string::npos) << run.err;
  run = RunPvtwin(dir_, "export --from -1d");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("give --db"), std::string::npos) << run.err;
  run = RunPvtwin(dir_, "export --db t.db --from yesterday");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--from = yesterday: expected ISO 8601"), std::string::npos) << run.err;
}

TEST_F(StoreCli, LongImportsReportProgress) {
  WriteRows("days.csv",
            MinuteRows(kJune1Noon2024UtcS, 3 * 17280, 5.0));  // three days of 5 s samples
  const ProcessResult run = Pvtwin("import --csv days.csv --db t.db");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("import: 17280/51840 samples (33 %)"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("import: 51840/51840 samples (100 %)"), std::string::npos) << run.err;
  RawDb db(dir_ / "t.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min WHERE n_samples = 12"), 4320.0);
}

TEST_F(StoreCli, BadInputsExitWithTwoAndSayWhatIsWrong) {
  // 90 s is neither a poll period (a divisor of 60 s) nor whole minutes.
  WriteRows("ninety.csv", MinuteRows(kJune1Noon2024UtcS, 5, 90.0));
  ProcessResult run = Pvtwin("import --csv ninety.csv --db t.db");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("ninety.csv: time step = 90 s"), std::string::npos) << run.err;
  run = Pvtwin("import --csv ninety.csv --db t.db --timezone Mars/Olympus");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--timezone = \"Mars/Olympus\": expected a zone"), std::string::npos)
      << run.err;
  run = Pvtwin("import --csv missing.csv --db t.db");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("missing.csv"), std::string::npos) << run.err;
  run = Pvtwin("export --db nowhere.db --from 0 --to 60");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--db = nowhere.db: no such database"), std::string::npos) << run.err;
  WriteRows("a.csv", MinuteRows(kJune1Noon2024UtcS, 12, 5.0));
  ASSERT_EQ(Pvtwin("import --csv a.csv --db t.db").exit_code, 0);
  run = Pvtwin("export --db t.db --from 2024-06-02T00:00:00Z --to 2024-06-01T00:00:00Z");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--to = 2024-06-01T00:00:00Z: must be later"), std::string::npos)
      << run.err;
  run = Pvtwin("export --db t.db --from yesterday --to 60");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--from = yesterday"), std::string::npos) << run.err;
}

// Data of a coarser logger keep their step: each row of a 2- or 15-min CSV
// is one measurement_interval row with its step_s, nothing is invented in
// measurement_1min, and export --table interval gives the values back.
TEST_F(StoreCli, CoarseLoggerDataAreStoredAtTheirOwnStep) {
  for (const int step_min : {2, 15}) {
    SCOPED_TRACE(step_min);
    const double step_s = 60.0 * step_min;
    const std::string name = std::to_string(step_min) + "min";
    const Series rows = MinuteRows(kJune1Noon2024UtcS, 8, step_s);
    WriteRows(name + ".csv", rows);
    ProcessResult run = Pvtwin("import --csv " + name + ".csv --db " + name + ".db");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find("imported 8 rows of " + std::to_string(step_min) +
                           "-min data into measurement_interval"),
              std::string::npos)
        << run.err;
    ASSERT_EQ(Pvtwin("import --csv " + name + ".csv --db " + name + ".db").exit_code, 0);
    RawDb db(dir_ / (name + ".db"));
    EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_interval"), 8.0);
    EXPECT_EQ(db.Number("SELECT COUNT(DISTINCT step_s) FROM measurement_interval"), 1.0);
    EXPECT_EQ(db.Number("SELECT MIN(step_s) FROM measurement_interval"), step_s);
    EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 0.0);
    EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s"), 0.0);

    run = Pvtwin("export --db " + name +
                 ".db --table interval --from 2024-06-01 --to 2024-06-02 "
                 "--out back.csv");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    Series back;
    Diagnostics errors;
    ASSERT_TRUE(ReadCanonicalCsv((dir_ / "back.csv").string(), {}, &back, &errors, nullptr));
    ASSERT_EQ(back.size(), rows.size());
    EXPECT_EQ(back.step_s, step_s);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      EXPECT_EQ(back.time_s[i], rows.time_s[i]);
      for (const Channel c : kWritten) EXPECT_NEAR(back[c][i], rows[c][i], 1e-12) << ChannelName(c);
    }
  }
}

// Naive local time stamps across the autumn change of Europe/Vienna
// (2024-10-27: 03:00 CEST = 01:00 UTC becomes 02:00 CET, so 02:00–02:59 local
// happen twice). A logger writing local time every 15 min counts 01:45,
// 02:00 … 02:45, 02:00 … 02:45, 03:00: with --timezone the rows are 15 min
// apart in UTC throughout; without it, such a file is refused with its line.
TEST_F(StoreCli, NaiveLocalTimesAreReadInTheGivenZoneAcrossTheAutumnChange) {
  const char* locals[] = {"01:45", "02:00", "02:15", "02:30", "02:45", "02:00",
                          "02:15", "02:30", "02:45", "03:00", "03:15"};
  std::ostringstream csv;
  csv << "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n";
  for (const char* hhmm : locals) csv << "2024-10-27 " << hhmm << ",20,25,0.02,300,10,50\n";
  std::ofstream(dir_ / "local.csv") << csv.str();

  ProcessResult run = Pvtwin("import --csv local.csv --db t.db");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("local.csv:2: time"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("--timezone"), std::string::npos) << run.err;

  run = Pvtwin("import --csv local.csv --db t.db --timezone Europe/Vienna");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  RawDb db(dir_ / "t.db");
  const std::vector<std::vector<std::string>> ts =
      db.Rows("SELECT ts FROM measurement_interval ORDER BY ts");
  ASSERT_EQ(ts.size(), 11u);
  std::int64_t first = 0;
  std::string error;
  ASSERT_TRUE(ParseTime("2024-10-26T23:45:00Z", &first, &error));  // 01:45 CEST
  for (std::size_t i = 0; i < ts.size(); ++i) {
    EXPECT_EQ(std::stoll(ts[i][0]), first + 900 * static_cast<std::int64_t>(i)) << i;
  }

  // The same file read as a logger on standard time all year (+01:00): the
  // repeated quarter hours are now rows out of order, named by line.
  run = Pvtwin("import --csv local.csv --db u.db --timezone +01:00");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("local.csv:7: time"), std::string::npos) << run.err;
}

// The hour the clocks skip in spring (Europe/Vienna, 2024-03-31 02:00 →
// 03:00) holds no instant: a time stamp in it is an error naming the line,
// and the message points to a fixed offset.
TEST_F(StoreCli, ALocalTimeTheClocksSkipIsAnError) {
  std::ofstream(dir_ / "spring.csv") << "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n"
                                        "2024-03-31 01:00,20,25,0.02,300,10,50\n"
                                        "2024-03-31 02:00,20,25,0.02,300,10,50\n";
  const ProcessResult run = Pvtwin("import --csv spring.csv --db t.db --timezone Europe/Vienna");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("spring.csv:3: time"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("does not exist in Europe/Vienna"), std::string::npos) << run.err;
}

// The verbs that only read (export, diagnose --db) open the store read-only:
// a store of an older schema is refused with what to do, never migrated,
// and its file is left byte for byte as it was.
TEST_F(StoreCli, ReadOnlyVerbsRefuseAnOlderSchemaInsteadOfMigratingIt) {
  WriteRows("m.csv", MinuteRows(kJune1Noon2024UtcS, 5, 60.0));
  ASSERT_EQ(Pvtwin("import --csv m.csv --db t.db").exit_code, 0);
  {
    RawDb db(dir_ / "t.db");
    ASSERT_EQ(db.Exec("PRAGMA user_version = 5"), SQLITE_OK);
  }
  const std::string before = testing::ReadFile(dir_ / "t.db");
  const std::string message = "store schema 5 is older than this pvtwin's " +
                              std::to_string(kStoreSchemaVersion) +
                              "; run the daemon or `pvtwin migrate` to upgrade it";
  ProcessResult run = Pvtwin("export --db t.db --from 2024-06-01 --to 2024-06-02");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find(message), std::string::npos) << run.err;
  run = Pvtwin("diagnose --db t.db --from 2024-06-01 --to 2024-06-02");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find(message), std::string::npos) << run.err;
  EXPECT_EQ(testing::ReadFile(dir_ / "t.db"), before) << "the store was written";
  {
    RawDb db(dir_ / "t.db");
    EXPECT_EQ(db.Number("PRAGMA user_version"), 5.0);
  }
}

// `pvtwin migrate`, named by that message, opens the store as the daemon
// does (upgrading it) and says its schema; a current store stays as it is.
TEST_F(StoreCli, MigrateNamesTheSchemaOfTheStore) {
  WriteRows("m.csv", MinuteRows(kJune1Noon2024UtcS, 5, 60.0));
  ASSERT_EQ(Pvtwin("import --csv m.csv --db t.db").exit_code, 0);
  ProcessResult run = Pvtwin("migrate --db t.db");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("t.db: store schema " + std::to_string(kStoreSchemaVersion)),
            std::string::npos)
      << run.out;
  run = RunPvtwin(dir_, "migrate --db none.db");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "none.db"));
}

// A read-only verb never creates a store either.
TEST_F(StoreCli, ReadOnlyVerbsNeverCreateAStore) {
  const ProcessResult run = RunPvtwin(dir_, "export --db none.db --from 2024-06-01");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "none.db"));
}

// A reader without write access (uid/gid 65534, as a member of the store's
// group would be) exports from a store in a directory it cannot write: with
// the daemon's connection open (mode=ro through the existing -wal and -shm,
// readable to it) and after the daemon closed it (no -wal, no -shm: the file
// alone, immutable). As root only: setpriv acts as the other user.
TEST_F(StoreCli, AReaderWithoutWriteAccessExportsWithAndWithoutTheDaemon) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to act as another user (setpriv)";
  WriteRows("m.csv", MinuteRows(kJune1Noon2024UtcS, 5, 60.0));
  ASSERT_EQ(Pvtwin("import --csv m.csv --db t.db").exit_code, 0);
  std::filesystem::permissions(dir_, std::filesystem::perms(0755));
  const std::string as_reader = "setpriv --reuid=65534 --regid=65534 --clear-groups '" +
                                std::string(PVTWIN_BINARY) +
                                "' export --db t.db --from 2024-06-01 --to 2024-06-02";
  // The daemon's connection stands open: -wal and -shm exist, 0644.
  {
    RawDb daemon(dir_ / "t.db");
    ASSERT_EQ(daemon.Number("SELECT COUNT(*) FROM measurement_1min"), 5.0);
    ASSERT_TRUE(std::filesystem::exists(dir_ / "t.db-shm"));
    const ProcessResult run = testing::RunCommand(dir_, as_reader);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.out.find("2024-06-01T12:04:00Z"), std::string::npos) << run.out;
  }
  // Closed: SQLite removed -wal and -shm, and the reader cannot create them.
  ASSERT_FALSE(std::filesystem::exists(dir_ / "t.db-shm"));
  const ProcessResult run = testing::RunCommand(dir_, as_reader);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("2024-06-01T12:04:00Z"), std::string::npos) << run.out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "t.db-shm"));
}

}  // namespace
}  // namespace pvtwin
