// The SQLite store on a real database file: schema and views with their
// exact columns, round trips, restart-safe aggregation, retention,
// calibration rows, forecast_latest and forecast_skill against hand-computed
// errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/common/units.h"
#include "io/store/store.h"
#include "tests/support/fixtures.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/store_schema_v10.h"
#include "tests/support/store_schema_v11.h"

namespace pvtwin {
namespace {

using testing::RawDb;

using testing::kJune1_2024UtcS;
using testing::kJune1Noon2024UtcS;

// A sample whose values follow from its time, so reads can be checked.
Sample MakeSample(std::int64_t ts) {
  Sample s;
  s.ts_s = ts;
  const double k = static_cast<double>(ts - kJune1Noon2024UtcS) / 5.0;
  s.Set(Channel::kTInC, 20.0 + 0.01 * k);
  s.Set(Channel::kTOutC, 30.0 + 0.01 * k);
  s.Set(Channel::kMdotKgS, 0.03);
  s.Set(Channel::kGPoaWM2, 600.0 + k);
  s.Set(Channel::kTAmbC, 15.0);
  s.Set(Channel::kPElW, 150.0 + k);
  s.Set(Channel::kAoiRad, DegToRad(30.0));
  return s;
}

std::vector<Sample> MakeSamples(std::int64_t t0, int n) {
  std::vector<Sample> v;
  for (int i = 0; i < n; ++i) v.push_back(MakeSample(t0 + 5 * i));
  return v;
}

class StoreTest : public testing::TempDirTest {
 protected:
  std::string DbPath() const { return (dir_ / "pvtwin.db").string(); }
  std::unique_ptr<Store> OpenStore() {
    std::string error;
    std::unique_ptr<Store> store = Store::Open(DbPath(), &error);
    EXPECT_NE(store, nullptr) << error;
    return store;
  }
};

std::vector<std::string> WithChannels(std::vector<std::string> head,
                                      const std::vector<std::string>& tail) {
  for (const ChannelInfo& info : kChannels) head.emplace_back(info.name);
  head.insert(head.end(), tail.begin(), tail.end());
  return head;
}

TEST_F(StoreTest, SchemaHasTheContractsTablesViewsAndColumns) {
  ASSERT_NE(OpenStore(), nullptr);
  RawDb db(DbPath());
  EXPECT_EQ(db.Number("PRAGMA user_version"), static_cast<double>(kStoreSchemaVersion));
  EXPECT_EQ(db.Rows("PRAGMA journal_mode")[0][0], "wal");
  // sample_5s and measurement_1min: every canonical channel, named as in
  // core/common/channels.h (doc/contracts.md "SQLite").
  EXPECT_EQ(db.Columns("sample_5s"), WithChannels({"ts"}, {"rejected_mask"}));
  EXPECT_EQ(db.Columns("measurement_1min"), WithChannels({"ts"}, {"n_samples", "qc_flags"}));
  EXPECT_EQ(db.Columns("sample_5s")[8], "aoi_deg");
  EXPECT_EQ(db.Columns("calibration"),
            (std::vector<std::string>{"id", "run_at", "variant", "window_start", "window_end",
                                      "status", "mae_p_el_w", "mae_q_th_w", "runtime_s", "n_evals",
                                      "params_json", "reason", "heldout_mae_w", "accepted"}));
  // Version 6 appended the bands and the reference (issue 15), version 8
  // the medians and the coverage per output, version 10 the basis (issue 53).
  EXPECT_EQ(db.Columns("forecast"),
            (std::vector<std::string>{"issued_at", "ts", "calibration_id", "p_el_w", "q_th_w",
                                      "t_pv_c", "t_out_c", "inputs", "p_el_w_p10", "p_el_w_p90",
                                      "q_th_w_p10", "q_th_w_p90", "p_el_w_ref", "q_th_w_ref",
                                      "p_el_w_p50", "q_th_w_p50", "basis"}));
  EXPECT_EQ(db.Columns("forecast_latest"),
            (std::vector<std::string>{"ts", "issued_at", "p_el_w", "q_th_w", "t_pv_c", "t_out_c",
                                      "p_el_w_p10", "p_el_w_p90", "q_th_w_p10", "q_th_w_p90",
                                      "p_el_w_p50", "q_th_w_p50", "basis"}));
  EXPECT_EQ(db.Columns("forecast_skill"),
            (std::vector<std::string>{"day", "mae_p_el_w", "mae_q_th_w", "nmae_p_el", "nmae_q_th",
                                      "skill_p_el", "skill_q_th", "coverage_p10_p90", "minutes",
                                      "coverage_p_el", "coverage_q_th"}));
  EXPECT_EQ(
      db.Columns("weather_forecast"),
      (std::vector<std::string>{"ts", "g_poa_w_m2", "ghi_w_m2", "dhi_w_m2", "g_poa_diffuse_w_m2",
                                "t_amb_c", "wind_m_s", "t_sky_c", "lw_down_w_m2", "source"}));
  // Version 5: the weather rows' source, the plant the store belongs to.
  EXPECT_EQ(db.Columns("plant_config"), (std::vector<std::string>{"key", "value"}));
  EXPECT_EQ(db.Columns("operation_plan"), (std::vector<std::string>{"ts", "t_in_c", "flow_kg_s"}));
  // Version 2: rows of a coarser logger at their own step.
  EXPECT_EQ(db.Columns("measurement_interval"), WithChannels({"ts", "step_s"}, {"qc_flags"}));
  // Primary key of forecast: (issued_at, ts); views are views.
  EXPECT_EQ(db.Rows("SELECT name FROM pragma_table_info('forecast') WHERE pk > 0 ORDER BY pk"),
            (std::vector<std::vector<std::string>>{{"issued_at"}, {"ts"}}));
  // Version 3: the parameters of every calibration and their history.
  EXPECT_EQ(
      db.Columns("calibration_param"),
      (std::vector<std::string>{"calibration_id", "name", "value", "std_error", "unit", "status"}));
  EXPECT_EQ(db.Columns("parameter_history"),
            (std::vector<std::string>{"run_at", "calibration_id", "accepted", "name", "value",
                                      "std_error", "unit", "status"}));
  // Version 4: monitoring (doc/contracts.md "Operation contracts").
  EXPECT_EQ(
      db.Columns("performance_daily"),
      (std::vector<std::string>{"day", "e_el_meas_wh", "e_el_model_wh", "e_th_meas_wh",
                                "e_th_model_wh", "pi_el", "pi_th", "pi_el_low", "pi_el_high",
                                "pi_th_low", "pi_th_high", "valid_minutes", "calibration_id"}));
  EXPECT_EQ(db.Columns("qc_event"),
            (std::vector<std::string>{"id", "channel", "start_ts", "end_ts", "kind", "detail"}));
  EXPECT_EQ(db.Columns("diagnosis"),
            (std::vector<std::string>{"id", "run_at", "calibration_id", "window_start",
                                      "window_end", "base_variant", "verdict", "low_confidence",
                                      "shrink_pct", "bias_p_el_w", "bias_q_th_w", "report_json"}));
  EXPECT_EQ(db.Columns("event"), (std::vector<std::string>{"ts", "kind", "severity", "message"}));
  const std::vector<std::string> qc = db.Columns("measurement_qc");
  ASSERT_GE(qc.size(), 9u);
  EXPECT_EQ(qc[1], "few_samples");
  EXPECT_EQ(qc[8], "imported");
  EXPECT_NE(std::find(qc.begin(), qc.end(), "missing_p_el_w"), qc.end());
  // Version 9: the local days and the views by local day (issue 54).
  EXPECT_EQ(db.Columns("local_day"), (std::vector<std::string>{"day", "start_ts", "end_ts"}));
  EXPECT_EQ(db.Columns("local_day_zone"), (std::vector<std::string>{"id", "zone"}));
  EXPECT_EQ(db.Columns("forecast_skill_local"), db.Columns("forecast_skill"));
  EXPECT_EQ(db.Columns("performance_daily_local"),
            (std::vector<std::string>{"day", "e_el_meas_wh", "e_el_model_wh", "e_th_meas_wh",
                                      "e_th_model_wh", "pi_el", "pi_th", "valid_minutes"}));
  EXPECT_EQ(db.Rows("SELECT name FROM sqlite_master WHERE type = 'view' ORDER BY name"),
            (std::vector<std::vector<std::string>>{{"event"},
                                                   {"forecast_latest"},
                                                   {"forecast_skill"},
                                                   {"forecast_skill_local"},
                                                   {"measurement_qc"},
                                                   {"parameter_history"},
                                                   {"performance_daily_local"}}));
}

// A store written by version 1 is migrated on open to the current version
// and keeps its rows.
TEST_F(StoreTest, AVersionOneStoreIsMigratedAndKeepsItsRows) {
  {
    auto store = OpenStore();
    std::string error;
    ASSERT_TRUE(store->InsertSamples(MakeSamples(kJune1Noon2024UtcS, 3), &error)) << error;
  }
  {
    RawDb db(DbPath());
    ASSERT_EQ(db.Exec("INSERT INTO forecast(issued_at, ts, p_el_w) VALUES(0, 60, 1)"), SQLITE_OK);
    // Back to what version 1 wrote: without the tables and views of 2 to 11
    // (version 1's two forecast views stand in as views of those names,
    // which version 6 replaces).
    std::vector<std::string> downgrade = testing::DropSchemaV12();  // version 12
    for (const std::string& sql : testing::DropSchemaV11()) downgrade.push_back(sql);
    for (const char* sql : {"DROP VIEW performance_daily_local",
                            "DROP VIEW forecast_skill_local",
                            "DROP TABLE local_day_zone",
                            "DROP TABLE local_day",
                            "DROP VIEW forecast_latest",
                            "DROP VIEW forecast_skill",
                            "ALTER TABLE forecast DROP COLUMN basis",
                            "ALTER TABLE forecast DROP COLUMN p_el_w_p10",
                            "ALTER TABLE forecast DROP COLUMN p_el_w_p90",
                            "ALTER TABLE forecast DROP COLUMN q_th_w_p10",
                            "ALTER TABLE forecast DROP COLUMN q_th_w_p90",
                            "ALTER TABLE forecast DROP COLUMN p_el_w_ref",
                            "ALTER TABLE forecast DROP COLUMN q_th_w_ref",
                            "ALTER TABLE forecast DROP COLUMN p_el_w_p50",
                            "ALTER TABLE forecast DROP COLUMN q_th_w_p50",
                            "CREATE VIEW forecast_latest(ts) AS SELECT ts FROM forecast",
                            "CREATE VIEW forecast_skill(day) AS SELECT ts FROM measurement_1min",
                            "DROP TABLE measurement_interval",
                            "DROP VIEW parameter_history",
                            "DROP TABLE calibration_param",
                            "DROP VIEW event",
                            "DROP VIEW measurement_qc",
                            "DROP TABLE performance_daily",
                            "DROP TABLE qc_event",
                            "DROP TABLE monitor_event",
                            "DROP TABLE diagnosis",
                            "ALTER TABLE weather_forecast DROP COLUMN source",
                            "DROP TABLE plant_config",
                            "DROP TABLE store_identity",
                            "PRAGMA user_version = 1"}) {
      downgrade.push_back(sql);
    }
    for (const std::string& sql : downgrade) ASSERT_EQ(db.Exec(sql), SQLITE_OK) << sql;
  }
  auto store = OpenStore();
  ASSERT_NE(store, nullptr);
  RawDb db(DbPath());
  EXPECT_EQ(db.Number("PRAGMA user_version"), static_cast<double>(kStoreSchemaVersion));
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s"), 3.0);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_interval"), 0.0);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM parameter_history"), 0.0);
  // Version 7: the migrated store gets an identity of its own.
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM store_identity WHERE length(store_id) = 32"), 1.0);
  // Version 8: the medians and the coverage per output.
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM pragma_table_info('forecast') WHERE name IN "
                      "('p_el_w_p50', 'q_th_w_p50')"),
            2.0);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM pragma_table_info('forecast_skill') WHERE name IN "
                      "('coverage_p_el', 'coverage_q_th')"),
            2.0);
  // Version 10: a row written before is a calibrated forecast.
  EXPECT_EQ(db.Rows("SELECT basis FROM forecast_latest"),
            (std::vector<std::vector<std::string>>{{"calibrated"}}));
}

TEST_F(StoreTest, EveryNewStoreGetsItsOwnIdentityAndKeepsItWhenReopened) {
  std::string first;
  {
    auto store = OpenStore();
    ASSERT_NE(store, nullptr);
    RawDb db(DbPath());
    first = db.Text("SELECT store_id FROM store_identity WHERE id = 1");
  }
  ASSERT_EQ(first.size(), 32u) << first;
  EXPECT_EQ(first.find_first_not_of("0123456789abcdef"), std::string::npos) << first;
  {
    auto store = OpenStore();  // reopened: the same id
    RawDb db(DbPath());
    EXPECT_EQ(db.Text("SELECT store_id FROM store_identity"), first);
  }
  const std::string other_path = (dir_ / "other.db").string();
  std::string error;
  auto other = Store::Open(other_path, &error);
  ASSERT_NE(other, nullptr) << error;
  RawDb db(other_path);
  EXPECT_NE(db.Text("SELECT store_id FROM store_identity"), first);
}

TEST_F(StoreTest, ReopeningKeepsDataAndANewerSchemaOrAForeignFileIsRefused) {
  {
    auto store = OpenStore();
    std::string error;
    ASSERT_TRUE(store->InsertSamples(MakeSamples(kJune1Noon2024UtcS, 3), &error)) << error;
  }
  {
    auto store = OpenStore();  // second open: no migration runs again
    std::vector<Sample> out;
    std::string error;
    ASSERT_TRUE(store->ReadSamples(kJune1Noon2024UtcS, kJune1Noon2024UtcS + 60, &out, &error))
        << error;
    EXPECT_EQ(out.size(), 3u);
  }
  {
    RawDb db(DbPath());
    ASSERT_EQ(db.Exec("PRAGMA user_version = " + std::to_string(kStoreSchemaVersion + 1)),
              SQLITE_OK);
  }
  std::string error;
  EXPECT_EQ(Store::Open(DbPath(), &error), nullptr);
  EXPECT_NE(error.find("schema version " + std::to_string(kStoreSchemaVersion + 1) + " is newer"),
            std::string::npos)
      << error;

  const std::string text_file = (dir_ / "notes.txt").string();
  FILE* f = std::fopen(text_file.c_str(), "w");
  std::fputs("this is not a database, but it is long enough to look like a header.........\n", f);
  std::fclose(f);
  error.clear();
  EXPECT_EQ(Store::Open(text_file, &error), nullptr);
  EXPECT_NE(error.find(text_file), std::string::npos) << error;
}

TEST_F(StoreTest, SamplesRoundTripWithMissingAndRejectedValuesAndAoiInDegrees) {
  auto store = OpenStore();
  std::vector<Sample> in = MakeSamples(kJune1Noon2024UtcS, 4);
  in[1].Set(Channel::kPElW, std::nan(""));  // not read
  in[2].Reject(Channel::kTAmbC);            // read but rejected
  std::string error;
  ASSERT_TRUE(store->InsertSamples(in, &error)) << error;
  std::vector<Sample> out;
  ASSERT_TRUE(store->ReadSamples(kJune1Noon2024UtcS + 5, kJune1Noon2024UtcS + 20, &out, &error))
      << error;
  ASSERT_EQ(out.size(), 3u);  // [from, to): ts 5, 10, 15
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Sample& expected = in[i + 1];
    EXPECT_EQ(out[i].ts_s, expected.ts_s);
    EXPECT_EQ(out[i].rejected_mask, expected.rejected_mask);
    for (std::size_t c = 0; c < kNumChannels; ++c) {
      if (std::isnan(expected.value[c])) {
        EXPECT_TRUE(std::isnan(out[i].value[c])) << kChannels[c].name;
      } else {
        EXPECT_DOUBLE_EQ(out[i].value[c], expected.value[c]) << kChannels[c].name;
      }
    }
  }
  EXPECT_TRUE(out[1].Rejected(Channel::kTAmbC));
  RawDb db(DbPath());
  // SQL users see degrees in aoi_deg, NULL for missing values.
  EXPECT_NEAR(db.Number("SELECT aoi_deg FROM sample_5s LIMIT 1"), 30.0, 1e-12);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s WHERE p_el_w IS NULL"), 1.0);
  EXPECT_EQ(db.Number("SELECT rejected_mask FROM sample_5s WHERE ts = " +
                      std::to_string(kJune1Noon2024UtcS + 10)),
            static_cast<double>(1u << static_cast<unsigned>(Channel::kTAmbC)));
}

TEST_F(StoreTest, InsertingTheSameTimeAgainReplacesTheSample) {
  auto store = OpenStore();
  std::string error;
  std::vector<Sample> batch = MakeSamples(kJune1Noon2024UtcS, 2);
  ASSERT_TRUE(store->InsertSamples(batch, &error)) << error;
  batch[1].Set(Channel::kPElW, 999.0);
  ASSERT_TRUE(store->InsertSamples(batch, &error)) << error;
  std::vector<Sample> out;
  ASSERT_TRUE(store->ReadSamples(0, kJune1Noon2024UtcS + 3600, &out, &error)) << error;
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].Get(Channel::kPElW), 999.0);
}

TEST_F(StoreTest, AMinuteSplitByARestartIsAggregatedOnceWithAllTwelveSamples) {
  const std::vector<Sample> minute = MakeSamples(kJune1Noon2024UtcS, 12);
  std::string error;
  int written = -1;
  {
    auto store = OpenStore();
    ASSERT_TRUE(store->InsertSamples({minute.begin(), minute.begin() + 6}, &error)) << error;
    // The minute is still being polled: nothing to aggregate yet.
    ASSERT_TRUE(store->AggregateMinutes(kJune1Noon2024UtcS + 30, &written, &error)) << error;
    EXPECT_EQ(written, 0);
  }  // "crash": the process ends in the middle of the minute
  auto store = OpenStore();
  ASSERT_TRUE(store->InsertSamples({minute.begin() + 6, minute.end()}, &error)) << error;
  ASSERT_TRUE(store->AggregateMinutes(kJune1Noon2024UtcS + 60, &written, &error)) << error;
  EXPECT_EQ(written, 1);
  ASSERT_TRUE(store->AggregateMinutes(kJune1Noon2024UtcS + 60, &written, &error)) << error;
  EXPECT_EQ(written, 0);
  {
    auto again = OpenStore();  // a fresh process scans the whole table: still no duplicate
    ASSERT_TRUE(again->AggregateMinutes(kJune1Noon2024UtcS + 3600, &written, &error)) << error;
    EXPECT_EQ(written, 0);
  }
  MinuteRows rows;
  ASSERT_TRUE(store->ReadMinuteRows(0, kJune1Noon2024UtcS + 3600, &rows, &error)) << error;
  ASSERT_EQ(rows.rows.size(), 1u);
  EXPECT_EQ(rows.rows.time_s[0], kJune1Noon2024UtcS);
  EXPECT_EQ(rows.n_samples[0], 12);
  // p_el_w = 150 + k for k = 0..11: mean 155.5; q_th from 0.03 kg/s · 3650 · 10 K.
  EXPECT_DOUBLE_EQ(rows.rows[Channel::kPElW][0], 155.5);
  EXPECT_NEAR(rows.rows[Channel::kQThW][0], 1095.0, 1e-9);
  EXPECT_NEAR(rows.rows[Channel::kAoiRad][0], DegToRad(30.0), 1e-12);
  EXPECT_TRUE(rows.qc_flags[0] & kQcThermalPowerComputed);
  EXPECT_FALSE(rows.rows.Has(Channel::kTBackC));  // NULL everywhere: absent
  RawDb db(DbPath());
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 1.0);
}

TEST_F(StoreTest, ReaggregationReplacesMinutesAfterLateSamples) {
  auto store = OpenStore();
  const std::vector<Sample> minute = MakeSamples(kJune1Noon2024UtcS, 12);
  std::string error;
  int written = 0;
  ASSERT_TRUE(store->InsertSamples({minute.begin(), minute.begin() + 4}, &error)) << error;
  ASSERT_TRUE(store->AggregateMinutes(kJune1Noon2024UtcS + 60, &written, &error)) << error;
  ASSERT_TRUE(store->InsertSamples({minute.begin() + 4, minute.end()}, &error)) << error;
  ASSERT_TRUE(store->AggregateMinutes(kJune1Noon2024UtcS + 60, &written, &error)) << error;
  EXPECT_EQ(written, 0);  // AggregateMinutes never writes a minute twice
  ASSERT_TRUE(
      store->ReaggregateMinutes(kJune1Noon2024UtcS, kJune1Noon2024UtcS + 1, &written, &error))
      << error;
  EXPECT_EQ(written, 1);
  MinuteRows rows;
  ASSERT_TRUE(store->ReadMinuteRows(0, kJune1Noon2024UtcS + 60, &rows, &error)) << error;
  ASSERT_EQ(rows.rows.size(), 1u);
  EXPECT_EQ(rows.n_samples[0], 12);
}

TEST_F(StoreTest, ImportedMinutesRoundTripAndAreMarkedImported) {
  auto store = OpenStore();
  Series s;
  s.step_s = 60;
  s.time_s = {kJune1Noon2024UtcS, kJune1Noon2024UtcS + 60};
  s[Channel::kPElW] = {100.0, std::nan("")};
  s[Channel::kAoiRad] = {DegToRad(45.0), DegToRad(50.0)};
  std::string error;
  ASSERT_TRUE(store->WriteMinutes(s, &error)) << error;
  s[Channel::kPElW][0] = 110.0;
  ASSERT_TRUE(store->WriteMinutes(s, &error)) << error;  // upsert
  MinuteRows rows;
  ASSERT_TRUE(store->ReadMinuteRows(0, kJune1Noon2024UtcS + 3600, &rows, &error)) << error;
  ASSERT_EQ(rows.rows.size(), 2u);
  EXPECT_EQ(rows.rows[Channel::kPElW][0], 110.0);
  EXPECT_TRUE(std::isnan(rows.rows[Channel::kPElW][1]));
  EXPECT_NEAR(rows.rows[Channel::kAoiRad][1], DegToRad(50.0), 1e-12);
  EXPECT_TRUE(rows.qc_flags[0] & kQcImported);
  EXPECT_TRUE(rows.qc_flags[0] & kQcRequiredMissing);  // no t_in_c etc.
  RawDb db(DbPath());
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min WHERE n_samples IS NULL"), 2.0);
  s.time_s[1] = kJune1Noon2024UtcS + 61;  // not a minute start
  EXPECT_FALSE(store->WriteMinutes(s, &error));
  EXPECT_NE(error.find("not the start of a minute"), std::string::npos) << error;
}

TEST_F(StoreTest, RetentionDeletesOldSamplesAfterAggregatingThemKeepsMinutesPrunesForecasts) {
  auto store = OpenStore();
  std::string error;
  // One full minute at noon of each of 41 days.
  for (int day = 0; day <= 40; ++day) {
    ASSERT_TRUE(store->InsertSamples(MakeSamples(kJune1Noon2024UtcS + day * 86400, 12), &error))
        << error;
  }
  // Three issues for noon of day 5: the day-ahead one (23:00 the day
  // before), a superseded one (10:00) and the newest (11:00).
  const std::int64_t noon5 = kJune1Noon2024UtcS + 5 * 86400;
  for (const std::int64_t issued : {noon5 - 13 * 3600, noon5 - 7200, noon5 - 3600}) {
    ASSERT_TRUE(store->InsertForecast(issued, 0, "", {{noon5, 1, 2, 3, 4}}, &error)) << error;
  }
  const std::int64_t now = kJune1Noon2024UtcS + 40 * 86400 + 3600;  // 13:00 of day 40
  ASSERT_TRUE(store->ApplyRetention(now, 30, &error)) << error;
  // Cutoff 13:00 of day 10: noon samples of days 0..10 are gone, 11..40 kept.
  RawDb db(DbPath());
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM sample_5s"), 30.0 * 12);
  EXPECT_EQ(db.Number("SELECT MIN(ts) FROM sample_5s"),
            static_cast<double>(kJune1Noon2024UtcS + 11 * 86400));
  // The deleted minutes were aggregated first; the kept ones wait for
  // AggregateMinutes.
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min"), 11.0);
  EXPECT_EQ(db.Number("SELECT MIN(n_samples) FROM measurement_1min"), 12.0);
  EXPECT_EQ(
      db.Rows("SELECT issued_at - " + std::to_string(noon5) + " FROM forecast ORDER BY issued_at"),
      (std::vector<std::vector<std::string>>{{"-46800"}, {"-3600"}}));
  int written = 0;
  ASSERT_TRUE(store->AggregateMinutes(now, &written, &error)) << error;
  EXPECT_EQ(written, 30);
  EXPECT_FALSE(store->ApplyRetention(now, 0, &error));
  EXPECT_NE(error.find("raw_retention_days = 0"), std::string::npos) << error;
}

TEST_F(StoreTest, LatestAcceptedCalibrationIsTheNewestAcceptedRun) {
  auto store = OpenStore();
  std::string error;
  Store::CalibrationRow row;
  bool found = true;
  ASSERT_TRUE(store->LatestAcceptedCalibration(&row, &found, &error)) << error;
  EXPECT_FALSE(found);

  auto make = [](std::int64_t run_at, bool accepted, const std::string& reason) {
    Store::CalibrationRow r;
    r.run_at = run_at;
    r.variant = "2N1Ccolwr";
    r.window_start = run_at - 14 * 86400;
    r.window_end = run_at;
    r.status = accepted ? "accepted" : "rejected";
    r.mae_p_el_w = 3.5;
    r.mae_q_th_w = 20.25;
    r.runtime_s = 12.5;
    r.n_evals = 4242;
    r.params_json = "{\"u_front_w_m2k\": 9.5}";
    r.reason = reason;
    r.accepted = accepted;
    r.heldout_mae_w = accepted ? 23.0 : std::nan("");
    r.params = {{"u_front_w_m2k", 9.5 + static_cast<double>(run_at - kJune1_2024UtcS) / 86400.0,
                 0.25, "W/(m²·K)", "identified"},
                {"eps_pvt", 0.15, std::nan(""), "-", "fixed"}};
    return r;
  };
  Store::CalibrationRow first = make(kJune1_2024UtcS, true, "first calibration");
  Store::CalibrationRow worse =
      make(kJune1_2024UtcS + 2 * 86400, false, "held-out MAE 30 W > 23 W");
  Store::CalibrationRow second = make(kJune1_2024UtcS + 86400, true, "held-out MAE 22 W <= 23 W");
  for (Store::CalibrationRow* r : {&first, &worse, &second}) {
    ASSERT_TRUE(store->InsertCalibration(r, &error)) << error;
  }
  EXPECT_GT(first.id, 0);
  EXPECT_GT(worse.id, first.id);
  EXPECT_GT(second.id, worse.id);
  ASSERT_TRUE(store->LatestAcceptedCalibration(&row, &found, &error)) << error;
  ASSERT_TRUE(found);
  EXPECT_EQ(row.id, second.id);
  EXPECT_EQ(row.run_at, kJune1_2024UtcS + 86400);
  EXPECT_EQ(row.variant, "2N1Ccolwr");
  EXPECT_EQ(row.window_start, kJune1_2024UtcS + 86400 - 14 * 86400);
  EXPECT_EQ(row.status, "accepted");
  EXPECT_EQ(row.mae_q_th_w, 20.25);
  EXPECT_EQ(row.n_evals, 4242);
  EXPECT_EQ(row.params_json, "{\"u_front_w_m2k\": 9.5}");
  EXPECT_EQ(row.reason, "held-out MAE 22 W <= 23 W");
  EXPECT_TRUE(row.accepted);
  RawDb db(DbPath());
  EXPECT_EQ(
      db.Rows("SELECT heldout_mae_w FROM calibration WHERE id = " + std::to_string(worse.id))[0][0],
      "NULL");
  // The parameters of all three runs, in time order, with their acceptance;
  // a parameter without a standard error has NULL.
  EXPECT_EQ(db.Rows("SELECT run_at - " + std::to_string(kJune1_2024UtcS) +
                    ", accepted, value, std_error, unit, status FROM parameter_history WHERE "
                    "name = 'u_front_w_m2k' ORDER BY run_at"),
            (std::vector<std::vector<std::string>>{
                {"0", "1", "9.5", "0.25", "W/(m²·K)", "identified"},
                {"86400", "1", "10.5", "0.25", "W/(m²·K)", "identified"},
                {"172800", "0", "11.5", "0.25", "W/(m²·K)", "identified"}}));
  EXPECT_EQ(db.Rows("SELECT std_error FROM calibration_param WHERE name = 'eps_pvt' LIMIT 1")[0][0],
            "NULL");
  // By id, accepted ones only; by the end of the window, the newest accepted
  // one that ended at or before it.
  ASSERT_TRUE(store->AcceptedCalibrationById(first.id, &row, &found, &error)) << error;
  ASSERT_TRUE(found);
  EXPECT_EQ(row.reason, "first calibration");
  ASSERT_TRUE(store->AcceptedCalibrationById(worse.id, &row, &found, &error)) << error;
  EXPECT_FALSE(found);
  ASSERT_TRUE(
      store->LatestAcceptedCalibrationBefore(kJune1_2024UtcS + 86400 - 1, &row, &found, &error))
      << error;
  ASSERT_TRUE(found);
  EXPECT_EQ(row.id, first.id);
  ASSERT_TRUE(store->LatestAcceptedCalibrationBefore(kJune1_2024UtcS - 1, &row, &found, &error))
      << error;
  EXPECT_FALSE(found);
}

TEST_F(StoreTest, ForecastLatestPicksTheNewestIssueForEachTime) {
  auto store = OpenStore();
  std::string error;
  const std::int64_t t = kJune1Noon2024UtcS;
  // Issue A at 1000 covers t, t+60, t+120; issue B at 2000 covers t+60 … t+180.
  ASSERT_TRUE(store->InsertForecast(
      t - 1000, 1, "weather=persistence",
      {{t, 1, 10, 20, 30}, {t + 60, 2, 11, 21, 31}, {t + 120, 3, 12, 22, 32}}, &error))
      << error;
  ASSERT_TRUE(store->InsertForecast(
      t - 500, 2, "weather=weather_forecast",
      {{t + 60, 102, 111, 121, 131}, {t + 120, 103, 112, 122, 132}, {t + 180, 104, 113, 123, 133}},
      &error))
      << error;
  RawDb db(DbPath());
  const std::string ts = std::to_string(t);
  EXPECT_EQ(
      db.Rows("SELECT ts - " + ts + ", issued_at - " + ts +
              ", p_el_w, q_th_w, t_pv_c, t_out_c FROM forecast_latest ORDER BY ts"),
      (std::vector<std::vector<std::string>>{{"0", "-1000", "1.0", "10.0", "20.0", "30.0"},
                                             {"60", "-500", "102.0", "111.0", "121.0", "131.0"},
                                             {"120", "-500", "103.0", "112.0", "122.0", "132.0"},
                                             {"180", "-500", "104.0", "113.0", "123.0", "133.0"}}));
  EXPECT_EQ(db.Rows("SELECT DISTINCT inputs FROM forecast WHERE calibration_id = 2")[0][0],
            "weather=weather_forecast");
  std::vector<Store::ForecastRow> latest;
  ASSERT_TRUE(store->ReadLatestForecast(t + 60, t + 180, &latest, &error)) << error;
  ASSERT_EQ(latest.size(), 2u);
  EXPECT_EQ(latest[0].ts, t + 60);
  EXPECT_EQ(latest[0].p_el_w, 102.0);
  EXPECT_EQ(latest[1].t_out_c, 132.0);
}

// Day one (issue 53): a forecast from the start values is flagged in the
// table and in forecast_latest; the calibrations skipped before the first
// accepted one (a new plant waiting for its history) stay in `calibration`
// but are no warning in `event`, a skip after it still is.
TEST_F(StoreTest, StartValueForecastsAreFlaggedAndTheFirstWaitIsNoWarningInEvent) {
  auto store = OpenStore();
  std::string error;
  const std::int64_t t = kJune1Noon2024UtcS;
  ASSERT_TRUE(store->InsertForecast(t - 1000, 0, ForecastBasis::kStartValues, "start values",
                                    {{t, 1, 10, 20, 30}, {t + 60, 2, 11, 21, 31}}, &error))
      << error;
  ASSERT_TRUE(store->InsertForecast(t - 500, 7, "bands", {{t + 60, 102, 111, 121, 131}}, &error))
      << error;
  RawDb db(DbPath());
  const std::string ts = std::to_string(t);
  EXPECT_EQ(db.Rows("SELECT ts - " + ts +
                    ", basis, calibration_id FROM forecast ORDER BY "
                    "issued_at, ts"),
            (std::vector<std::vector<std::string>>{{"0", "start_values", "NULL"},
                                                   {"60", "start_values", "NULL"},
                                                   {"60", "calibrated", "7"}}));
  EXPECT_EQ(db.Rows("SELECT ts - " + ts + ", basis FROM forecast_latest ORDER BY ts"),
            (std::vector<std::vector<std::string>>{{"0", "start_values"}, {"60", "calibrated"}}));

  const auto calibration = [&](std::int64_t run_at, const char* status, const char* reason) {
    Store::CalibrationRow r;
    r.run_at = run_at;
    r.variant = "2N1Ccolwr";
    r.status = status;
    r.accepted = std::string(status) == "accepted";
    r.reason = reason;
    ASSERT_TRUE(store->InsertCalibration(&r, &error)) << error;
  };
  calibration(t, "skipped", "waiting for history: 0.0 h of 48 h");
  calibration(t + 3600, "skipped", "waiting for history: 1.0 h of 48 h");
  calibration(t + 2 * 86400, "accepted", "first parameters of this database");
  calibration(t + 9 * 86400, "skipped", "window holds 1.2 days of 1-min data; two are needed");
  ASSERT_TRUE(store->InsertMonitorEvent(t, "calibration_waiting", "info",
                                        "waiting for history: 0.0 h of 48 h", &error))
      << error;
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM calibration"), 4.0);
  EXPECT_EQ(db.Rows("SELECT ts - " + ts + ", kind, severity FROM event ORDER BY ts"),
            (std::vector<std::vector<std::string>>{
                {"0", "calibration_waiting", "info"},
                {std::to_string(2 * 86400), "calibration_accepted", "info"},
                {std::to_string(9 * 86400), "calibration_skipped", "warning"}}));
}

TEST_F(StoreTest, ForecastSkillScoresTheDayAheadForecastAgainstValidMeasurements) {
  auto store = OpenStore();
  std::string error;
  const std::int64_t m0 = kJune1Noon2024UtcS, m1 = kJune1Noon2024UtcS + 60,
                     m2 = kJune1Noon2024UtcS + 120;
  // Measurements at three minutes of day 0; the third is invalid.
  Series meas;
  meas.step_s = 60;
  meas.time_s = {m0, m1, m2};
  meas[Channel::kPElW] = {110.0, 180.0, 1000.0};
  meas[Channel::kQThW] = {400.0, -100.0, 1000.0};
  meas[Channel::kValid] = {1.0, 1.0, 0.0};
  ASSERT_TRUE(store->WriteMinutes(meas, &error)) << error;
  // An old issue (two days before), the day-ahead issue (1 h before the day
  // starts) and an intraday issue (after the day started, not scored).
  ASSERT_TRUE(store->InsertForecast(kJune1_2024UtcS - 2 * 86400, 1, "",
                                    {{m0, 0, 0, 0, 0}, {m1, 0, 0, 0, 0}, {m2, 0, 0, 0, 0}},
                                    &error));
  ASSERT_TRUE(store->InsertForecast(kJune1_2024UtcS - 3600, 2, "",
                                    {{m0, 100, 500, 0, 0}, {m1, 200, 0, 0, 0}, {m2, 0, 0, 0, 0}},
                                    &error));
  ASSERT_TRUE(store->InsertForecast(kJune1_2024UtcS + 600, 3, "",
                                    {{m0, 110, 400, 0, 0}, {m1, 180, -100, 0, 0}}, &error));
  // Day-ahead errors: P_el |100 − 110| = 10, |200 − 180| = 20 → MAE 15 W,
  // mean |measured| 145 W → nMAE 15/145. Q_u: |500 − 400| = 100,
  // |0 − (−100)| = 100 → MAE 100 W, mean |measured| 250 W → nMAE 0.4.
  RawDb db(DbPath());
  const auto rows = db.Rows(
      "SELECT day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th FROM "
      "forecast_skill");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0][0], std::to_string(kJune1_2024UtcS));
  EXPECT_DOUBLE_EQ(std::stod(rows[0][1]), 15.0);
  EXPECT_DOUBLE_EQ(std::stod(rows[0][2]), 100.0);
  EXPECT_NEAR(std::stod(rows[0][3]), 15.0 / 145.0, 1e-12);
  EXPECT_NEAR(std::stod(rows[0][4]), 0.4, 1e-12);
  std::vector<Store::SkillRow> skill;
  ASSERT_TRUE(store->ReadForecastSkill(kJune1_2024UtcS, kJune1_2024UtcS + 86400, &skill, &error))
      << error;
  ASSERT_EQ(skill.size(), 1u);
  EXPECT_EQ(skill[0].day, kJune1_2024UtcS);
  EXPECT_DOUBLE_EQ(skill[0].mae_p_el_w, 15.0);
  EXPECT_NEAR(skill[0].nmae_q_th, 0.4, 1e-12);
  ASSERT_TRUE(store->ReadForecastSkill(kJune1_2024UtcS + 86400, kJune1_2024UtcS + 2 * 86400, &skill,
                                       &error));
  EXPECT_TRUE(skill.empty());
}

// Skill against the reference and the band's coverage, by hand: 400 minutes
// of day 0 forecast the day before. P_el: forecast 100, reference 110,
// measured 100 + (k % 4) → |e| = 0,1,2,3 (mean 1.5), |e_ref| = 10,9,8,7
// (mean 8.5): skill 1 − 1.5/8.5. Q_u: forecast 500, reference 480, measured
// 510 → skill 1 − 10/30. Bands: P_el [99, 101.5] holds k % 4 ∈ {0, 1} (200
// of 400), Q_u [490, 520] all 400; the first 40 minutes have a band of no
// width for Q_u (night-like) and count for neither: coverage (200 + 360) /
// (400 + 360). A second day with 100 scored minutes keeps its MAE but gets
// no skill or coverage.
TEST_F(StoreTest, ForecastSkillScoresAgainstTheReferenceAndCountsTheBandsCoverage) {
  auto store = OpenStore();
  std::string error;
  const std::int64_t day1 = kJune1_2024UtcS + 86400;
  Series meas;
  meas.step_s = 60;
  std::vector<Store::ForecastRow> rows;
  std::vector<double> p_el, q_th;
  for (int k = 0; k < 400; ++k) {
    const std::int64_t t = kJune1_2024UtcS + 60 * k;
    meas.time_s.push_back(t);
    p_el.push_back(100.0 + k % 4);
    q_th.push_back(510.0);
    Store::ForecastRow r{t, 100.0, 500.0, 0.0, 0.0};
    r.p_el_w_p10 = 99.0;
    r.p_el_w_p90 = 101.5;
    r.q_th_w_p10 = k < 40 ? 500.0 : 490.0;
    r.q_th_w_p90 = k < 40 ? 500.0 : 520.0;
    r.p_el_w_ref = 110.0;
    r.q_th_w_ref = 480.0;
    r.p_el_w_p50 = 100.5;
    rows.push_back(r);
  }
  for (int k = 0; k < 100; ++k) {
    meas.time_s.push_back(day1 + 60 * k);
    p_el.push_back(50.0);
    q_th.push_back(50.0);
    Store::ForecastRow r{day1 + 60 * k, 40.0, 40.0, 0.0, 0.0};
    r.p_el_w_ref = 50.0;
    r.q_th_w_ref = 50.0;
    rows.push_back(r);
  }
  meas[Channel::kPElW] = p_el;
  meas[Channel::kQThW] = q_th;
  ASSERT_TRUE(store->WriteMinutes(meas, &error)) << error;
  ASSERT_TRUE(store->InsertForecast(kJune1_2024UtcS - 3600, 1, "", rows, &error)) << error;
  std::vector<Store::SkillRow> skill;
  ASSERT_TRUE(store->ReadForecastSkill(kJune1_2024UtcS, day1 + 86400, &skill, &error)) << error;
  ASSERT_EQ(skill.size(), 2u);
  EXPECT_EQ(skill[0].minutes, 400);
  EXPECT_DOUBLE_EQ(skill[0].mae_p_el_w, 1.5);
  EXPECT_NEAR(skill[0].skill_p_el, 1.0 - 1.5 / 8.5, 1e-12);
  EXPECT_NEAR(skill[0].skill_q_th, 1.0 - 10.0 / 30.0, 1e-12);
  EXPECT_NEAR(skill[0].coverage_p10_p90, (200.0 + 360.0) / (400.0 + 360.0), 1e-12);
  // Per output (version 8): P_el 200 of 400, Q_u 360 of 360.
  EXPECT_NEAR(skill[0].coverage_p_el, 0.5, 1e-12);
  EXPECT_NEAR(skill[0].coverage_q_th, 1.0, 1e-12);
  EXPECT_EQ(skill[1].minutes, 100);
  EXPECT_TRUE(std::isnan(skill[1].coverage_p_el));
  EXPECT_DOUBLE_EQ(skill[1].mae_p_el_w, 10.0);
  EXPECT_TRUE(std::isnan(skill[1].skill_p_el));
  EXPECT_TRUE(std::isnan(skill[1].coverage_p10_p90));
  std::vector<Store::ForecastRow> latest;
  ASSERT_TRUE(store->ReadLatestForecast(kJune1_2024UtcS, kJune1_2024UtcS + 120, &latest, &error))
      << error;
  ASSERT_EQ(latest.size(), 2u);
  EXPECT_EQ(latest[1].p_el_w_p10, 99.0);
  EXPECT_EQ(latest[1].q_th_w_p90, 500.0);
  EXPECT_EQ(latest[1].p_el_w_p50, 100.5);
  EXPECT_TRUE(std::isnan(latest[1].q_th_w_p50));
  ASSERT_TRUE(store->ReadLatestForecast(day1, day1 + 60, &latest, &error)) << error;
  EXPECT_TRUE(std::isnan(latest[0].p_el_w_p10));  // written without a band: NULL
}

TEST_F(StoreTest, PruningOldForecastsLeavesBothViewsAsTheyWere) {
  auto store = OpenStore();
  std::string error;
  // Hourly issues from 6 h before day 1 to 5 h into it, each 6 h ahead at
  // 1 min, and measurements for every minute they cover.
  const std::int64_t day1 = kJune1_2024UtcS + 86400;
  Series meas;
  meas.step_s = 60;
  for (std::int64_t t = day1 - 6 * 3600; t < day1 + 11 * 3600; t += 60) {
    meas.time_s.push_back(t);
    meas.Ensure(Channel::kPElW).push_back(100.0 + static_cast<double>(t % 7));
    meas.Ensure(Channel::kQThW).push_back(500.0 - static_cast<double>(t % 5));
  }
  ASSERT_TRUE(store->WriteMinutes(meas, &error)) << error;
  for (int h = -6; h < 6; ++h) {
    const std::int64_t issued = day1 + h * 3600;
    std::vector<Store::ForecastRow> rows;
    for (std::int64_t t = issued; t < issued + 6 * 3600; t += 60) {
      rows.push_back({t, 100.0 + h, 500.0 + 2 * h, 0.0, 0.0});
    }
    ASSERT_TRUE(store->InsertForecast(issued, 0, "", rows, &error)) << error;
  }
  RawDb db(DbPath());
  const std::string latest = "SELECT * FROM forecast_latest ORDER BY ts";
  const std::string skill = "SELECT * FROM forecast_skill ORDER BY day";
  const auto latest_before = db.Rows(latest);
  const auto skill_before = db.Rows(skill);
  // Day 0's minutes have no issue from before day 0 began: day 1 only.
  ASSERT_EQ(skill_before.size(), 1u);
  const double rows_before = db.Number("SELECT COUNT(*) FROM forecast");
  EXPECT_EQ(rows_before, 12.0 * 360);
  ASSERT_TRUE(store->PruneForecasts(kJune1_2024UtcS, day1 + 86400, &error)) << error;
  EXPECT_EQ(db.Rows(latest), latest_before);
  EXPECT_EQ(db.Rows(skill), skill_before);
  // Left: the newest issue of each ts, plus the day-ahead issue of day 1
  // (issued at 00:00, the newest at or before the day began) where a newer
  // one exists: 01:00 … 06:00, 300 minutes.
  const double distinct_ts = db.Number("SELECT COUNT(DISTINCT ts) FROM forecast");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast"), distinct_ts + 5 * 60);
}

TEST_F(StoreTest, ForecastInputsWrittenBySqlAreReadAsSeries) {
  auto store = OpenStore();
  {
    RawDb db(DbPath());
    const std::string t = std::to_string(kJune1Noon2024UtcS);
    ASSERT_EQ(db.Exec("INSERT INTO weather_forecast(ts, g_poa_w_m2, t_amb_c, wind_m_s) VALUES "
                      "(" +
                      t + ", 500, 20, 2), (" + t + " + 900, 600, 21, NULL), (" + t +
                      " + 1800, 700, 22, 3)"),
              SQLITE_OK);
    ASSERT_EQ(db.Exec("INSERT INTO operation_plan(ts, t_in_c, flow_kg_s) VALUES (" + t +
                      ", 25, 0.03), (" + t + " + 60, 26, 0.0)"),
              SQLITE_OK);
  }
  Series weather, plan;
  std::string error;
  ASSERT_TRUE(
      store->ReadWeatherForecast(kJune1Noon2024UtcS, kJune1Noon2024UtcS + 1800, &weather, &error))
      << error;
  ASSERT_EQ(weather.size(), 2u);  // [from, to)
  EXPECT_EQ(weather.step_s, 900.0);
  EXPECT_EQ(weather[Channel::kGPoaWM2], (std::vector<double>{500.0, 600.0}));
  EXPECT_EQ(weather[Channel::kWindMS][0], 2.0);
  EXPECT_TRUE(std::isnan(weather[Channel::kWindMS][1]));
  EXPECT_FALSE(weather.Has(Channel::kGhiWM2));  // NULL everywhere: absent
  ASSERT_TRUE(
      store->ReadOperationPlan(kJune1Noon2024UtcS, kJune1Noon2024UtcS + 3600, &plan, &error))
      << error;
  EXPECT_EQ(plan[Channel::kTInC], (std::vector<double>{25.0, 26.0}));
  EXPECT_EQ(plan[Channel::kMdotKgS], (std::vector<double>{0.03, 0.0}));
}

// `sqlite3 .import` writes an empty CSV cell as the text '' into a REAL
// column (SQLite keeps text that is no number as text); sqlite3_column_double
// turns it into 0 °C and 0 m/s. Text is missing and counted, unless it is a
// whole number: a numeric text in a REAL column becomes REAL on insert
// (typeof() says so below), the same text stored as a BLOB stays one.
TEST_F(StoreTest, TextInForecastInputsIsMissingAndCounted) {
  auto store = OpenStore();
  const std::string t0 = std::to_string(kJune1Noon2024UtcS);
  {
    RawDb db(DbPath());
    ASSERT_EQ(db.Exec("INSERT INTO weather_forecast(ts, g_poa_w_m2, t_amb_c, wind_m_s) VALUES "
                      "(" +
                      t0 + ", 500, '', ''), (" + t0 + " + 60, 510, 'abc', '3,5'), (" + t0 +
                      " + 120, 520, '12.5', CAST('2.5' AS BLOB)), (" + t0 +
                      " + 180, 530, ' 13 ', 'n/a'), (" + t0 + " + 240, 540, 14, 2)"),
              SQLITE_OK);
    ASSERT_EQ(db.Text("SELECT typeof(t_amb_c) FROM weather_forecast WHERE ts = " + t0), "text");
    ASSERT_EQ(db.Text("SELECT typeof(t_amb_c) FROM weather_forecast WHERE ts = " + t0 + " + 120"),
              "real");
    ASSERT_EQ(db.Text("SELECT typeof(wind_m_s) FROM weather_forecast WHERE ts = " + t0 + " + 120"),
              "blob");
    ASSERT_EQ(db.Exec("INSERT INTO operation_plan(ts, t_in_c, flow_kg_s) VALUES (" + t0 +
                      ", '', 0.03), (" + t0 + " + 60, 'x', 'y'), (" + t0 + " + 120, 25, 0.02)"),
              SQLITE_OK);
  }
  Series weather, plan;
  Store::TextCells text;
  std::string error;
  ASSERT_TRUE(store->ReadWeatherForecast(kJune1Noon2024UtcS, kJune1Noon2024UtcS + 300, &weather,
                                         &error, &text))
      << error;
  ASSERT_EQ(weather.size(), 5u);
  const std::vector<double>& t_amb = weather[Channel::kTAmbC];
  const std::vector<double>& wind = weather[Channel::kWindMS];
  EXPECT_TRUE(std::isnan(t_amb[0]) && std::isnan(t_amb[1])) << t_amb[0] << " " << t_amb[1];
  EXPECT_EQ(t_amb[2], 12.5);
  EXPECT_EQ(t_amb[3], 13.0);
  EXPECT_EQ(t_amb[4], 14.0);
  EXPECT_TRUE(std::isnan(wind[0]) && std::isnan(wind[1]) && std::isnan(wind[3]));
  EXPECT_EQ(wind[2], 2.5);  // the BLOB '2.5' is a whole number
  EXPECT_EQ(wind[4], 2.0);
  EXPECT_EQ(weather[Channel::kGPoaWM2][0], 500.0);
  EXPECT_EQ(text.count[static_cast<std::size_t>(Channel::kTAmbC)], 2u);
  EXPECT_EQ(text.count[static_cast<std::size_t>(Channel::kWindMS)], 3u);
  EXPECT_EQ(text.Total(), 5u);
  EXPECT_EQ(text.Warning("weather_forecast"),
            "weather_forecast: 2 cells of t_amb_c, 3 of wind_m_s hold text, read as missing");

  ASSERT_TRUE(
      store->ReadOperationPlan(kJune1Noon2024UtcS, kJune1Noon2024UtcS + 300, &plan, &error, &text))
      << error;
  ASSERT_EQ(plan.size(), 3u);
  EXPECT_TRUE(std::isnan(plan[Channel::kTInC][0]) && std::isnan(plan[Channel::kTInC][1]));
  EXPECT_TRUE(std::isnan(plan[Channel::kMdotKgS][1]));
  EXPECT_EQ(plan[Channel::kMdotKgS][0], 0.03);
  EXPECT_EQ(plan[Channel::kTInC][2], 25.0);
  EXPECT_EQ(text.Total(), 3u);
  EXPECT_EQ(text.Warning("operation_plan"),
            "operation_plan: 2 cells of t_in_c, 1 of flow_kg_s hold text, read as missing");
  // A read without text: no warning.
  ASSERT_TRUE(store->ReadOperationPlan(kJune1Noon2024UtcS + 120, kJune1Noon2024UtcS + 300, &plan,
                                       &error, &text));
  EXPECT_EQ(text.Total(), 0u);
  EXPECT_EQ(text.Warning("operation_plan"), "");
}

TEST_F(StoreTest, WeatherForecastRowsKeepTheirSourceAndAreReplacedPerMinute) {
  auto store = OpenStore();
  Series rows;
  rows.step_s = 60.0;
  rows.time_s = {kJune1Noon2024UtcS, kJune1Noon2024UtcS + 60};
  rows[Channel::kGPoaWM2] = {500.0, 510.0};
  rows[Channel::kTAmbC] = {20.0, std::nan("")};
  std::string error;
  ASSERT_TRUE(store->WriteWeatherForecast(rows, "import-weather a.json", &error)) << error;
  rows.time_s = {kJune1Noon2024UtcS + 60, kJune1Noon2024UtcS + 120};
  rows[Channel::kGPoaWM2] = {600.0, 610.0};
  rows[Channel::kTAmbC] = {21.0, 22.0};
  ASSERT_TRUE(store->WriteWeatherForecast(rows, "fetch http://x", &error)) << error;
  {
    RawDb db(DbPath());
    ASSERT_EQ(db.Exec("INSERT INTO weather_forecast(ts, t_amb_c) VALUES (" +
                      std::to_string(kJune1Noon2024UtcS + 180) + ", 23)"),
              SQLITE_OK);
  }
  Series weather;
  ASSERT_TRUE(
      store->ReadWeatherForecast(kJune1Noon2024UtcS, kJune1Noon2024UtcS + 240, &weather, &error))
      << error;
  ASSERT_EQ(weather.size(), 4u);
  EXPECT_EQ(weather[Channel::kGPoaWM2][1], 600.0);  // the later write replaced the minute
  EXPECT_EQ(weather[Channel::kTAmbC][0], 20.0);
  std::vector<std::string> sources;
  ASSERT_TRUE(
      store->ReadWeatherSources(kJune1Noon2024UtcS, kJune1Noon2024UtcS + 240, &sources, &error))
      << error;
  EXPECT_EQ(sources, (std::vector<std::string>{"fetch http://x", "import-weather a.json",
                                               "weather_forecast"}));
}

TEST_F(StoreTest, PlantConfigRoundTrips) {
  auto store = OpenStore();
  std::vector<std::pair<std::string, double>> values = {{"latitude_deg", 47.4}, {"tilt_deg", 20.0}};
  std::string error;
  ASSERT_TRUE(store->WritePlantConfig(values, &error)) << error;
  values[0].second = 48.0;
  ASSERT_TRUE(store->WritePlantConfig(values, &error)) << error;
  std::vector<std::pair<std::string, double>> read;
  ASSERT_TRUE(store->ReadPlantConfig(&read, &error)) << error;
  EXPECT_EQ(read, values);
}

}  // namespace
}  // namespace pvtwin
