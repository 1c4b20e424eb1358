// pvtwin import and export as real processes on real files: 5 s and 1-min
// CSV, idempotent re-import of overlapping data, --db, progress, errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/common/units.h"
#include "io/csv.h"
#include "io/time_format.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/sqlite_db.h"

namespace pvtwin {
namespace {

using testing::ProcessResult;
using testing::RawDb;
using testing::RunPvtwin;

constexpr std::int64_t kMinute0 = 1717243200;  // 2024-06-01T12:00:00Z

// rows at step_s from t0; p_el_w = 100 + i for row i (i counted from
// kMinute0 in steps of step_s), so minute means are known by hand.
Series Rows(std::int64_t t0, std::size_t n, double step_s) {
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
    p[i] = 100.0 + static_cast<double>(s.time_s[i] - kMinute0) / step_s;
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
  WriteRows("a.csv", Rows(kMinute0, 36, 5.0));        // minutes 0, 1, 2
  WriteRows("b.csv", Rows(kMinute0 + 120, 24, 5.0));  // minutes 2, 3
  ProcessResult run = Pvtwin("import --csv a.csv --db t.db");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("imported 36 samples"), std::string::npos) << run.err;
  RawDb db(dir_ / "t.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s"), 36.0);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 3.0);
  // Minute 1 holds p_el_w = 112 … 123: mean 117.5 W.
  const std::string minute1 = std::to_string(kMinute0 + 60);
  EXPECT_EQ(db.Number("SELECT p_el_w FROM measurement_1min WHERE ts = " + minute1), 117.5);
  // Q_u = 0.02 kg/s · 3600 J/(kg·K) (the config's c_p) · 10 K = 720 W.
  EXPECT_NEAR(db.Number("SELECT q_th_w FROM measurement_1min WHERE ts = " + minute1), 720.0, 1e-9);
  EXPECT_NEAR(db.Number("SELECT aoi_deg FROM sample_5s LIMIT 1"), 40.0, 1e-9);

  for (const char* csv : {"a.csv", "b.csv", "a.csv", "b.csv"}) {
    run = Pvtwin(std::string("import --csv ") + csv + " --db t.db");
    ASSERT_EQ(run.exit_code, 0) << run.err;
  }
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s"), 48.0);
  EXPECT_EQ(db.Rows("SELECT ts - " + std::to_string(kMinute0) +
                    ", n_samples, p_el_w FROM measurement_1min ORDER BY ts"),
            (std::vector<std::vector<std::string>>{{"0", "12", "105.5"},
                                                   {"60", "12", "117.5"},
                                                   {"120", "12", "129.5"},
                                                   {"180", "12", "141.5"}}));
}

TEST_F(StoreCli, OneMinuteImportExportsBackToTheSameCsvValues) {
  Series minutes = Rows(kMinute0 + 1, 5, 60.0);  // a logger writing hh:mm:01
  WriteRows("m.csv", minutes);
  ProcessResult run = Pvtwin("import --csv m.csv --db t.db");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("5 rows not at a minute start were moved"), std::string::npos) << run.err;
  run = Pvtwin("import --csv m.csv --db t.db");  // idempotent
  ASSERT_EQ(run.exit_code, 0) << run.err;
  RawDb db(dir_ / "t.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 5.0);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s"), 0.0);
  EXPECT_EQ(db.Number("SELECT MIN(ts) FROM measurement_1min"), static_cast<double>(kMinute0));

  run = Pvtwin("export --db t.db --from 2024-06-01T12:01:00Z --to " +
               std::to_string(kMinute0 + 240) + " --out e.csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  Series back;
  Diagnostics errors;
  ASSERT_TRUE(ReadCanonicalCsv((dir_ / "e.csv").string(), {}, &back, &errors, nullptr))
      << (errors.empty() ? "" : errors[0].ToString());
  ASSERT_EQ(back.size(), 3u);  // [12:01, 12:04)
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.time_s[i], kMinute0 + 60 * static_cast<std::int64_t>(i + 1));
    for (const Channel c : kWritten) {
      EXPECT_NEAR(back[c][i], minutes[c][i + 1], 1e-12) << ChannelName(c);
    }
  }
}

// A disk that fills up during the export (a file size limit, with SIGXFSZ
// ignored so that the write fails with EFBIG as on a full disk): exit 1, and
// neither a truncated e.csv nor the partial file is left behind.
TEST_F(StoreCli, ExportToAFullDiskLeavesNoPartialFile) {
  WriteRows("m.csv", Rows(kMinute0, 5000, 60.0));  // about 400 kB as CSV
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

TEST_F(StoreCli, FiveSecondTableExportsTheRawSamples) {
  WriteRows("a.csv", Rows(kMinute0, 24, 5.0));
  ASSERT_EQ(Pvtwin("import --csv a.csv --db t.db").exit_code, 0);
  const ProcessResult run =
      Pvtwin("export --db t.db --table 5s --from " + std::to_string(kMinute0) + " --to " +
             std::to_string(kMinute0 + 60));
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
  WriteRows("a.csv", Rows(kMinute0, 12, 5.0));
  ASSERT_EQ(Pvtwin("import --csv a.csv").exit_code, 0);
  RawDb db(dir_ / "configured.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 1.0);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "t.db"));
}

// export needs no config when --db names the store, and takes a date or a
// time relative to now; the 5 s table's period then comes from the samples.
TEST_F(StoreCli, ExportWithOnlyTheDbADateAndARelativeTime) {
  WriteRows("a.csv", Rows(kMinute0, 36, 5.0));  // three minutes of 5 s samples
  ASSERT_EQ(Pvtwin("import --csv a.csv --db t.db").exit_code, 0);
  const std::string day = FormatIsoUtc(kMinute0).substr(0, 10);  // YYYY-MM-DD
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
  WriteRows("days.csv", Rows(kMinute0, 3 * 17280, 5.0));  // three days of 5 s samples
  const ProcessResult run = Pvtwin("import --csv days.csv --db t.db");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("import: 17280/51840 samples (33 %)"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("import: 51840/51840 samples (100 %)"), std::string::npos) << run.err;
  RawDb db(dir_ / "t.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min WHERE n_samples = 12"), 4320.0);
}

TEST_F(StoreCli, BadInputsExitWithTwoAndSayWhatIsWrong) {
  WriteRows("two_min.csv", Rows(kMinute0, 5, 120.0));
  ProcessResult run = Pvtwin("import --csv two_min.csv --db t.db");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("two_min.csv: time step = 120 s"), std::string::npos) << run.err;
  run = Pvtwin("import --csv missing.csv --db t.db");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("missing.csv"), std::string::npos) << run.err;
  run = Pvtwin("export --db nowhere.db --from 0 --to 60");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--db = nowhere.db: no such database"), std::string::npos) << run.err;
  WriteRows("a.csv", Rows(kMinute0, 12, 5.0));
  ASSERT_EQ(Pvtwin("import --csv a.csv --db t.db").exit_code, 0);
  run = Pvtwin("export --db t.db --from 2024-06-02T00:00:00Z --to 2024-06-01T00:00:00Z");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--to = 2024-06-01T00:00:00Z: must be later"), std::string::npos)
      << run.err;
  run = Pvtwin("export --db t.db --from yesterday --to 60");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--from = yesterday"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace pvtwin
