// The central day-ahead forecasts (central schema version 5, io/fleet/upload.h
// forecast_day_ahead) against a real PostgreSQL and the real `pvtwin upload`:
// a plant that re-issues its forecast every hour, across UTC midnights, keeps
// each minute's day-ahead issue centrally, whatever the order of upload, and
// the central forecast_skill equals the store's per day.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "tests/fleet/upload_fixture.h"

namespace pvtwin {
namespace {

using testing::RawDb;
using testing::RunPvtwin;
using upload_test::ExpectSameRows;
using upload_test::kMorning;
using upload_test::LocalRows;
using upload_test::Upload;

// 2024-06-01 00:00 UTC: the first of three days of 1-min rows.
constexpr std::int64_t kDay0 = kMorning - 8 * 3600;
// The hourly issues: from 21:00 UTC before the first day to 01:00 UTC of the
// third, each for the 30 h after it (as far as there are measurements).
constexpr int kFirstHour = -3;
constexpr int kLastHour = 49;
constexpr int kHorizonH = 30;

// The store's rows of forecast that are day-ahead rows: per ts the newest
// issue at or before 00:00 UTC of its day (the store's forecast_skill rule).
const char* const kLocalDayAhead =
    "f WHERE issued_at = (SELECT max(g.issued_at) FROM forecast g WHERE g.ts = f.ts "
    "AND g.issued_at <= f.ts - ((f.ts % 86400) + 86400) % 86400)";
const char* const kSkillColumns =
    "day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, skill_p_el, skill_q_th, "
    "coverage_p10_p90, minutes, coverage_p_el, coverage_q_th";

class DayAhead : public Upload {
 protected:
  // The issue made at kDay0 + hour h: made from the measurements, with an
  // error of its own per issue, so that the issue a minute is scored
  // against shows in the day's MAE; every column of the forecast set.
  static void Issue(RawDb* db, int h) {
    const std::string at = std::to_string(kDay0 + h * 3600LL);
    const std::string k = std::to_string(((h % 5) + 5) % 5);
    ASSERT_EQ(db->Exec("INSERT INTO forecast(issued_at, ts, p_el_w, q_th_w, p_el_w_p10, "
                       "p_el_w_p90, q_th_w_p10, q_th_w_p90, p_el_w_ref, q_th_w_ref, p_el_w_p50, "
                       "q_th_w_p50) SELECT " +
                       at + ", ts, p_el_w * (1.04 + 0.03 * " + k + ") + 2 * " + k +
                       ", q_th_w * (0.95 - 0.02 * " + k + ") - 3 * " + k +
                       ", p_el_w * 0.9 - 10, p_el_w * 1.2 + 10, q_th_w * 0.8 - 40, "
                       "q_th_w * 1.1 + 40, p_el_w * 0.7 + " +
                       k +
                       ", q_th_w * 0.6 + 10, "
                       "p_el_w * 1.05, q_th_w * 0.97 FROM measurement_1min WHERE ts >= " +
                       at + " AND ts < " + at + " + " + std::to_string(kHorizonH * 3600)),
              SQLITE_OK)
        << h;
  }
  // The issues hours, in this order, with an upload (batches of batch_rows)
  // after every `every` of them and after the last.
  void IssueAndUpload(const std::string& name, const std::vector<int>& hours, int every) {
    for (std::size_t i = 0; i < hours.size(); ++i) {
      {
        RawDb db(Db(name));
        Issue(&db, hours[i]);
      }
      if ((i + 1) % every == 0 || i + 1 == hours.size()) {
        const auto run = UploadOnce(name);
        ASSERT_EQ(run.exit_code, 0) << run.err;
        ASSERT_EQ(Pending(name), 0.0);
      }
    }
  }
  static std::vector<int> Hours(int first, int last) {
    std::vector<int> hours;
    for (int h = first; h <= last; ++h) hours.push_back(h);
    return hours;
  }

  // The central forecast_skill of the plant equals its store's, day by day
  // and column by column; returns the days.
  std::size_t ExpectSkillAsStore(const std::string& name) {
    const auto local = LocalRows(
        Db(name), std::string("SELECT ") + kSkillColumns + " FROM forecast_skill ORDER BY day");
    const auto central =
        pg_.Query(std::string("SELECT ") + kSkillColumns +
                      " FROM forecast_skill WHERE plant_id = '" + name + "' ORDER BY day",
                  "fleet");
    EXPECT_EQ(local.size(), central.size()) << name;
    if (local.size() != central.size()) return 0;
    for (std::size_t r = 0; r < local.size(); ++r) {
      for (std::size_t c = 0; c < local[r].size(); ++c) {
        const auto& cell = local[r][c];
        if (cell.type == SQLITE_NULL) {
          EXPECT_EQ(central[r][c], "NULL") << name << " day " << r << " column " << c;
          continue;
        }
        const double x = cell.type == SQLITE_INTEGER ? static_cast<double>(cell.i) : cell.x;
        EXPECT_NEAR(std::strtod(central[r][c].c_str(), nullptr), x, 1e-9 * (1.0 + std::fabs(x)))
            << name << " day " << r << " column " << c << ": central " << central[r][c];
      }
    }
    return local.size();
  }
  // The central forecast_day_ahead of the plant holds the store's day-ahead
  // rows, value by value.
  std::size_t ExpectDayAheadAsStore(const std::string& name) {
    return ExpectSameRows(pg_, Db(name), name, "forecast", kLocalDayAhead, "ts",
                          "forecast_day_ahead");
  }
  // Two plants' central forecast_skill rows agree to rounding (PostgreSQL
  // may sum the minutes in another order).
  static void ExpectSameSkill(const std::vector<std::vector<std::string>>& a,
                              const std::vector<std::vector<std::string>>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t r = 0; r < a.size(); ++r) {
      ASSERT_EQ(a[r].size(), b[r].size());
      for (std::size_t c = 0; c < a[r].size(); ++c) {
        const double x = std::strtod(a[r][c].c_str(), nullptr);
        EXPECT_NEAR(std::strtod(b[r][c].c_str(), nullptr), x, 1e-9 * (1.0 + std::fabs(x)))
            << "day " << r << " column " << c << ": " << a[r][c] << " vs " << b[r][c];
      }
    }
  }
  // The plant's central rows of a table (every column but plant_id), as text.
  std::vector<std::vector<std::string>> CentralRows(const std::string& table,
                                                    const std::string& name,
                                                    const std::string& order) {
    auto rows = pg_.Query(
        "SELECT * FROM " + table + " WHERE plant_id = '" + name + "' ORDER BY " + order, "fleet");
    for (auto& row : rows) row.erase(row.begin());  // plant_id first
    return rows;
  }
};

// Hourly issues, uploaded every five issues in batches of 700 rows: issues
// at 23:00 and 00:00 UTC are followed by later ones before (and after) they
// are sent. Centrally every minute keeps its day-ahead issue, and the three
// days score as in the store. The central forecast, which keeps only the
// newest issue of each minute, holds the day-ahead issue of few minutes
// (what version 4's view scored).
TEST_F(DayAhead, HourlyReissuesKeepEachMinutesDayAheadIssueAndTheSkillOfTheStore) {
  WritePlant("hourly", "batch_rows = 700\n");
  Import("hourly", kDay0, 3, 60, 5);
  IssueAndUpload("hourly", Hours(kFirstHour, kLastHour), 5);

  EXPECT_EQ(ExpectDayAheadAsStore("hourly"), 3u * 1440);
  EXPECT_EQ(ExpectSkillAsStore("hourly"), 3u);
  EXPECT_GE(Central("SELECT min(minutes) FROM forecast_skill WHERE plant_id = 'hourly'"), 360);
  ExpectPlantEqual("hourly");
  // Of the newest issues only those of each day's first hour are day-ahead.
  EXPECT_EQ(Central("SELECT count(*) FROM forecast WHERE issued_at <= ts - mod(mod(ts, 86400) + "
                    "86400, 86400)"),
            3 * 60);
}

// The same issues sent in another order give the same central rows: one
// plant uploads them in time order and, after four more issues around the
// last midnight, everything again (--resend); the other uploads them newest
// first (older issues arrive last). A further --resend changes nothing.
TEST_F(DayAhead, AnotherUploadOrderAndAResendGiveTheSameCentralRows) {
  for (const std::string name : {"forward", "backward"}) {
    WritePlant(name, "batch_rows = 900\n");
    Import(name, kDay0, 3, 60, 7);
  }
  IssueAndUpload("forward", Hours(kFirstHour, kLastHour - 4), 4);
  {
    RawDb db(Db("forward"));
    for (int h = kLastHour - 3; h <= kLastHour; ++h) Issue(&db, h);
  }
  auto run = RunPvtwin(dir_.path(), "upload --once --resend --config forward.toml");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::vector<int> newest_first = Hours(kFirstHour, kLastHour);
  std::reverse(newest_first.begin(), newest_first.end());
  IssueAndUpload("backward", newest_first, 4);

  const auto day_ahead = CentralRows("forecast_day_ahead", "forward", "ts");
  EXPECT_EQ(day_ahead.size(), 3u * 1440);
  EXPECT_EQ(CentralRows("forecast_day_ahead", "backward", "ts"), day_ahead);
  EXPECT_EQ(CentralRows("forecast", "backward", "ts"), CentralRows("forecast", "forward", "ts"));
  const auto skill = CentralRows("forecast_skill", "forward", "day");
  EXPECT_EQ(skill.size(), 3u);
  ExpectSameSkill(CentralRows("forecast_skill", "backward", "day"), skill);
  for (const std::string name : {"forward", "backward"}) {
    ExpectDayAheadAsStore(name);
    ExpectSkillAsStore(name);
  }

  run = RunPvtwin(dir_.path(), "upload --once --resend --config backward.toml");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(CentralRows("forecast_day_ahead", "backward", "ts"), day_ahead);
  ExpectSameSkill(CentralRows("forecast_skill", "backward", "day"), skill);
}

// A central database of version 4 (no forecast_day_ahead, forecast_skill
// over forecast) and a store whose forecast triggers queue only the newest
// issue of each ts, as pvtwin made them before: `upload --init` migrates to
// version 5 and fills forecast_day_ahead with the central forecast rows that
// are day-ahead rows; the store's triggers are replaced and its day-ahead
// rows queued, and the next upload completes the table as the store has it.
TEST_F(DayAhead, AVersion4DatabaseGainsTheTableFromItsForecastRowsAndTheStoreRequeues) {
  WritePlant("old", "");
  Import("old", kDay0, 2, 60, 9);
  IssueAndUpload("old", Hours(kFirstHour, 30), 8);
  // Back to version 4, centrally and in the store.
  ASSERT_EQ(pg_.Text("DROP TABLE forecast_day_ahead CASCADE", "fleet"), "");
  ASSERT_EQ(pg_.Text("CREATE VIEW forecast_skill(plant_id, day, mae_p_el_w, mae_q_th_w, "
                     "nmae_p_el, nmae_q_th, skill_p_el, skill_q_th, coverage_p10_p90, minutes, "
                     "coverage_p_el, coverage_q_th) AS SELECT NULL::text, NULL::bigint, "
                     "NULL::double precision, NULL::double precision, NULL::double precision, "
                     "NULL::double precision, NULL::double precision, NULL::double precision, "
                     "NULL::double precision, NULL::bigint, NULL::double precision, NULL::double "
                     "precision WHERE false",
                     "fleet"),
            "");
  ASSERT_EQ(pg_.Text("UPDATE pvtwin_schema SET version = 4", "fleet"), "");
  {
    RawDb db(Db("old"));
    for (const std::string when : {"INSERT", "UPDATE"}) {
      const std::string trigger =
          "upload_queue_forecast_" + std::string(when == "INSERT" ? "insert" : "update");
      ASSERT_EQ(
          db.Exec("DROP TRIGGER " + trigger + "; CREATE TRIGGER " + trigger + " AFTER " + when +
                  " ON forecast BEGIN DELETE FROM upload_queue WHERE table_name = "
                  "'forecast' AND k1 = NEW.ts AND k2 <= NEW.issued_at; INSERT INTO "
                  "upload_queue(table_name, k1, k2) VALUES('forecast', NEW.ts, "
                  "NEW.issued_at); END"),
          SQLITE_OK);
    }
    // Two issues under the old triggers: only the newest of each ts queued.
    Issue(&db, 31);
    Issue(&db, 32);
  }
  const long long qualifying = Central(
      "SELECT count(*) FROM forecast WHERE issued_at <= ts - mod(mod(ts, 86400) + 86400, 86400)");
  ASSERT_GT(qualifying, 0);

  auto run = RunPvtwin(dir_.path(), "upload --init --config old.toml");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(Central("SELECT max(version) FROM pvtwin_schema"), 5);
  EXPECT_EQ(Central("SELECT count(*) FROM forecast_day_ahead"), qualifying);
  EXPECT_EQ(Central("SELECT count(*) FROM (SELECT * FROM forecast WHERE issued_at <= ts - "
                    "mod(mod(ts, 86400) + 86400, 86400) EXCEPT SELECT * FROM "
                    "forecast_day_ahead) x"),
            0);
  {
    RawDb db(Db("old"));
    EXPECT_NE(db.Text("SELECT sql FROM sqlite_schema WHERE name = "
                      "'upload_queue_forecast_insert'")
                  .find("k2 >"),
              std::string::npos);
    // Only the forecast's triggers were of another text.
    EXPECT_EQ(db.Number("SELECT rows_pending FROM upload_status WHERE table_name = "
                        "'measurement_1min'"),
              0.0);
    EXPECT_GT(db.Number("SELECT rows_pending FROM upload_status WHERE table_name = 'forecast'"),
              0.0);
  }
  run = UploadOnce("old");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(ExpectDayAheadAsStore("old"), 2u * 1440);
  EXPECT_GT(Central("SELECT count(*) FROM forecast_day_ahead"), qualifying);
  EXPECT_EQ(ExpectSkillAsStore("old"), 2u);
}

}  // namespace
}  // namespace pvtwin
