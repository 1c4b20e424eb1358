// forecast_skill materialised per UTC day (store schema version 11): the
// view returns what version 10's query computes from the same rows, before
// the refresh, after it and after a late import and a late forecast change
// closed days; a prune marks nothing; after the refresh a year of 1-min
// rows costs the view only today's minutes (counted in SQLite's virtual
// machine steps and full-scan steps, and read in its query plan); the
// migration from version 10 keeps the values. Real store files.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "io/store/store.h"
#include "tests/support/fixtures.h"
#include "tests/support/forecast_skill_check.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/store_schema_v10.h"
#include "tests/support/store_schema_v11.h"

namespace pvtwin {
namespace {

using testing::RawDb;

using testing::kDayS;
using testing::kJune1_2024UtcS;

using testing::CostOf;
using testing::ExpectSameRows;
using testing::Issue;
using testing::QueryCost;

using testing::kForecastSkillRowsByDay;
using testing::kForecastSkillV10RowsByDay;

class SkillDayTest : public testing::TempDirTest {
 protected:
  std::string DbPath() const { return (dir_ / "pvtwin.db").string(); }
  std::unique_ptr<Store> Open() {
    StoreOptions options;
    options.log = nullptr;
    std::string error;
    std::unique_ptr<Store> store = Store::Open(DbPath(), options, &error);
    EXPECT_NE(store, nullptr) << error;
    return store;
  }

  static Series Minutes(std::int64_t from, std::int64_t to, double offset_w) {
    return testing::Measured(from, to, 60, offset_w);
  }

  // Measurements from day 0 to noon of day 3, and hourly issues 26 h
  // ahead from 12 h before day 0.
  void FillFourDays(Store* store) {
    std::string error;
    ASSERT_TRUE(store->WriteMinutes(
        Minutes(kJune1_2024UtcS, kJune1_2024UtcS + 3 * kDayS + kDayS / 2, 0.0), &error))
        << error;
    testing::InsertHourlyIssues(store, kJune1_2024UtcS - kDayS / 2,
                                kJune1_2024UtcS + 3 * kDayS + kDayS / 2);
  }
};

// The view's rows equal version 10's query on the same rows at each stage;
// a changed closed day is computed live until the refresh materialises it
// again. Without the dirty marks the view would show the stale
// materialised rows of days 1 and 2, which this test tells apart.
TEST_F(SkillDayTest, TheViewEqualsVersionTensQueryBeforeAndAfterMaterialisingAndALateImport) {
  auto store = Open();
  ASSERT_NE(store, nullptr);
  ASSERT_NO_FATAL_FAILURE(FillFourDays(store.get()));
  RawDb db(DbPath());
  const auto v10_before = db.Rows(kForecastSkillV10RowsByDay);
  ASSERT_EQ(v10_before.size(), 4u) << "days 0 to 3 are scored";
  ExpectSameRows(db.Rows(kForecastSkillRowsByDay), v10_before, "before the refresh");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_day"), 0.0);

  const std::int64_t now = kJune1_2024UtcS + 3 * kDayS + kDayS / 2;  // noon of day 3
  int written = 0;
  std::string error;
  ASSERT_TRUE(store->RefreshForecastSkill(now, &written, &error)) << error;
  EXPECT_EQ(written, 3) << "the closed days 0, 1 and 2";
  EXPECT_EQ(db.Number("SELECT done_before FROM forecast_skill_state"),
            static_cast<double>(kJune1_2024UtcS + 3 * kDayS));
  ExpectSameRows(db.Rows(kForecastSkillRowsByDay), db.Rows(kForecastSkillV10RowsByDay), "after the refresh");
  ASSERT_TRUE(store->RefreshForecastSkill(now, &written, &error)) << error;
  EXPECT_EQ(written, 0) << "nothing more to do: no day written again";

  // A late import of day 1's morning and a late forecast issued at 00:00 of
  // day 2 (the newest at or before the day began) change two closed days.
  const std::int64_t day1 = kJune1_2024UtcS + kDayS, day2 = kJune1_2024UtcS + 2 * kDayS;
  ASSERT_TRUE(store->WriteMinutes(Minutes(day1 + 6 * 3600, day1 + 9 * 3600, 60.0), &error))
      << error;
  ASSERT_TRUE(store->InsertForecast(day2, 0, "late", Issue(day2, kDayS, -40.0), &error)) << error;
  EXPECT_EQ(
      db.Rows("SELECT day FROM forecast_skill_dirty ORDER BY day"),
      (std::vector<std::vector<std::string>>{{std::to_string(day1)}, {std::to_string(day2)}}));
  const auto v10_late = db.Rows(kForecastSkillV10RowsByDay);
  ExpectSameRows(db.Rows(kForecastSkillRowsByDay), v10_late, "after the late import");
  for (const std::int64_t day : {day1, day2}) {
    const std::string where = " WHERE day = " + std::to_string(day);
    EXPECT_NE(db.Text("SELECT mae_p_el_w FROM forecast_skill_day" + where),
              db.Text("SELECT mae_p_el_w FROM forecast_skill" + where))
        << "the materialised row of day " << day << " is stale until the refresh";
  }
  written = 0;
  ASSERT_TRUE(store->RefreshForecastSkill(now, &written, &error)) << error;
  EXPECT_EQ(written, 2);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_dirty"), 0.0);
  ExpectSameRows(db.Rows(kForecastSkillRowsByDay), v10_late, "after the second refresh");

  // Pruning superseded issues changes no score, so it marks no day dirty.
  const double rows_before = db.Number("SELECT COUNT(*) FROM forecast");
  ASSERT_TRUE(store->PruneForecasts(kJune1_2024UtcS - kDayS, now + 2 * kDayS, &error)) << error;
  EXPECT_LT(db.Number("SELECT COUNT(*) FROM forecast"), rows_before / 2);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_dirty"), 0.0);
  ExpectSameRows(db.Rows(kForecastSkillRowsByDay), v10_late, "after the prune");
  ExpectSameRows(db.Rows(kForecastSkillV10RowsByDay), v10_late, "version 10's query after the prune");

  // Deleting a scored forecast row of a closed day does change its score.
  ASSERT_EQ(db.Exec("DELETE FROM forecast WHERE issued_at = " + std::to_string(day2) +
                    " AND ts = " + std::to_string(day2 + 12 * 3600)),
            SQLITE_OK);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_dirty"), 1.0);
  ExpectSameRows(db.Rows(kForecastSkillRowsByDay), db.Rows(kForecastSkillV10RowsByDay), "after deleting a scored row");
}

// A year of 1-min rows and one issue a day, made by SQL in one statement
// each. After the refresh the view computes today's minutes only: its
// virtual machine steps stay below those of one more whole day computed
// live, a small fraction of version 10's query over the year, and it scans
// no table of minutes in full.
TEST_F(SkillDayTest, AfterTheRefreshAYearCostsTheViewOnlyTodaysMinutes) {
  const std::int64_t today = kJune1_2024UtcS + 365 * kDayS;
  const std::int64_t now = today + kDayS / 2;
  {
    auto store = Open();
    ASSERT_NE(store, nullptr);
  }
  RawDb db(DbPath());
  const std::string minutes = "WITH RECURSIVE t(ts) AS (SELECT " + std::to_string(kJune1_2024UtcS) +
                              " UNION ALL SELECT ts + 60 " + "FROM t WHERE ts + 60 < " +
                              std::to_string(now) + ") ";
  ASSERT_EQ(
      db.Exec(minutes + "INSERT INTO measurement_1min(ts, p_el_w, q_th_w, valid) SELECT ts, "
                        "100 + (ts / 60 * 7919) % 250, 400 + (ts / 60 * 104729) % 450, 1 FROM t"),
      SQLITE_OK);
  ASSERT_EQ(db.Exec(minutes +
                    "INSERT INTO forecast(issued_at, ts, p_el_w, q_th_w, p_el_w_p10, p_el_w_p90, "
                    "q_th_w_p10, q_th_w_p90, p_el_w_ref, q_th_w_ref) SELECT ts - ts % 86400 - "
                    "3600, ts, 210, 590, 150, 260, 400, 800, 200, 600 FROM t"),
            SQLITE_OK);
  {
    auto store = Open();
    int written = 0;
    std::string error;
    ASSERT_TRUE(store->RefreshForecastSkill(now, &written, &error)) << error;
    EXPECT_EQ(written, 365);
  }
  const std::string view = "SELECT * FROM forecast_skill";
  const QueryCost cost = CostOf(DbPath(), view);
  EXPECT_EQ(cost.rows, 366) << "365 materialised days and today";
  const QueryCost year = CostOf(DbPath(), testing::kForecastSkillV10);
  EXPECT_EQ(year.rows, 366);
  // Yesterday made dirty: the view computes one more whole day live.
  ASSERT_EQ(db.Exec("UPDATE measurement_1min SET p_el_w = p_el_w + 1 WHERE ts = " +
                    std::to_string(today - 3600)),
            SQLITE_OK);
  const QueryCost with_yesterday = CostOf(DbPath(), view);
  EXPECT_EQ(with_yesterday.rows, 366);
  const long one_day = with_yesterday.vm_steps - cost.vm_steps;
  EXPECT_LT(cost.vm_steps, one_day) << "today's half day costs less than one whole day";
  EXPECT_LT(100 * cost.vm_steps, year.vm_steps) << "version 10's query computes 365.5 days";
  EXPECT_LT(cost.fullscan_steps, 1440) << "no table of minutes is scanned in full";
  EXPECT_GT(year.fullscan_steps, 365 * 1440);
  std::printf(
      "forecast_skill over a year: view %ld VM steps (%ld full-scan), with yesterday "
      "dirty %ld, version 10's query %ld (%ld full-scan)\n",
      cost.vm_steps, cost.fullscan_steps, with_yesterday.vm_steps, year.vm_steps,
      year.fullscan_steps);
  // The query plan reaches measurement_1min by its key only.
  const auto plan = db.Rows("EXPLAIN QUERY PLAN " + view);
  int searches = 0;
  for (const auto& row : plan) {
    const std::string detail = row.back() + " ";  // the view names measurement_1min m
    EXPECT_NE(detail.rfind("SCAN m ", 0), 0u) << detail;
    searches += detail.rfind("SEARCH m USING INTEGER PRIMARY KEY", 0) == 0;
  }
  // Version 12 reads measurement_interval m the same way for days without
  // 1-min rows: two searches of each table.
  EXPECT_EQ(searches, 4) << "the rows from done_before on, and those of the dirty days";
}

// A version 10 store is migrated with its closed days materialised, and the
// view returns what version 10's did.
TEST_F(SkillDayTest, MigratingFromVersionTenMaterialisesTheDaysAndKeepsTheValues) {
  {
    auto store = Open();
    ASSERT_NE(store, nullptr);
    ASSERT_NO_FATAL_FAILURE(FillFourDays(store.get()));
  }
  std::vector<std::vector<std::string>> v10;
  {
    RawDb db(DbPath());
    std::vector<std::string> downgrade = testing::DropSchemaV12();
    for (const std::string& sql : testing::DropSchemaV11()) downgrade.push_back(sql);
    downgrade.push_back("DROP VIEW forecast_skill");
    downgrade.push_back(std::string("CREATE VIEW forecast_skill") + testing::kForecastSkillColumns +
                        " AS " + testing::kForecastSkillV10);
    downgrade.push_back("PRAGMA user_version = 10");
    for (const std::string& sql : downgrade) ASSERT_EQ(db.Exec(sql), SQLITE_OK) << sql;
    v10 = db.Rows(kForecastSkillRowsByDay);
    ASSERT_EQ(v10.size(), 4u);
  }
  auto store = Open();
  ASSERT_NE(store, nullptr);
  EXPECT_EQ(store->upgrade().from_version, 10);
  EXPECT_EQ(store->upgrade().to_version, kStoreSchemaVersion);
  RawDb db(DbPath());
  // The stored days end on day 3, long over: all four are materialised.
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_day"), 4.0);
  EXPECT_EQ(db.Number("SELECT done_before FROM forecast_skill_state"),
            static_cast<double>(kJune1_2024UtcS + 4 * kDayS));
  ExpectSameRows(db.Rows(kForecastSkillRowsByDay), v10, "after the migration");
  ExpectSameRows(db.Rows("SELECT * FROM forecast_skill_day ORDER BY day"), v10,
                 "the materialised rows");
  RawDb copy(store->upgrade().backup_path);
  EXPECT_EQ(copy.Number("PRAGMA user_version"), 10.0);
}

}  // namespace
}  // namespace pvtwin
