// forecast_skill of days without 1-min rows (store schema version 12,
// issue 53 item 5): a day that has only measurement_interval rows (10- and
// 15-min here) is scored from them, each row weighted by its minutes, and
// the view's row equals the test's own computation in C++ over the rows; a
// day with 1-min rows keeps version 10's values to the last digit;
// forecast_skill_local does the same per local day (Vienna); the triggers
// on measurement_interval mark such days dirty and only them; a year of
// 10-min rows costs the view only today's rows after the refresh (SQLite
// VM steps, as a ratio); a version 11 store migrates with its interval days
// materialised and its other rows kept. Real store files.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cmath>
#include <cstdio>
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

using testing::ExpectSameRows;
using testing::Measured;
using testing::RawDb;
using testing::Rows;
using testing::ScoreDayByHand;

using testing::kDayS;
using testing::kJune1_2024UtcS;
using testing::kForecastSkillRowsByDay;
using testing::kForecastSkillV10RowsByDay;

// The view's rows of the given days.
Rows RowsOfDays(const Rows& rows, const std::vector<std::int64_t>& days) {
  Rows out;
  for (const auto& row : rows) {
    for (const std::int64_t day : days) {
      if (row[0] == std::to_string(day)) out.push_back(row);
    }
  }
  return out;
}

class SkillIntervalTest : public testing::TempDirTest {
 protected:
  std::string DbPath() const { return (dir_ / "pvtwin.db").string(); }
  std::unique_ptr<Store> Open(const std::string& zone = "") {
    StoreOptions options;
    options.log = nullptr;
    options.time_zone = zone;
    std::string error;
    std::unique_ptr<Store> store = Store::Open(DbPath(), options, &error);
    EXPECT_NE(store, nullptr) << error;
    return store;
  }

  // Day 0 and day 1 of 1-min rows; 10-min rows of days 1 and 2 (day 1's
  // are not scored: it has 1-min rows); 15-min rows of day 3 until noon;
  // hourly issues 26 h ahead from 12 h before day 0.
  static void FillDays(Store* store) {
    std::string error;
    ASSERT_TRUE(store->WriteMinutes(Measured(kJune1_2024UtcS, kJune1_2024UtcS + 2 * kDayS, 60, 0.0),
                                    &error))
        << error;
    ASSERT_TRUE(store->WriteIntervalRows(
        Measured(kJune1_2024UtcS + kDayS, kJune1_2024UtcS + 3 * kDayS, 600, 25.0), &error))
        << error;
    ASSERT_TRUE(store->WriteIntervalRows(
        Measured(kJune1_2024UtcS + 3 * kDayS, kJune1_2024UtcS + 3 * kDayS + kDayS / 2, 900, -15.0),
        &error))
        << error;
    testing::InsertHourlyIssues(store, kJune1_2024UtcS - kDayS / 2,
                                kJune1_2024UtcS + 3 * kDayS + kDayS / 2);
  }

  // The rows forecast_skill should have for the interval days `days`,
  // computed by the test.
  static Rows IntervalDaysByHand(RawDb& db, const std::vector<std::int64_t>& days) {
    Rows rows;
    for (const std::int64_t day : days) {
      rows.push_back(ScoreDayByHand(db, "measurement_interval", day, day + kDayS, day)
                         .Cells(std::to_string(day)));
    }
    return rows;
  }
};

// Days 2 and 3 (interval rows only) are scored with each row weighted by
// its step; days 0 and 1 keep version 10's values exactly, before and
// after the refresh materialises the closed days.
TEST_F(SkillIntervalTest, IntervalDaysAreScoredByTheirStepAndMinuteDaysKeepTheirValues) {
  auto store = Open();
  ASSERT_NE(store, nullptr);
  ASSERT_NO_FATAL_FAILURE(FillDays(store.get()));
  RawDb db(DbPath());
  const std::int64_t day2 = kJune1_2024UtcS + 2 * kDayS, day3 = kJune1_2024UtcS + 3 * kDayS;
  const Rows view = db.Rows(kForecastSkillRowsByDay);
  ASSERT_EQ(view.size(), 4u) << "days 0 to 3 are scored (version 11: days 0 and 1)";
  const Rows v10 = db.Rows(kForecastSkillV10RowsByDay);
  ASSERT_EQ(v10.size(), 2u);
  EXPECT_EQ(RowsOfDays(view, {kJune1_2024UtcS, kJune1_2024UtcS + kDayS}), v10)
      << "the same text, to the last digit";
  ExpectSameRows(RowsOfDays(view, {day2, day3}), IntervalDaysByHand(db, {day2, day3}),
                 "interval days against the test's computation", 1e-9);
  // minutes stays minutes: ten per scored 10-min row, an integer.
  const auto by_hand = ScoreDayByHand(db, "measurement_interval", day2, day2 + kDayS, day2);
  EXPECT_GT(by_hand.pairs, 100);
  EXPECT_EQ(db.Text("SELECT minutes FROM forecast_skill WHERE day = " + std::to_string(day2)),
            std::to_string(10 * by_hand.pairs));
  EXPECT_EQ(
      db.Text("SELECT typeof(minutes) FROM forecast_skill WHERE day = " + std::to_string(day3)),
      "integer");
  EXPECT_FALSE(std::isnan(
      db.Number("SELECT skill_p_el FROM forecast_skill WHERE day = " + std::to_string(day3))))
      << "half a day of 15-min rows is 360 minutes or more";

  int written = 0;
  std::string error;
  ASSERT_TRUE(store->RefreshForecastSkill(day3 + kDayS / 2, &written, &error)) << error;
  EXPECT_EQ(written, 3) << "the closed days 0, 1 and 2";
  EXPECT_EQ(db.Rows("SELECT * FROM forecast_skill_day ORDER BY day"),
            RowsOfDays(view, {kJune1_2024UtcS, kJune1_2024UtcS + kDayS, day2}));
  EXPECT_EQ(db.Rows(kForecastSkillRowsByDay), view) << "the same rows, materialised";
}

// A late 10-min import into day 2 marks it dirty, one into day 0 (scored
// from its 1-min rows) does not; a 1-min row in day 2 switches it to 1-min
// scoring, and deleting it switches it back.
TEST_F(SkillIntervalTest, IntervalTriggersMarkOnlyDaysScoredFromIntervalRows) {
  auto store = Open();
  ASSERT_NE(store, nullptr);
  ASSERT_NO_FATAL_FAILURE(FillDays(store.get()));
  const std::int64_t day2 = kJune1_2024UtcS + 2 * kDayS,
                     now = kJune1_2024UtcS + 3 * kDayS + kDayS / 2;
  std::string error;
  ASSERT_TRUE(store->RefreshForecastSkill(now, nullptr, &error)) << error;
  RawDb db(DbPath());
  const std::string of_day2 = " WHERE day = " + std::to_string(day2);
  const std::string materialised = db.Text("SELECT mae_p_el_w FROM forecast_skill_day" + of_day2);

  ASSERT_TRUE(store->WriteIntervalRows(
      Measured(kJune1_2024UtcS + 6 * 3600, kJune1_2024UtcS + 9 * 3600, 600, 80.0), &error))
      << error;
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_dirty"), 0.0)
      << "day 0 is scored from its 1-min rows: its interval rows change nothing";
  ASSERT_TRUE(
      store->WriteIntervalRows(Measured(day2 + 6 * 3600, day2 + 9 * 3600, 600, 80.0), &error))
      << error;
  EXPECT_EQ(db.Rows("SELECT day FROM forecast_skill_dirty"), Rows{{std::to_string(day2)}});
  ExpectSameRows(db.Rows("SELECT * FROM forecast_skill" + of_day2), IntervalDaysByHand(db, {day2}),
                 "day 2 computed live after the late import", 1e-9);
  EXPECT_NE(db.Text("SELECT mae_p_el_w FROM forecast_skill" + of_day2), materialised);
  int written = 0;
  ASSERT_TRUE(store->RefreshForecastSkill(now, &written, &error)) << error;
  EXPECT_EQ(written, 1);
  ExpectSameRows(db.Rows("SELECT * FROM forecast_skill_day" + of_day2),
                 IntervalDaysByHand(db, {day2}), "day 2 materialised again", 1e-9);

  // One 1-min row in day 2: the day is scored from it alone, as version 10.
  ASSERT_TRUE(
      store->WriteMinutes(Measured(day2 + 12 * 3600, day2 + 12 * 3600 + 60, 60, 0.0), &error))
      << error;
  EXPECT_EQ(db.Rows("SELECT * FROM forecast_skill" + of_day2),
            RowsOfDays(db.Rows(kForecastSkillV10RowsByDay), {day2}));
  EXPECT_EQ(db.Number("SELECT minutes FROM forecast_skill" + of_day2), 1.0);
  ASSERT_TRUE(store->RefreshForecastSkill(now, nullptr, &error)) << error;
  ASSERT_EQ(db.Exec("DELETE FROM measurement_1min WHERE ts >= " + std::to_string(day2)), SQLITE_OK);
  ExpectSameRows(db.Rows("SELECT * FROM forecast_skill" + of_day2), IntervalDaysByHand(db, {day2}),
                 "day 2 back on its interval rows", 1e-9);
}

// forecast_skill_local in Vienna (UTC + 2 h): a local day with 1-min rows
// keeps version 11's values exactly (2024-06-03, 22:00 UTC of day 1 to
// 22:00 of day 2, is scored from its 2 h of 1-min rows, not from its 22 h
// of 10-min rows); 2024-06-04, without 1-min rows, mixes 10- and 15-min
// rows, each weighted by its step, against the issue of its local midnight.
TEST_F(SkillIntervalTest, LocalDaysWithoutMinuteRowsAreScoredFromIntervalRows) {
  auto store = Open("Europe/Vienna");
  ASSERT_NE(store, nullptr);
  ASSERT_NO_FATAL_FAILURE(FillDays(store.get()));
  RawDb db(DbPath());
  const Rows local = db.Rows("SELECT * FROM forecast_skill_local ORDER BY day");
  const Rows v11 = db.Rows(std::string(testing::kForecastSkillLocalV11) + " ORDER BY day");
  ASSERT_EQ(v11.size(), 3u) << "2024-06-01 to 2024-06-03 hold 1-min rows";
  ASSERT_EQ(local.size(), 4u) << "and 2024-06-04 interval rows only";
  EXPECT_EQ(Rows(local.begin(), local.begin() + 3), v11);
  EXPECT_LE(std::stod(local[2][8]), 120.0) << "2024-06-03: its 2 h of 1-min rows at most";
  Rows by_hand;
  for (const auto& row : local) {
    const auto bounds =
        db.Rows("SELECT start_ts, end_ts FROM local_day WHERE day = '" + row[0] + "'");
    ASSERT_EQ(bounds.size(), 1u);
    const std::int64_t start = std::stoll(bounds[0][0]), end = std::stoll(bounds[0][1]);
    const bool minutes =
        db.Number("SELECT COUNT(*) FROM measurement_1min WHERE ts >= " + bounds[0][0] +
                  " AND ts < " + bounds[0][1]) > 0;
    by_hand.push_back(
        ScoreDayByHand(db, minutes ? "measurement_1min" : "measurement_interval", start, end, start)
            .Cells(row[0]));
  }
  ExpectSameRows(local, by_hand, "forecast_skill_local against the test's computation", 1e-9);
  // 2024-06-04 holds 2 h of 10-min rows and 12 h of 15-min rows.
  EXPECT_EQ(db.Number("SELECT COUNT(DISTINCT step_s) FROM measurement_interval WHERE ts >= "
                      "(SELECT start_ts FROM local_day WHERE day = '2024-06-04') AND ts < "
                      "(SELECT end_ts FROM local_day WHERE day = '2024-06-04')"),
            2.0);
}

// A year of 10-min rows and one issue a day, made by SQL. Before the
// refresh the view computes every day live; after it, only today: its VM
// steps stay below those of one more whole day, a small fraction of the
// live year, and no table of rows is scanned in full.
TEST_F(SkillIntervalTest, AfterTheRefreshAYearOfTenMinuteRowsCostsTheViewOnlyToday) {
  const std::int64_t today = kJune1_2024UtcS + 365 * kDayS;
  const std::int64_t now = today + kDayS / 2;
  { ASSERT_NE(Open(), nullptr); }
  RawDb db(DbPath());
  const std::string rows = "WITH RECURSIVE t(ts) AS (SELECT " + std::to_string(kJune1_2024UtcS) +
                           " UNION ALL SELECT ts + 600 FROM t WHERE ts + 600 < " +
                           std::to_string(now) + ") ";
  ASSERT_EQ(
      db.Exec(rows + "INSERT INTO measurement_interval(ts, step_s, p_el_w, q_th_w, valid) SELECT "
                     "ts, 600, 100 + (ts / 600 * 7919) % 250, 400 + (ts / 600 * 104729) % 450, 1 "
                     "FROM t"),
      SQLITE_OK);
  ASSERT_EQ(
      db.Exec(rows + "INSERT INTO forecast(issued_at, ts, p_el_w, q_th_w, p_el_w_p10, p_el_w_p90, "
                     "q_th_w_p10, q_th_w_p90, p_el_w_ref, q_th_w_ref) SELECT ts - ts % 86400 - "
                     "3600, ts, 210, 590, 150, 260, 400, 800, 200, 600 FROM t"),
      SQLITE_OK);
  const std::string view = "SELECT * FROM forecast_skill";
  const testing::QueryCost live = testing::CostOf(DbPath(), view);
  EXPECT_EQ(live.rows, 366) << "every day computed live";
  const Rows before = db.Rows(kForecastSkillRowsByDay);
  {
    auto store = Open();
    int written = 0;
    std::string error;
    ASSERT_TRUE(store->RefreshForecastSkill(now, &written, &error)) << error;
    EXPECT_EQ(written, 365);
  }
  ExpectSameRows(db.Rows(kForecastSkillRowsByDay), before, "after the refresh");
  const std::int64_t day100 = kJune1_2024UtcS + 100 * kDayS;
  ExpectSameRows(RowsOfDays(before, {day100}), IntervalDaysByHand(db, {day100}),
                 "day 100 against the test's computation", 1e-9);
  const testing::QueryCost cost = testing::CostOf(DbPath(), view);
  EXPECT_EQ(cost.rows, 366);
  ASSERT_EQ(db.Exec("UPDATE measurement_interval SET p_el_w = p_el_w + 1 WHERE ts = " +
                    std::to_string(today - 3600)),
            SQLITE_OK);
  const testing::QueryCost with_yesterday = testing::CostOf(DbPath(), view);
  const long one_day = with_yesterday.vm_steps - cost.vm_steps;
  EXPECT_LT(cost.vm_steps, one_day) << "today's half day costs less than one whole day";
  EXPECT_LT(50 * cost.vm_steps, live.vm_steps) << "the live view computes 365.5 days";
  EXPECT_LT(cost.fullscan_steps, 144) << "no table of rows is scanned in full";
  EXPECT_GT(live.vm_steps, 365 * one_day / 2);
  std::printf(
      "forecast_skill over a year of 10-min rows: view %ld VM steps (%ld full-scan), with "
      "yesterday dirty %ld, every day live %ld (%ld full-scan)\n",
      cost.vm_steps, cost.fullscan_steps, with_yesterday.vm_steps, live.vm_steps,
      live.fullscan_steps);
  int searches = 0;
  for (const auto& row : db.Rows("EXPLAIN QUERY PLAN " + view)) {
    const std::string detail = row.back() + " ";
    EXPECT_NE(detail.rfind("SCAN m ", 0), 0u) << detail;
    searches += detail.rfind("SEARCH m USING INTEGER PRIMARY KEY", 0) == 0;
  }
  EXPECT_EQ(searches, 4) << "each table: from done_before on, and the dirty days";
}

// A store as version 11 left it (no row for the closed interval day 2, the
// views of 1-min rows only, no interval triggers) migrates to version 12:
// day 2 is materialised from its interval rows, days 0 and 1 keep their
// rows, and the backup is the version 11 file.
TEST_F(SkillIntervalTest, MigratingFromVersionElevenScoresTheIntervalDays) {
  const std::int64_t day2 = kJune1_2024UtcS + 2 * kDayS, day3 = kJune1_2024UtcS + 3 * kDayS;
  Rows v11;
  {
    auto store = Open();
    ASSERT_NE(store, nullptr);
    ASSERT_NO_FATAL_FAILURE(FillDays(store.get()));
    std::string error;
    ASSERT_TRUE(store->RefreshForecastSkill(day3 + kDayS / 2, nullptr, &error)) << error;
  }
  {
    RawDb db(DbPath());
    static_assert(kStoreSchemaVersion == 12, "take the new version's objects back here too");
    std::vector<std::string> downgrade = testing::DropSchemaV12();
    downgrade.push_back("DELETE FROM forecast_skill_day WHERE day = " + std::to_string(day2));
    downgrade.push_back("DROP VIEW forecast_skill");
    downgrade.push_back(std::string("CREATE VIEW forecast_skill") + testing::kForecastSkillColumns +
                        " AS " + testing::kForecastSkillV10);
    downgrade.push_back("DROP VIEW forecast_skill_local");
    downgrade.push_back(std::string("CREATE VIEW forecast_skill_local") +
                        testing::kForecastSkillColumns + " AS " + testing::kForecastSkillLocalV11);
    downgrade.push_back("PRAGMA user_version = 11");
    for (const std::string& sql : downgrade) ASSERT_EQ(db.Exec(sql), SQLITE_OK) << sql;
    v11 = db.Rows(kForecastSkillRowsByDay);
    ASSERT_EQ(v11.size(), 2u) << "version 11 scores the 1-min days only";
  }
  auto store = Open();
  ASSERT_NE(store, nullptr);
  EXPECT_EQ(store->upgrade().from_version, 11);
  EXPECT_EQ(store->upgrade().to_version, 12);
  RawDb db(DbPath());
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_day"), 3.0) << "days 0, 1 and 2";
  const Rows view = db.Rows(kForecastSkillRowsByDay);
  EXPECT_EQ(RowsOfDays(view, {kJune1_2024UtcS, kJune1_2024UtcS + kDayS}), v11);
  ExpectSameRows(RowsOfDays(view, {day2, day3}), IntervalDaysByHand(db, {day2, day3}),
                 "the interval days after the migration", 1e-9);
  ExpectSameRows(db.Rows("SELECT * FROM forecast_skill_day WHERE day = " + std::to_string(day2)),
                 IntervalDaysByHand(db, {day2}), "day 2 materialised by the migration", 1e-9);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_local"), 4.0);
  ASSERT_EQ(db.Exec("DELETE FROM measurement_interval WHERE ts = " + std::to_string(day2 + 43200)),
            SQLITE_OK);
  EXPECT_EQ(db.Rows("SELECT day FROM forecast_skill_dirty"), Rows{{std::to_string(day2)}})
      << "the migration made the interval triggers";
  RawDb copy(store->upgrade().backup_path);
  EXPECT_EQ(copy.Number("PRAGMA user_version"), 11.0);
}

}  // namespace
}  // namespace pvtwin
