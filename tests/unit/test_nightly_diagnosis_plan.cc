// daemon/service/nightly_diagnosis.h, NightlyDiagnosis::PlanFor: when the
// nightly diagnosis starts and on which days. Without a change it runs at
// most every every_days on the calibration's window; after a change that a
// performance alarm saw inside the window it judges the days since, every
// night while the change lies inside the window.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <numbers>
#include <string>

#include "core/common/calendar.h"
#include "core/physics/solar_position.h"
#include "daemon/service/nightly_diagnosis.h"
#include "tests/support/fixtures.h"
#include "tests/support/sqlite_db.h"

namespace pvtwin::cli {
namespace {

using testing::kDayS;
constexpr std::int64_t kJune16 = 1750032000;  // 2025-06-16T00:00:00Z

// Tonight's job: the 14-day calibration window ending at midnight, the
// daemon's clock at 00:30.
NightlyDiagnosis::Job Tonight(std::int64_t change_from = 0) {
  NightlyDiagnosis::Job job;
  job.window_start = kJune16 - 14 * kDayS;
  job.window_end = kJune16;
  job.now_s = kJune16 + 1800;
  job.calibration_id = 7;
  job.change_from = change_from;
  return job;
}

Store::DiagnosisRow Row(std::int64_t run_at, std::int64_t window_start, const char* verdict) {
  Store::DiagnosisRow row;
  row.run_at = run_at;
  row.window_start = window_start;
  row.window_end = run_at - 1800;
  row.verdict = verdict;
  return row;
}

TEST(NightlyDiagnosisPlan, WithoutAChangeEveryEveryDaysOnTheCalibrationWindow) {
  DiagnosisConfig config;
  config.every_days = 7;
  const NightlyDiagnosis::Job job = Tonight();
  NightlyDiagnosis::Plan plan = NightlyDiagnosis::PlanFor(config, nullptr, job);
  EXPECT_TRUE(plan.start);  // the first diagnosis of the store
  EXPECT_EQ(plan.window_start, job.window_start);
  EXPECT_EQ(plan.why, "");
  const Store::DiagnosisRow three_days = Row(job.now_s - 3 * kDayS, job.window_start, "unknown");
  EXPECT_FALSE(NightlyDiagnosis::PlanFor(config, &three_days, job).start);
  // Seven days less the hour the nightly runs drift by.
  const Store::DiagnosisRow a_week = Row(job.now_s - 7 * kDayS + 3000, job.window_start, "none");
  EXPECT_TRUE(NightlyDiagnosis::PlanFor(config, &a_week, job).start);
}

TEST(NightlyDiagnosisPlan, AChangeInsideTheWindowIsJudgedOnTheDaysSinceEveryNight) {
  DiagnosisConfig config;
  config.every_days = 7;
  const std::int64_t change = kJune16 - 7 * kDayS;  // clipping from 2025-06-09
  const NightlyDiagnosis::Job job = Tonight(change);
  // Last night's diagnosis, on the calibration window or already on the
  // days since the change, whatever it said: tonight's judges the days
  // since the change (a day more), whatever every_days says.
  for (const std::int64_t last_from : {job.window_start, change}) {
    for (const char* verdict : {"undecided", "unknown", "none", "pv_clipping"}) {
      const Store::DiagnosisRow last = Row(job.now_s - kDayS, last_from, verdict);
      const NightlyDiagnosis::Plan plan = NightlyDiagnosis::PlanFor(config, &last, job);
      EXPECT_TRUE(plan.start) << verdict;
      EXPECT_EQ(plan.window_start, change) << verdict;
      EXPECT_NE(plan.why.find("2025-06-09"), std::string::npos) << plan.why;
    }
  }
  EXPECT_TRUE(NightlyDiagnosis::PlanFor(config, nullptr, job).start);
}

TEST(NightlyDiagnosisPlan, AChangeTooRecentOrBeforeTheWindowLeavesTheWindowAlone) {
  DiagnosisConfig config;
  config.every_days = 7;
  const Store::DiagnosisRow recent = Row(kJune16 - kDayS, kJune16 - 15 * kDayS, "unknown");
  // One day since the change: no training and held-out day of the changed plant yet.
  NightlyDiagnosis::Job job = Tonight(kJune16 - kDayS);
  NightlyDiagnosis::Plan plan = NightlyDiagnosis::PlanFor(config, &recent, job);
  EXPECT_FALSE(plan.start);
  EXPECT_EQ(plan.window_start, job.window_start);
  // Two days since: judged.
  job = Tonight(kJune16 - 2 * kDayS);
  plan = NightlyDiagnosis::PlanFor(config, &recent, job);
  EXPECT_TRUE(plan.start);
  EXPECT_EQ(plan.window_start, kJune16 - 2 * kDayS);
  // A change at or before the window's start: the whole window is the
  // changed plant, the calibration's window and every_days as always.
  for (const std::int64_t from : {kJune16 - 14 * kDayS, kJune16 - 20 * kDayS}) {
    job = Tonight(from);
    plan = NightlyDiagnosis::PlanFor(config, &recent, job);
    EXPECT_FALSE(plan.start);
    EXPECT_EQ(plan.window_start, job.window_start);
    EXPECT_EQ(plan.why, "");
  }
}

TEST(NightlyDiagnosisPlan, TheWindowHoldsWholeLocalSolarDays) {
  DiagnosisConfig config;
  config.every_days = 7;
  // Graz, 15.44° E: local mean solar midnight at 22:58:14 UTC. The night's
  // run at 02:00 CEST ends the calibration window at 00:00 UTC, an hour
  // into the next solar day: the diagnosis ends at that day's start, and a
  // change from 9 June (00:00 UTC) is judged from its solar day's start.
  Plant graz;
  graz.longitude_rad = 15.44 * std::numbers::pi / 180.0;
  const std::int64_t offset = SolarDayOffsetS(graz);
  ASSERT_EQ(offset, 3706);
  const std::int64_t solar_midnight_16 = kJune16 - offset;
  NightlyDiagnosis::Job job = Tonight(kJune16 - 7 * kDayS);
  job.solar_offset_s = offset;
  NightlyDiagnosis::Plan plan = NightlyDiagnosis::PlanFor(config, nullptr, job);
  EXPECT_TRUE(plan.start);
  EXPECT_EQ(plan.window_end, solar_midnight_16);
  EXPECT_EQ(plan.window_start, solar_midnight_16 - 7 * kDayS);
  EXPECT_EQ(SolarDayStartS(plan.window_end - 1, offset), solar_midnight_16 - kDayS);
  // Two UTC days since the change are two whole solar days: judged.
  job.change_from = kJune16 - 2 * kDayS;
  plan = NightlyDiagnosis::PlanFor(config, nullptr, job);
  EXPECT_TRUE(plan.start);
  EXPECT_EQ(plan.window_end - plan.window_start, 2 * kDayS);
  // Without a change, the calibration's window, rounded the same way.
  job.change_from = 0;
  plan = NightlyDiagnosis::PlanFor(config, nullptr, job);
  EXPECT_EQ(plan.window_start, solar_midnight_16 - 14 * kDayS);
  EXPECT_EQ(plan.window_end, solar_midnight_16);
  // Chicago, 87.63° W (solar midnight at 05:50:31 UTC), run at 02:00 CDT
  // (07:00 UTC): the window ends at the solar midnight an hour before; its
  // start, 00:00 UTC (18:09 solar time the evening before), moves to the
  // solar midnight after it, the change day's own.
  Plant chicago;
  chicago.longitude_rad = -87.63 * std::numbers::pi / 180.0;
  job.solar_offset_s = SolarDayOffsetS(chicago);
  job.window_end = kJune16 + 7 * 3600;
  job.change_from = kJune16 - 7 * kDayS;
  plan = NightlyDiagnosis::PlanFor(config, nullptr, job);
  EXPECT_EQ(plan.window_end, kJune16 - job.solar_offset_s);
  EXPECT_EQ(plan.window_start, kJune16 - 7 * kDayS - job.solar_offset_s);
  EXPECT_LT(plan.window_end, job.window_end);
  EXPECT_GT(plan.window_start, job.change_from);
}

class CalibrationBeforeChangeTest : public testing::TempDirTest {};

// The plant before a change is the calibration whose window ended before the
// changed plant saw the sun: the example site (47.358° N, 16.128° E), whose
// local solar day starts at 22:55 UTC and whose sun rises near 02:52 UTC on
// 9 June; the daemon calibrates at 02:00 CEST, its window ending at 00:00 UTC.
TEST_F(CalibrationBeforeChangeTest, TheNewestAcceptedOneEndedBeforeTheChangesFirstSunlight) {
  std::string error;
  std::unique_ptr<Store> store = Store::Open((dir_ / "pvtwin.db").string(), &error);
  ASSERT_NE(store, nullptr) << error;
  constexpr std::int64_t kJune9 = kJune16 - 7 * kDayS;  // 2025-06-09T00:00:00Z
  auto insert = [&](std::int64_t window_end, bool accepted) {
    Store::CalibrationRow row;
    row.run_at = window_end + 60;
    row.variant = "2N1Ccolwr";
    row.window_start = window_end - 14 * kDayS;
    row.window_end = window_end;
    row.status = accepted ? "accepted" : "rejected";
    row.params_json = "{\"u_front_w_m2k\": 9.5}";
    row.accepted = accepted;
    EXPECT_TRUE(store->InsertCalibration(&row, &error)) << error;
    return row.id;
  };
  const std::int64_t day_before = insert(kJune9 - kDayS, true);
  const std::int64_t change_night = insert(kJune9 + 180, true);  // its dark hours only
  insert(kJune9 + 600, false);                                   // rejected
  insert(kJune9 + 4 * 3600, true);  // after sunrise: it holds the changed plant's light
  insert(kJune9 + kDayS, true);

  Plant site;
  site.latitude_rad = 47.358 * std::numbers::pi / 180.0;
  site.longitude_rad = 16.128 * std::numbers::pi / 180.0;
  NightlyDiagnosis::Job job = Tonight(kJune9);
  job.solar_offset_s = SolarDayOffsetS(site);
  job.site = SiteAtStandardPressure(site);
  NightlyDiagnosis::Plan plan = NightlyDiagnosis::PlanFor(DiagnosisConfig{}, nullptr, job);
  ASSERT_TRUE(plan.since_change);
  ASSERT_EQ(plan.window_start, kJune9 - job.solar_offset_s);
  Store::CalibrationRow row;
  bool found = false;
  ASSERT_TRUE(NightlyDiagnosis::CalibrationBeforeChange(*store, plan, job, &row, &found, &error))
      << error;
  ASSERT_TRUE(found);
  EXPECT_EQ(row.id, change_night);
  // A change a day earlier: the change night's calibration holds a day of it.
  job.change_from = kJune9 - kDayS;
  plan = NightlyDiagnosis::PlanFor(DiagnosisConfig{}, nullptr, job);
  ASSERT_TRUE(NightlyDiagnosis::CalibrationBeforeChange(*store, plan, job, &row, &found, &error));
  ASSERT_TRUE(found);
  EXPECT_EQ(row.id, day_before);
  // Earlier than every calibration: none; without a change: none asked for.
  job.change_from = kJune9 - 3 * kDayS;
  plan = NightlyDiagnosis::PlanFor(DiagnosisConfig{}, nullptr, job);
  ASSERT_TRUE(plan.since_change);
  ASSERT_TRUE(NightlyDiagnosis::CalibrationBeforeChange(*store, plan, job, &row, &found, &error));
  EXPECT_FALSE(found);
  job.change_from = 0;
  plan = NightlyDiagnosis::PlanFor(DiagnosisConfig{}, nullptr, job);
  ASSERT_TRUE(NightlyDiagnosis::CalibrationBeforeChange(*store, plan, job, &row, &found, &error));
  EXPECT_FALSE(found);
}

}  // namespace
}  // namespace pvtwin::cli
