// Local days in the store (schema version 9): local_day's bounds in
// Europe/Vienna across both daylight saving changes of 2024, and
// forecast_skill_local and performance_daily_local against what the test
// computes from the rows it wrote. The test reckons Vienna's days with the
// EU rule (CET = UTC+1, CEST = UTC+2 from 01:00 UTC on the last Sunday of
// March to 01:00 UTC on the last Sunday of October), not with the tz
// database the store uses. Real store files.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "io/store/store.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/store_schema_v10.h"
#include "tests/support/store_schema_v11.h"

namespace pvtwin {
namespace {

using testing::RawDb;
namespace chr = std::chrono;

using testing::kDayS;

std::int64_t UtcMidnight(chr::year_month_day ymd) {
  return chr::sys_days{ymd}.time_since_epoch().count() * kDayS;
}

std::int64_t LastSundayUtcOneAm(chr::year y, chr::month m) {
  const chr::sys_days last{chr::year_month_weekday_last{y, m, chr::weekday_last{chr::Sunday}}};
  return last.time_since_epoch().count() * kDayS + 3600;
}

// UTC instant of 00:00 Vienna time on the date ymd (EU rule).
std::int64_t ViennaMidnight(chr::year_month_day ymd) {
  const std::int64_t dst_from = LastSundayUtcOneAm(ymd.year(), chr::March);
  const std::int64_t dst_to = LastSundayUtcOneAm(ymd.year(), chr::October);
  const std::int64_t cet = UtcMidnight(ymd) - 3600;
  return cet >= dst_from && cet < dst_to ? UtcMidnight(ymd) - 7200 : cet;
}

std::string DateText(chr::year_month_day ymd) {
  char text[16];
  std::snprintf(text, sizeof text, "%04d-%02u-%02u", static_cast<int>(ymd.year()),
                static_cast<unsigned>(ymd.month()), static_cast<unsigned>(ymd.day()));
  return text;
}

struct Day {
  std::string date;
  std::int64_t start = 0, end = 0;
};

// The days (Vienna or UTC) that overlap [from, to).
std::vector<Day> DaysOverlapping(std::int64_t from, std::int64_t to, bool vienna) {
  std::vector<Day> days;
  chr::year_month_day ymd{chr::sys_days{chr::days{from / kDayS - 1}}};
  for (;; ymd = chr::sys_days{ymd} + chr::days{1}) {
    const chr::year_month_day next{chr::sys_days{ymd} + chr::days{1}};
    Day d{DateText(ymd), vienna ? ViennaMidnight(ymd) : UtcMidnight(ymd),
          vienna ? ViennaMidnight(next) : UtcMidnight(next)};
    if (d.start >= to) break;
    if (d.end > from) days.push_back(d);
  }
  return days;
}

// One measured minute; valid 0 on a few.
struct Minute {
  std::int64_t ts = 0;
  double p_el_w = 0.0, q_th_w = 0.0, g_poa_w_m2 = 0.0;
  bool valid = true;
};

// The minutes of [from, to): a clear-sky-like day shape in UTC, with a few
// invalid minutes and a little night-time irradiance noise below zero.
std::vector<Minute> MakeMinutes(std::int64_t from, std::int64_t to) {
  std::vector<Minute> minutes;
  for (std::int64_t ts = from; ts < to; ts += 60) {
    const double hour = static_cast<double>(((ts % kDayS) + kDayS) % kDayS) / 3600.0;
    const double sun = std::max(0.0, std::sin((hour - 5.0) / 14.0 * std::numbers::pi));
    Minute m;
    m.ts = ts;
    m.g_poa_w_m2 = sun > 0.0 ? 900.0 * sun + 10.0 * std::sin(ts / 600.0) : -2.0;
    m.p_el_w = 180.0 * sun + 3.0 * std::cos(ts / 300.0);
    m.q_th_w = 700.0 * sun - 40.0 + 5.0 * std::sin(ts / 900.0);
    m.valid = (ts / 60) % 97 != 0;
    minutes.push_back(m);
  }
  return minutes;
}

Series ToSeries(const std::vector<Minute>& minutes) {
  Series s;
  s.step_s = 60.0;
  for (const Minute& m : minutes) {
    s.time_s.push_back(m.ts);
    s[Channel::kPElW].push_back(m.p_el_w);
    s[Channel::kQThW].push_back(m.q_th_w);
    s[Channel::kGPoaWM2].push_back(m.g_poa_w_m2);
    s[Channel::kValid].push_back(m.valid ? 1.0 : 0.0);
  }
  return s;
}

// A forecast issue: rows for the minutes of [issued_at, issued_at + 36 h)
// that are measured, each off the measurement by an error of its own.
struct Issue {
  std::int64_t issued_at = 0;
  std::map<std::int64_t, std::pair<double, double>> rows;  // ts -> p_el_w, q_th_w
};

std::vector<Issue> MakeIssues(const std::vector<Minute>& minutes) {
  std::vector<Issue> issues;
  const std::int64_t from = minutes.front().ts - kDayS, to = minutes.back().ts;
  for (std::int64_t day = from - ((from % kDayS) + kDayS) % kDayS; day < to; day += kDayS) {
    // Every 3 h from 23:00 UTC (winter's local midnight) on, and at 23:30
    // UTC (after it, before the UTC midnight).
    for (const std::int64_t at : {-3600, -1800, 7200, 18000, 28800, 39600, 50400, 61200, 72000}) {
      Issue issue;
      issue.issued_at = day + at;
      for (const Minute& m : minutes) {
        if (m.ts < issue.issued_at || m.ts >= issue.issued_at + 36 * 3600) continue;
        const double e = static_cast<double>((issue.issued_at / 60 + m.ts / 60) % 23) - 9.0;
        issue.rows[m.ts] = {m.p_el_w + 2.0 * e, m.q_th_w - 5.0 * e + 1.0};
      }
      if (!issue.rows.empty()) issues.push_back(issue);
    }
  }
  return issues;
}

// A UTC day's model energies: whatever a calibration said (not scored for
// the electrical output on every third day).
DayPerformance ModelDay(std::int64_t day_start) {
  const std::int64_t k = day_start / kDayS;
  DayPerformance d;
  d.day_start_s = day_start;
  d.valid_minutes = 1000;
  d.e_el_model_wh = 1500.0 + 37.0 * static_cast<double>(k % 7);
  d.e_th_model_wh = 4200.0 - 53.0 * static_cast<double>(k % 5);
  d.e_el_meas_wh = d.e_th_meas_wh = 1.0;  // not used by the local view
  d.pi_el = k % 3 == 1 ? kNoValue : 0.9;
  d.pi_th = 0.95;
  d.pi_el_low = d.pi_el_high = d.pi_th_low = d.pi_th_high = kNoValue;
  return d;
}

std::int64_t UtcDayOf(std::int64_t ts) { return ts - ((ts % kDayS) + kDayS) % kDayS; }

class StoreLocalDayTest : public testing::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    if (const char* tz = std::getenv("TZ")) saved_tz_ = tz;
  }
  void TearDown() override {
    if (saved_tz_) {
      ::setenv("TZ", saved_tz_->c_str(), 1);
    } else {
      ::unsetenv("TZ");
    }
    ::tzset();
    TempDirTest::TearDown();
  }

  std::string DbPath() const { return (dir_ / "pvtwin.db").string(); }

  std::unique_ptr<Store> OpenIn(const std::string& zone) {
    StoreOptions options;
    options.time_zone = zone;
    options.log = {};
    std::string error;
    std::unique_ptr<Store> store = Store::Open(DbPath(), options, &error);
    EXPECT_NE(store, nullptr) << error;
    return store;
  }

  // Writes minutes, forecasts and performance days of [from, to) into the
  // store, and keeps them for the expected values.
  void Fill(Store* store, std::int64_t from, std::int64_t to) {
    const std::vector<Minute> minutes = MakeMinutes(from, to);
    const std::vector<Issue> issues = MakeIssues(minutes);
    minutes_.insert(minutes_.end(), minutes.begin(), minutes.end());
    issues_.insert(issues_.end(), issues.begin(), issues.end());
    std::string error;
    ASSERT_TRUE(store->WriteMinutes(ToSeries(minutes), &error)) << error;
    for (const Issue& issue : issues) {
      std::vector<Store::ForecastRow> rows;
      for (const auto& entry : issue.rows) {
        Store::ForecastRow& row = rows.emplace_back();
        row.ts = entry.first;
        row.p_el_w = entry.second.first;
        row.q_th_w = entry.second.second;
      }
      ASSERT_TRUE(store->InsertForecast(issue.issued_at, 0, "test", rows, &error)) << error;
    }
    for (std::int64_t day = UtcDayOf(from); day < to; day += kDayS) {
      ASSERT_TRUE(store->WritePerformanceDay(ModelDay(day), 0, &error)) << error;
    }
  }

  // A Vienna store with three UTC days of data from each of the dates
  // first (the days around the clock changes).
  std::unique_ptr<Store> ViennaStore(std::initializer_list<chr::year_month_day> firsts) {
    auto store = OpenIn("Europe/Vienna");
    if (store == nullptr) return store;
    for (const chr::year_month_day& first : firsts) {
      Fill(store.get(), UtcMidnight(first), UtcMidnight(first) + 3 * kDayS);
    }
    return store;
  }

  // The newest issue at or before day_start with a row at ts.
  const Issue* ScoredIssue(std::int64_t ts, std::int64_t day_start) const {
    const Issue* best = nullptr;
    for (const Issue& issue : issues_) {
      if (issue.issued_at <= day_start && issue.rows.count(ts) &&
          (best == nullptr || issue.issued_at > best->issued_at)) {
        best = &issue;
      }
    }
    return best;
  }

  struct Skill {
    double mae_p = 0.0, mae_q = 0.0;
    int minutes = 0;
  };
  // forecast_skill's MAE and minutes of the day [start, end), by the test.
  Skill ExpectedSkill(const Day& day) const {
    Skill s;
    for (const Minute& m : minutes_) {
      if (m.ts < day.start || m.ts >= day.end || !m.valid) continue;
      const Issue* issue = ScoredIssue(m.ts, day.start);
      if (issue == nullptr) continue;
      const auto& f = issue->rows.at(m.ts);
      s.mae_p += std::abs(f.first - m.p_el_w);
      s.mae_q += std::abs(f.second - m.q_th_w);
      ++s.minutes;
    }
    s.mae_p /= s.minutes;
    s.mae_q /= s.minutes;
    return s;
  }

  struct Performance {
    double e_el_meas = 0.0, e_th_meas = 0.0, e_el_model = 0.0, e_th_model = 0.0;
    bool el_scored = true;
    int valid_minutes = 0;
  };
  // performance_daily_local's row of the day, by the test: measured
  // energies summed, model energies apportioned by irradiation.
  Performance ExpectedPerformance(const Day& day) const {
    Performance p;
    std::map<std::int64_t, double> g_in_day, g_whole;  // per UTC day
    for (const Minute& m : minutes_) {
      if (!m.valid) continue;
      const double g = std::max(m.g_poa_w_m2, 0.0);
      g_whole[UtcDayOf(m.ts)] += g;
      if (m.ts < day.start || m.ts >= day.end) continue;
      g_in_day[UtcDayOf(m.ts)] += g;
      p.e_el_meas += m.p_el_w / 60.0;
      p.e_th_meas += m.q_th_w / 60.0;
      ++p.valid_minutes;
    }
    for (const auto& [utc_day, g] : g_in_day) {
      const DayPerformance model = ModelDay(utc_day);
      const double share = g / g_whole.at(utc_day);
      p.e_el_model += model.e_el_model_wh * share;
      p.e_th_model += model.e_th_model_wh * share;
      p.el_scored = p.el_scored && std::isfinite(model.pi_el);
    }
    return p;
  }

  std::optional<std::string> saved_tz_;
  std::vector<Minute> minutes_;
  std::vector<Issue> issues_;
};

const chr::year_month_day kSpring{chr::year{2024}, chr::March, chr::day{30}};
const chr::year_month_day kAutumn{chr::year{2024}, chr::October, chr::day{26}};

// Three UTC days of minutes from the UTC midnight of `first`.
std::pair<std::int64_t, std::int64_t> ThreeDays(chr::year_month_day first) {
  return {UtcMidnight(first), UtcMidnight(first) + 3 * kDayS};
}

TEST_F(StoreLocalDayTest, ViennaDaysHave23And25HoursAtTheClockChanges) {
  auto store = ViennaStore({kSpring, kAutumn});
  ASSERT_NE(store, nullptr);
  ASSERT_FALSE(HasFatalFailure());
  RawDb db(DbPath());
  EXPECT_EQ(db.Number("SELECT end_ts - start_ts FROM local_day WHERE day = '2024-03-31'"),
            23.0 * 3600);
  EXPECT_EQ(db.Number("SELECT end_ts - start_ts FROM local_day WHERE day = '2024-10-27'"),
            25.0 * 3600);
  // Every day of the data and two after it, as the EU rule has them.
  for (const auto& first : {kSpring, kAutumn}) {
    const auto [from, to] = ThreeDays(first);
    for (const Day& day : DaysOverlapping(from, to + 2 * kDayS, true)) {
      const auto rows =
          db.Rows("SELECT start_ts, end_ts FROM local_day WHERE day = '" + day.date + "'");
      ASSERT_EQ(rows.size(), 1u) << day.date;
      EXPECT_EQ(rows[0][0], std::to_string(day.start)) << day.date;
      EXPECT_EQ(rows[0][1], std::to_string(day.end)) << day.date;
    }
  }
  EXPECT_EQ(db.Text("SELECT zone FROM local_day_zone"), "Europe/Vienna");
}

TEST_F(StoreLocalDayTest, ForecastSkillLocalScoresLocalDaysAgainstTheIssueOfLocalMidnight) {
  auto store = ViennaStore({kSpring, kAutumn});
  ASSERT_NE(store, nullptr);
  ASSERT_FALSE(HasFatalFailure());
  RawDb db(DbPath());
  for (const auto& first : {kSpring, kAutumn}) {
    const auto [from, to] = ThreeDays(first);
    for (const Day& day : DaysOverlapping(from, to, true)) {
      const Skill expected = ExpectedSkill(day);
      const auto rows =
          db.Rows("SELECT mae_p_el_w, mae_q_th_w, minutes FROM forecast_skill_local WHERE day = '" +
                  day.date + "'");
      ASSERT_EQ(rows.size(), 1u) << day.date;
      EXPECT_NEAR(std::stod(rows[0][0]), expected.mae_p, 1e-9) << day.date;
      EXPECT_NEAR(std::stod(rows[0][1]), expected.mae_q, 1e-9) << day.date;
      EXPECT_EQ(std::stoi(rows[0][2]), expected.minutes) << day.date;
    }
  }
  // The local day of the spring change holds 23 h of minutes, the autumn
  // one 25 h (all of them measured).
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min m JOIN local_day d ON m.ts >= "
                      "d.start_ts AND m.ts < d.end_ts WHERE d.day = '2024-10-27'"),
            25.0 * 60);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM measurement_1min m JOIN local_day d ON m.ts >= "
                      "d.start_ts AND m.ts < d.end_ts WHERE d.day = '2024-03-31'"),
            23.0 * 60);
}

TEST_F(StoreLocalDayTest, PerformanceDailyLocalApportionsTheUtcDaysModelEnergies) {
  auto store = ViennaStore({kSpring, kAutumn});
  ASSERT_NE(store, nullptr);
  ASSERT_FALSE(HasFatalFailure());
  RawDb db(DbPath());
  int checked = 0, unscored = 0;
  for (const Day& day :
       DaysOverlapping(ThreeDays(kSpring).first, ThreeDays(kAutumn).second, true)) {
    if (!(db.Number("SELECT COUNT(*) FROM measurement_1min m JOIN local_day d ON m.ts >= "
                    "d.start_ts AND m.ts < d.end_ts WHERE d.day = '" +
                    day.date + "'") > 0)) {
      continue;  // between the seasons
    }
    const Performance expected = ExpectedPerformance(day);
    const auto rows = db.Rows(
        "SELECT e_el_meas_wh, e_el_model_wh, e_th_meas_wh, e_th_model_wh, pi_el, pi_th, "
        "valid_minutes FROM performance_daily_local WHERE day = '" +
        day.date + "'");
    ASSERT_EQ(rows.size(), 1u) << day.date;
    const auto& r = rows[0];
    // pi: NULL where not scored, or where no model energy falls in the
    // local day (a day of night hours only).
    const double pi_el = expected.el_scored && expected.e_el_model != 0.0
                             ? expected.e_el_meas / expected.e_el_model
                             : std::nan("");
    const double pi_th =
        expected.e_th_model != 0.0 ? expected.e_th_meas / expected.e_th_model : std::nan("");
    ASSERT_EQ(std::count(r.begin(), r.end(), "NULL"), std::isnan(pi_el) + std::isnan(pi_th))
        << day.date << ": " << ::testing::PrintToString(r);
    EXPECT_NEAR(std::stod(r[0]), expected.e_el_meas, 1e-6) << day.date;
    EXPECT_NEAR(std::stod(r[1]), expected.e_el_model, 1e-6) << day.date;
    EXPECT_NEAR(std::stod(r[2]), expected.e_th_meas, 1e-6) << day.date;
    EXPECT_NEAR(std::stod(r[3]), expected.e_th_model, 1e-6) << day.date;
    if (!std::isnan(pi_el)) {
      EXPECT_NEAR(std::stod(r[4]), pi_el, 1e-9) << day.date;
    }
    if (!std::isnan(pi_th)) {
      EXPECT_NEAR(std::stod(r[5]), pi_th, 1e-9) << day.date;
    }
    unscored += !expected.el_scored;
    EXPECT_EQ(std::stoi(r[6]), expected.valid_minutes) << day.date;
    ++checked;
  }
  // Each season: its first day (from 01:00 or 02:00), the day of the
  // change, the next, and the day the data ends in (to 01:00 or 02:00).
  EXPECT_EQ(checked, 8);
  EXPECT_GT(unscored, 0);
}

// In a UTC store the local views are the UTC ones, day by day.
TEST_F(StoreLocalDayTest, AUtcStoresLocalViewsEqualTheUtcViews) {
  auto store = OpenIn("UTC");
  ASSERT_NE(store, nullptr);
  const auto [from, to] = ThreeDays(kSpring);
  ASSERT_NO_FATAL_FAILURE(Fill(store.get(), from, to));
  RawDb db(DbPath());
  const auto utc = db.Rows("SELECT * FROM forecast_skill ORDER BY day");
  const auto local = db.Rows("SELECT * FROM forecast_skill_local ORDER BY day");
  ASSERT_EQ(utc.size(), 3u);
  ASSERT_EQ(local.size(), utc.size());
  const std::vector<Day> days = DaysOverlapping(from, to, false);
  for (std::size_t i = 0; i < utc.size(); ++i) {
    EXPECT_EQ(utc[i][0], std::to_string(days[i].start));
    EXPECT_EQ(local[i][0], days[i].date);
    for (std::size_t c = 1; c < utc[i].size(); ++c) EXPECT_EQ(local[i][c], utc[i][c]) << c;
  }
  const auto perf_utc = db.Rows(
      "SELECT e_el_model_wh, e_th_model_wh, pi_th IS NULL, pi_el IS NULL FROM performance_daily "
      "ORDER BY day");
  const auto perf_local = db.Rows(
      "SELECT e_el_model_wh, e_th_model_wh, pi_th IS NULL, pi_el IS NULL, e_el_meas_wh "
      "FROM performance_daily_local ORDER BY day");
  ASSERT_EQ(perf_local.size(), perf_utc.size());
  for (std::size_t i = 0; i < perf_utc.size(); ++i) {
    EXPECT_NEAR(std::stod(perf_local[i][0]), std::stod(perf_utc[i][0]), 1e-9);
    EXPECT_NEAR(std::stod(perf_local[i][1]), std::stod(perf_utc[i][1]), 1e-9);
    EXPECT_EQ(perf_local[i][2], perf_utc[i][2]);
    EXPECT_EQ(perf_local[i][3], perf_utc[i][3]);
    EXPECT_NEAR(std::stod(perf_local[i][4]), ExpectedPerformance(days[i]).e_el_meas, 1e-6);
  }
}

// Pruning keeps the issue each local day is scored against.
TEST_F(StoreLocalDayTest, PruningLeavesForecastSkillLocalAsItWas) {
  auto store = ViennaStore({kSpring});
  ASSERT_NE(store, nullptr);
  ASSERT_FALSE(HasFatalFailure());
  const auto [from, to] = ThreeDays(kSpring);
  RawDb db(DbPath());
  const double before_rows = db.Number("SELECT COUNT(*) FROM forecast");
  const auto before = db.Rows("SELECT * FROM forecast_skill_local ORDER BY day");
  std::string error;
  ASSERT_TRUE(store->PruneForecasts(from - kDayS, to + kDayS, &error)) << error;
  EXPECT_LT(db.Number("SELECT COUNT(*) FROM forecast"), before_rows);
  EXPECT_EQ(db.Rows("SELECT * FROM forecast_skill_local ORDER BY day"), before);
}

// A store opened in another zone makes its local days anew; one opened
// without a zone keeps them; a migrated store gets them for its data.
TEST_F(StoreLocalDayTest, LocalDaysFollowTheZoneAndAreMadeAtMigration) {
  const auto [from, to] = ThreeDays(kAutumn);
  {
    auto store = OpenIn("UTC");
    ASSERT_NE(store, nullptr);
    ASSERT_NO_FATAL_FAILURE(Fill(store.get(), from, to));
  }
  const std::string q = "SELECT end_ts - start_ts FROM local_day WHERE day = '2024-10-27'";
  EXPECT_EQ(RawDb(DbPath()).Number(q), 24.0 * 3600);
  ASSERT_NE(OpenIn("Europe/Vienna"), nullptr);
  EXPECT_EQ(RawDb(DbPath()).Number(q), 25.0 * 3600);
  ASSERT_NE(OpenIn(""), nullptr);
  EXPECT_EQ(RawDb(DbPath()).Number(q), 25.0 * 3600);
  {
    RawDb db(DbPath());
    // Back to version 8: version 10's forecast.basis (its forecast_latest
    // stands in as a view of that name, which version 10 replaces), then
    // version 9's local days.
    static_assert(kStoreSchemaVersion == 12, "take the new version's objects back here too");
    std::vector<std::string> downgrade = testing::DropSchemaV12();
    for (const std::string& sql : testing::DropSchemaV11())
      downgrade.push_back(sql);  // and its view:
    downgrade.push_back("DROP VIEW forecast_skill");
    downgrade.push_back(std::string("CREATE VIEW forecast_skill") + testing::kForecastSkillColumns +
                        " AS " + testing::kForecastSkillV10);
    for (const char* sql : {"DROP VIEW forecast_latest", "DROP VIEW forecast_skill_local",
                            "ALTER TABLE forecast DROP COLUMN basis",
                            "CREATE VIEW forecast_latest(ts) AS SELECT ts FROM forecast",
                            "DROP VIEW performance_daily_local", "DROP TABLE local_day_zone",
                            "DROP TABLE local_day", "PRAGMA user_version = 8"}) {
      downgrade.push_back(sql);
    }
    for (const std::string& sql : downgrade) ASSERT_EQ(db.Exec(sql), SQLITE_OK) << sql;
  }
  ASSERT_NE(OpenIn("Europe/Vienna"), nullptr);
  RawDb db(DbPath());
  EXPECT_EQ(db.Number("PRAGMA user_version"), static_cast<double>(kStoreSchemaVersion));
  EXPECT_EQ(db.Number(q), 25.0 * 3600);
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM local_day"),
            static_cast<double>(DaysOverlapping(from, to + 2 * kDayS, true).size()));
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_local"), 4.0);
}

TEST_F(StoreLocalDayTest, AnUnknownZoneIsRefusedAtOpen) {
  StoreOptions options;
  options.time_zone = "Europe/Atlantis";
  std::string error;
  EXPECT_EQ(Store::Open(DbPath(), options, &error), nullptr);
  EXPECT_NE(error.find("Europe/Atlantis"), std::string::npos) << error;
}

}  // namespace
}  // namespace pvtwin
