// Private to io/store: Store::Impl (the connection, its prepared statements
// and the transaction runner) and the helpers the store's files share.
// store.cc opens and closes the store, store_schema.cc holds the schema and
// its migrations, store_samples.cc the measurements and forecast inputs,
// store_forecast.cc calibrations, forecasts and their scores,
// store_monitoring.cc events, sensor faults and diagnoses, store_local_day.cc
// the local days of the configured zone, store_skill.cc the materialised
// forecast_skill. Not included
// outside io/store.
#ifndef PVTWIN_IO_STORE_STORE_IMPL_H_
#define PVTWIN_IO_STORE_STORE_IMPL_H_

#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "core/common/units.h"
#include "io/platform/log.h"
#include "io/store/store.h"

namespace pvtwin {
namespace store_detail {

inline constexpr std::int64_t kSecondsPerDay = 86400;
inline constexpr std::int64_t kNoLowerBound = std::numeric_limits<std::int64_t>::min();

inline std::int64_t MinuteStart(std::int64_t t_s) {
  std::int64_t k = t_s / kMinuteS;
  if (t_s % kMinuteS < 0) --k;
  return k * kMinuteS;
}

// SQL value of channel c: degrees for the aoi_deg column, else as in core.
inline double ToSql(Channel c, double core_value) {
  return c == Channel::kAoiRad ? RadToDeg(core_value) : core_value;
}
inline double FromSql(Channel c, double sql_value) {
  return c == Channel::kAoiRad ? DegToRad(sql_value) : sql_value;
}

// "c1, c2, ..." of every canonical channel, and "?, ?, ..." of the same count.
inline std::string ChannelColumns(const std::string& prefix = "") {
  std::string s;
  for (const ChannelInfo& info : kChannels) {
    if (!s.empty()) s += ", ";
    s += prefix + std::string(info.name);
  }
  return s;
}
inline std::string Placeholders(std::size_t n) {
  std::string s;
  for (std::size_t i = 0; i < n; ++i) s += i ? ", ?" : "?";
  return s;
}
inline std::string ChannelColumnDefs() {
  std::string s;
  for (const ChannelInfo& info : kChannels) s += ", " + std::string(info.name) + " REAL";
  return s;
}

// Channels of the forecast input tables (columns in this order).
inline constexpr Channel kWeatherChannels[] = {
    Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaDiffuseWM2,
    Channel::kTAmbC,   Channel::kWindMS, Channel::kTSkyC,  Channel::kLwDownWM2};
inline constexpr Channel kOperationChannels[] = {Channel::kTInC, Channel::kMdotKgS};

inline std::string ColumnDefs(std::span<const Channel> channels) {
  std::string s;
  for (const Channel c : channels) s += ", " + std::string(ChannelName(c)) + " REAL";
  return s;
}

// forecast_skill's SQL of schema version 11 (store_schema.cc), shared with
// the refresh of forecast_skill_day (store_skill.cc): the day-ahead pairs
// (columns day, err_p, meas_p, ...) of the measurement_1min rows m of the
// FROM list `from` where `where`, and the view's columns per day from a CTE
// `pairs` of them ("SELECT day, ... FROM pairs GROUP BY day").
std::string SkillPairsV11(const std::string& from, const std::string& where);
std::string SkillAggregatesV11();
// Those of version 12: the pairs also of the measurement_interval rows of
// UTC days without 1-min rows, each with its step_s; `from` writes the
// measurement table {m} (filled in once with each table), and the columns
// weight each pair by its minutes.
std::string SkillPairsV12(const std::string& from, const std::string& where);
std::string SkillAggregatesV12();

// The outcome of one database step: an SQLite result code and what was done.
struct DbStatus {
  int rc = SQLITE_OK;
  std::string what;
  std::string message;  // sqlite3_errmsg at the failure
  bool ok() const { return rc == SQLITE_OK; }
  bool busy() const { return rc == SQLITE_BUSY || rc == SQLITE_LOCKED; }
};

inline void BindReal(sqlite3_stmt* stmt, int index, double x) {
  if (std::isfinite(x)) {
    sqlite3_bind_double(stmt, index, x);
  } else {
    sqlite3_bind_null(stmt, index);
  }
}

inline double ColumnReal(sqlite3_stmt* stmt, int index) {
  return sqlite3_column_type(stmt, index) == SQLITE_NULL ? std::nan("")
                                                         : sqlite3_column_double(stmt, index);
}

// Columns 1, 2, … of the current row into *fields[0], *fields[1], … (NULL: NaN).
inline void ColumnReals(sqlite3_stmt* stmt, std::initializer_list<double*> fields) {
  int index = 1;
  for (double* field : fields) *field = ColumnReal(stmt, index++);
}

inline std::string ColumnText(sqlite3_stmt* stmt, int index) {
  const unsigned char* text = sqlite3_column_text(stmt, index);
  return text == nullptr ? std::string() : reinterpret_cast<const char*>(text);
}

}  // namespace store_detail

struct Store::Impl {
  using DbStatus = store_detail::DbStatus;

  sqlite3* db = nullptr;
  std::string path;
  StoreOptions options;
  std::mutex mutex;
  std::unordered_map<std::string, sqlite3_stmt*> statements;
  // AggregateMinutes looks for unaggregated samples from here on: the start
  // of the first minute not yet known to be done in this process (the whole
  // table after Open).
  std::int64_t aggregate_scan_from = store_detail::kNoLowerBound;
  // The zone of local_day: options.time_zone, or when that is empty the
  // zone the store's local_day was made in (UTC for a new store); set at Open.
  std::string zone = "UTC";
  // What Open's migration did (Store::upgrade).
  SchemaUpgrade upgrade;

  ~Impl() {
    for (auto& [sql, stmt] : statements) sqlite3_finalize(stmt);
    if (db != nullptr) sqlite3_close_v2(db);
  }

  DbStatus Fail(int rc, const std::string& what) const {
    return {rc == SQLITE_OK ? SQLITE_ERROR : rc, what, db ? sqlite3_errmsg(db) : "out of memory"};
  }

  std::string Describe(const DbStatus& s) const {
    std::string text = path + ": " + s.what;
    if (!s.message.empty()) text += ": " + s.message;
    return text + " (SQLite code " + std::to_string(s.rc) + ")";
  }

  // A store that cannot be written is refused at open with the reason an
  // operator can act on, not at the first failing write.
  bool CheckWritable(std::string* error) const {
    const std::filesystem::path file(path);
    const std::filesystem::path dir =
        file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
    const auto who = [] { return "uid " + std::to_string(::geteuid()); };
    if (::access(path.c_str(), F_OK) == 0 && ::access(path.c_str(), W_OK) != 0) {
      *error = path + ": permission denied: the database file is read-only for " + who() + " (" +
               std::strerror(errno) + ")";
      return false;
    }
    // WAL needs the -wal and -shm files beside the database.
    if (::access(dir.c_str(), W_OK) != 0) {
      *error = path + ": permission denied: " + who() + " cannot create files in " + dir.string() +
               " (" + std::strerror(errno) + "); the store needs its -wal and -shm files there";
      return false;
    }
    if (sqlite3_db_readonly(db, "main") == 1) {
      *error =
          path + ": read-only: SQLite opened the database read-only (a read-only file system?)";
      return false;
    }
    return true;
  }

  // PRAGMA quick_check (pages, records, indexes: corruption shows here, not
  // after an import "worked"), then that a non-empty file is a pvtwin store.
  bool CheckIntegrityAndOwner(std::string* error) {
    std::vector<std::string> problems;
    int rc = sqlite3_exec(
        db, "PRAGMA quick_check(5)",
        [](void* out, int, char** values, char**) {
          auto* list = static_cast<std::vector<std::string>*>(out);
          list->push_back(values[0] ? values[0] : "");
          return 0;
        },
        &problems, nullptr);
    if (rc == SQLITE_NOTADB) {
      *error = path + ": not an SQLite database (file is not a database); pvtwin leaves it alone";
      return false;
    }
    if (rc != SQLITE_OK) {
      *error = Describe(Fail(rc, "integrity check (PRAGMA quick_check)"));
      return false;
    }
    if (problems.size() != 1 || problems[0] != "ok") {
      std::string list;
      for (const std::string& p : problems) list += (list.empty() ? "" : "; ") + p;
      *error = path + ": the database is damaged (PRAGMA quick_check: " + list +
               "); pvtwin does not write to it. Keep a copy, then recover it with the sqlite3 "
               "shell's .recover, or move it away to start a new store";
      return false;
    }
    int version = 0;
    std::string tables;
    sqlite3_exec(
        db, "PRAGMA user_version",
        [](void* out, int, char** values, char**) {
          *static_cast<int*>(out) = values[0] ? std::atoi(values[0]) : 0;
          return 0;
        },
        &version, nullptr);
    sqlite3_exec(
        db, "SELECT name FROM sqlite_schema WHERE name NOT LIKE 'sqlite_%' ORDER BY name LIMIT 4",
        [](void* out, int, char** values, char**) {
          auto* list = static_cast<std::string*>(out);
          *list += (list->empty() ? "" : ", ") + std::string(values[0] ? values[0] : "");
          return 0;
        },
        &tables, nullptr);
    if (version > kStoreSchemaVersion) {
      *error = path + ": schema version " + std::to_string(version) +
               " is newer than this pvtwin knows (" + std::to_string(kStoreSchemaVersion) +
               "); use a newer pvtwin";
      return false;
    }
    if (version == 0 && !tables.empty()) {
      *error = path + ": not a pvtwin store (it holds " + tables +
               " and no pvtwin schema version); pvtwin leaves it unchanged";
      return false;
    }
    return true;
  }

  DbStatus Exec(const std::string& sql) {
    const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr);
    return rc == SQLITE_OK ? DbStatus{} : Fail(rc, sql.substr(0, 60));
  }

  // The cached prepared statement for sql, reset and unbound.
  DbStatus Prepare(const std::string& sql, sqlite3_stmt** stmt) {
    auto it = statements.find(sql);
    if (it == statements.end()) {
      sqlite3_stmt* fresh = nullptr;
      const int rc =
          sqlite3_prepare_v3(db, sql.c_str(), -1, SQLITE_PREPARE_PERSISTENT, &fresh, nullptr);
      if (rc != SQLITE_OK) return Fail(rc, "prepare " + sql.substr(0, 60));
      it = statements.emplace(sql, fresh).first;
    }
    sqlite3_reset(it->second);
    sqlite3_clear_bindings(it->second);
    *stmt = it->second;
    return {};
  }

  // Runs body in a BEGIN IMMEDIATE transaction (write) or as is (read);
  // retries the whole of it after SQLITE_BUSY. Returns true, or false with
  // *error set and the transaction rolled back.
  bool Run(bool write, const std::string& what, const std::function<DbStatus()>& body,
           std::string* error) {
    assert(error != nullptr);
    DbStatus status;
    for (int attempt = 0; attempt <= options.busy_retries; ++attempt) {
      if (attempt > 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10 << std::min(attempt, 6)));
      }
      if (write) {
        status = Exec("BEGIN IMMEDIATE");
        if (!status.ok()) {
          status.what = what + ": begin transaction";
          if (status.busy()) continue;
          break;
        }
      }
      status = body();
      if (status.ok() && write) {
        status = Exec("COMMIT");
        if (!status.ok()) status.what = what + ": commit";
      }
      if (status.ok()) return true;
      if (write && !sqlite3_get_autocommit(db)) Exec("ROLLBACK");
      if (!status.busy()) break;
    }
    if (status.busy()) status.what += " (database busy, gave up after retries)";
    *error = Describe(status);
    return false;
  }

  // Steps stmt to completion (no rows expected).
  DbStatus StepDone(sqlite3_stmt* stmt, const std::string& what) {
    const int rc = sqlite3_step(stmt);
    return rc == SQLITE_DONE ? DbStatus{} : Fail(rc, what);
  }

  // Runs the query sql, whose two parameters are a time range [from, to),
  // and hands each row to on_row.
  DbStatus SelectRange(const std::string& sql, std::int64_t from, std::int64_t to,
                       const std::function<void(sqlite3_stmt*)>& on_row, const std::string& what) {
    sqlite3_stmt* stmt = nullptr;
    DbStatus s = Prepare(sql, &stmt);
    if (!s.ok()) return s;
    sqlite3_bind_int64(stmt, 1, from);
    sqlite3_bind_int64(stmt, 2, to);
    int rc;
    while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) on_row(stmt);
    sqlite3_reset(stmt);
    return rc == SQLITE_DONE ? DbStatus{} : Fail(rc, what);
  }

  // Runs the migrations the store's user_version lacks, each in its own
  // transaction, after a backup of an existing store (store_schema.cc).
  bool Migrate(std::string* error);
  // Copies the database as this connection sees it into target_path
  // (SQLite's online backup; Store::BackupTo without the lock).
  bool BackupTo(const std::string& target_path, std::string* error);
  // Inserts the local_day rows (store_local_day.cc) of the days that
  // overlap [from_ts, to_ts) and the two days after it, keeping rows that
  // exist (inside a transaction).
  DbStatus CoverLocalDays(std::int64_t from_ts, std::int64_t to_ts);
  // At Open: sets zone, and makes local_day anew for the days of the stored
  // measurements when it was made in another zone, or not yet.
  bool SyncLocalDays(std::string* error);
  // Covers the local days from the first to the last stored measurement.
  DbStatus CoverMeasuredDays();
  // Writes the rows of `minutes` into measurement_1min and covers their
  // local days (inside a transaction).
  DbStatus WriteMinuteRows(const MinuteRows& minutes, bool replace, bool imported);
  DbStatus InsertCalibrationParams(std::int64_t calibration_id,
                                   const std::vector<CalibrationParamRow>& params);
  // Reads the samples of [from, to) whose minute has no 1-min row yet (all of
  // them if `all`), aggregates and writes them (inside a transaction).
  DbStatus AggregateRange(std::int64_t from_ts, std::int64_t to_ts, bool all, int* minutes_written);
  // The rows of a [from, to) query, each built by from_statement(stmt).
  template <typename Row, typename FromStatement>
  bool ReadRows(const std::string& sql, const std::string& what, std::int64_t from, std::int64_t to,
                FromStatement from_statement, std::vector<Row>* out, std::string* error);
  // Materialises forecast_skill for the closed UTC days before now_ts's day
  // that are dirty or not yet materialised (store_skill.cc; inside a
  // transaction); *days_written += the rows written.
  DbStatus RefreshForecastSkill(std::int64_t now_ts, int* days_written);
  // Deletes the forecast rows in [from_ts, to_ts) that no view uses.
  DbStatus PruneForecasts(std::int64_t from_ts, std::int64_t to_ts);
  bool ReadInputTable(const std::string& table, std::span<const Channel> channels,
                      std::int64_t from, std::int64_t to, Series* out, std::string* error,
                      TextCells* text_cells);
};

}  // namespace pvtwin

#endif  // PVTWIN_IO_STORE_STORE_IMPL_H_
