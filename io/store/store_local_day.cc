// The store's local days (schema version 9, io/store/store.h): the civil days
// of StoreOptions::time_zone with their UTC bounds, which SQLite cannot
// compute (it knows no time zones), written for the days of the stored
// measurements and two days ahead, so that forecast_skill_local and
// performance_daily_local group minutes by local day with a join.
#include <sqlite3.h>

#include <string>
#include <vector>

#include "io/platform/local_time.h"
#include "io/store/store_impl.h"

namespace pvtwin {

using namespace store_detail;

namespace {

// Days written ahead of the newest measurement: the day-ahead forecast's
// minutes have their local day before they are measured.
constexpr std::int64_t kLocalDaysAhead = 2;

}  // namespace

DbStatus Store::Impl::CoverLocalDays(std::int64_t from_ts, std::int64_t to_ts) {
  std::vector<LocalDay> days;
  std::string why;
  if (!LocalDaysOverlapping(zone, from_ts, to_ts + kLocalDaysAhead * kSecondsPerDay, &days, &why)) {
    return {SQLITE_ERROR, "local days of " + zone, why};
  }
  sqlite3_stmt* stmt = nullptr;
  DbStatus s =
      Prepare("INSERT OR IGNORE INTO local_day(day, start_ts, end_ts) VALUES(?, ?, ?)", &stmt);
  if (!s.ok()) return s;
  for (const LocalDay& day : days) {
    sqlite3_reset(stmt);
    sqlite3_bind_text(stmt, 1, day.date.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(stmt, 2, day.start_s);
    sqlite3_bind_int64(stmt, 3, day.end_s);
    s = StepDone(stmt, "write local_day " + day.date);
    if (!s.ok()) return s;
  }
  return {};
}

bool Store::Impl::SyncLocalDays(std::string* error) {
  Impl& db = *this;
  return db.Run(
      true, "make local_day",
      [&db]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare("SELECT zone FROM local_day_zone WHERE id = 1", &stmt);
        if (!s.ok()) return s;
        const std::string stored = sqlite3_step(stmt) == SQLITE_ROW ? ColumnText(stmt, 0) : "";
        sqlite3_reset(stmt);
        db.zone = !db.options.time_zone.empty() ? db.options.time_zone
                  : !stored.empty()             ? stored
                                                : "UTC";
        if (db.zone == stored) return {};
        s = db.Exec("DELETE FROM local_day");
        if (!s.ok()) return s;
        s = db.Prepare("INSERT OR REPLACE INTO local_day_zone(id, zone) VALUES(1, ?)", &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_text(stmt, 1, db.zone.c_str(), -1, SQLITE_TRANSIENT);
        s = db.StepDone(stmt, "write local_day_zone");
        if (!s.ok()) return s;
        return db.CoverMeasuredDays();
      },
      error);
}

DbStatus Store::Impl::CoverMeasuredDays() {
  sqlite3_stmt* stmt = nullptr;
  // The span of the measurements: 1-min rows and interval rows.
  DbStatus s = Prepare(
      "SELECT MIN(a), MAX(b) FROM (SELECT MIN(ts) AS a, MAX(ts) + 60 AS b FROM "
      "measurement_1min UNION ALL SELECT MIN(ts), MAX(ts + step_s) FROM measurement_interval)",
      &stmt);
  if (!s.ok()) return s;
  const int rc = sqlite3_step(stmt);
  if (rc != SQLITE_ROW) return Fail(rc, "span of the measurements");
  const bool any = sqlite3_column_type(stmt, 0) != SQLITE_NULL;
  const std::int64_t first = sqlite3_column_int64(stmt, 0);
  const std::int64_t end = sqlite3_column_int64(stmt, 1);
  sqlite3_reset(stmt);
  return any ? CoverLocalDays(first, end) : DbStatus{};
}

}  // namespace pvtwin
