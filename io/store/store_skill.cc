// forecast_skill materialised per UTC day (schema versions 11 and 12,
// io/store/store.h): Store::RefreshForecastSkill writes forecast_skill_day
// for the closed days not yet materialised and for the dirty ones (the
// triggers of store_schema.cc mark a materialised day dirty when its
// measurements or its scored forecasts change), so that the view computes
// only the rest (normally today) from measurement_1min and, for days
// without 1-min rows, measurement_interval.
#include <sqlite3.h>

#include <string>

#include "io/store/store_impl.h"

namespace pvtwin {

using namespace store_detail;

namespace {

// The rows of forecast_skill_day, in the view's column order.
constexpr const char* kInsertSkillDays =
    " INSERT INTO forecast_skill_day(day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, "
    "skill_p_el, skill_q_th, coverage_p10_p90, minutes, coverage_p_el, coverage_q_th)";

}  // namespace

bool Store::RefreshForecastSkill(std::int64_t now_ts, int* days_written, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  int written = 0;
  const bool ok = db.Run(
      true, "refresh forecast_skill_day",
      [&]() -> DbStatus {
        written = 0;
        return db.RefreshForecastSkill(now_ts, &written);
      },
      error);
  if (ok && days_written != nullptr) *days_written = written;
  return ok;
}

DbStatus Store::Impl::RefreshForecastSkill(std::int64_t now_ts, int* days_written) {
  // Days before today's 00:00 UTC are over.
  const std::int64_t today = now_ts - ((now_ts % kSecondsPerDay) + kSecondsPerDay) % kSecondsPerDay;
  sqlite3_stmt* stmt = nullptr;
  DbStatus s = Prepare("SELECT done_before FROM forecast_skill_state WHERE id = 1", &stmt);
  if (!s.ok()) return s;
  const int rc = sqlite3_step(stmt);
  if (rc != SQLITE_ROW && rc != SQLITE_DONE) return Fail(rc, "read forecast_skill_state");
  const std::int64_t done = rc == SQLITE_ROW ? sqlite3_column_int64(stmt, 0) : kNoLowerBound;
  sqlite3_reset(stmt);
  const std::int64_t new_done = std::max(done, today);

  // The dirty closed days and the days of [done, today): their old rows go,
  // their new ones are computed from the measurements and forecasts.
  s = Prepare(
      "DELETE FROM forecast_skill_day WHERE day IN (SELECT day FROM forecast_skill_dirty WHERE "
      "day < ?1) OR (day >= ?2 AND day < ?1)",
      &stmt);
  if (!s.ok()) return s;
  sqlite3_bind_int64(stmt, 1, today);
  sqlite3_bind_int64(stmt, 2, done);
  s = StepDone(stmt, "delete the forecast_skill_day rows to refresh");
  if (!s.ok()) return s;
  s = Prepare("WITH pairs AS (" +
                  SkillPairsV12("forecast_skill_dirty x CROSS JOIN {m} m ON m.ts >= "
                                "x.day AND m.ts < x.day + 86400",
                                "x.day < ?1 AND x.day < ?2") +
                  ")" + kInsertSkillDays + SkillAggregatesV12(),
              &stmt);
  if (!s.ok()) return s;
  sqlite3_bind_int64(stmt, 1, today);
  sqlite3_bind_int64(stmt, 2, done);
  s = StepDone(stmt, "materialise the dirty days of forecast_skill");
  if (!s.ok()) return s;
  *days_written += sqlite3_changes(db);
  if (today > done) {
    s = Prepare("WITH pairs AS (" + SkillPairsV12("{m} m", "m.ts >= ?1 AND m.ts < ?2") + ")" +
                    kInsertSkillDays + SkillAggregatesV12(),
                &stmt);
    if (!s.ok()) return s;
    sqlite3_bind_int64(stmt, 1, done);
    sqlite3_bind_int64(stmt, 2, today);
    s = StepDone(stmt, "materialise forecast_skill before " + std::to_string(today));
    if (!s.ok()) return s;
    *days_written += sqlite3_changes(db);
  }
  s = Prepare("DELETE FROM forecast_skill_dirty WHERE day < ?", &stmt);
  if (!s.ok()) return s;
  sqlite3_bind_int64(stmt, 1, today);
  s = StepDone(stmt, "clear forecast_skill_dirty");
  if (!s.ok()) return s;
  s = Prepare("INSERT OR REPLACE INTO forecast_skill_state(id, done_before) VALUES(1, ?)", &stmt);
  if (!s.ok()) return s;
  sqlite3_bind_int64(stmt, 1, new_done);
  return StepDone(stmt, "write forecast_skill_state");
}

}  // namespace pvtwin
