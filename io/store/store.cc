// The SQLite store; the design (schema, units, time, WAL and crash behaviour,
// retention) is described at the head of io/store/store.h.
#include "io/store/store.h"

#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <thread>
#include <unordered_map>

#include "core/common/units.h"
#include "core/data/physical_limits.h"
#include "core/forecast/forecast.h"

namespace pvtwin {

namespace fs = std::filesystem;
namespace {

constexpr std::int64_t kSecondsPerDay = 86400;
constexpr std::int64_t kNoLowerBound = std::numeric_limits<std::int64_t>::min();

std::int64_t MinuteStart(std::int64_t t_s) {
  std::int64_t k = t_s / kMinuteS;
  if (t_s % kMinuteS < 0) --k;
  return k * kMinuteS;
}

// SQL value of channel c: degrees for the aoi_deg column, else as in core.
double ToSql(Channel c, double core_value) {
  return c == Channel::kAoiRad ? RadToDeg(core_value) : core_value;
}
double FromSql(Channel c, double sql_value) {
  return c == Channel::kAoiRad ? DegToRad(sql_value) : sql_value;
}

// "c1, c2, ..." of every canonical channel, and "?, ?, ..." of the same count.
std::string ChannelColumns(const std::string& prefix = "") {
  std::string s;
  for (const ChannelInfo& info : kChannels) {
    if (!s.empty()) s += ", ";
    s += prefix + std::string(info.name);
  }
  return s;
}
std::string Placeholders(std::size_t n) {
  std::string s;
  for (std::size_t i = 0; i < n; ++i) s += i ? ", ?" : "?";
  return s;
}
std::string ChannelColumnDefs() {
  std::string s;
  for (const ChannelInfo& info : kChannels) s += ", " + std::string(info.name) + " REAL";
  return s;
}

// Channels of the forecast input tables (columns in this order).
constexpr Channel kWeatherChannels[] = {
    Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaDiffuseWM2,
    Channel::kTAmbC,   Channel::kWindMS, Channel::kTSkyC,  Channel::kLwDownWM2};
constexpr Channel kOperationChannels[] = {Channel::kTInC, Channel::kMdotKgS};

std::string ColumnDefs(std::span<const Channel> channels) {
  std::string s;
  for (const Channel c : channels) s += ", " + std::string(ChannelName(c)) + " REAL";
  return s;
}

// Schema version 1 (io/store/store.h). Each later version appends one Migration
// whose statements turn version N-1 into N; Open runs the missing ones in
// order, each in its own transaction together with the user_version update.
std::vector<std::string> SchemaV1() {
  return {
      "CREATE TABLE sample_5s(ts INTEGER PRIMARY KEY" + ChannelColumnDefs() +
          ", rejected_mask INTEGER NOT NULL DEFAULT 0)",
      "CREATE TABLE measurement_1min(ts INTEGER PRIMARY KEY" + ChannelColumnDefs() +
          ", n_samples INTEGER, qc_flags INTEGER NOT NULL DEFAULT 0)",
      "CREATE TABLE calibration(id INTEGER PRIMARY KEY, run_at INTEGER NOT NULL, variant TEXT, "
      "window_start INTEGER, window_end INTEGER, status TEXT NOT NULL, mae_p_el_w REAL, "
      "mae_q_th_w REAL, runtime_s REAL, n_evals INTEGER, params_json TEXT, reason TEXT, "
      "heldout_mae_w REAL, accepted INTEGER NOT NULL DEFAULT 0)",
      "CREATE INDEX calibration_accepted ON calibration(accepted, run_at)",
      "CREATE TABLE forecast(issued_at INTEGER NOT NULL, ts INTEGER NOT NULL, "
      "calibration_id INTEGER REFERENCES calibration(id), p_el_w REAL, q_th_w REAL, "
      "t_pv_c REAL, t_out_c REAL, inputs TEXT, PRIMARY KEY(issued_at, ts)) WITHOUT ROWID",
      "CREATE INDEX forecast_by_ts ON forecast(ts, issued_at)",
      "CREATE VIEW forecast_latest(ts, issued_at, p_el_w, q_th_w, t_pv_c, t_out_c) AS "
      "SELECT f.ts, f.issued_at, f.p_el_w, f.q_th_w, f.t_pv_c, f.t_out_c FROM forecast f "
      "WHERE f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = f.ts)",
      // Day-ahead pairs: for each valid measurement, the forecast row at its
      // ts from the newest issue at or before 00:00 UTC of its day. The
      // measurements drive the join (CROSS JOIN fixes SQLite's loop order),
      // each looking up its forecast through forecast_by_ts.
      "CREATE VIEW forecast_skill(day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th) AS "
      "WITH pairs AS ("
      " SELECT m.ts - ((m.ts % 86400) + 86400) % 86400 AS day,"
      "  f.p_el_w - m.p_el_w AS err_p, CASE WHEN f.p_el_w IS NOT NULL THEN m.p_el_w END AS meas_p,"
      "  f.q_th_w - m.q_th_w AS err_q, CASE WHEN f.q_th_w IS NOT NULL THEN m.q_th_w END AS meas_q"
      " FROM measurement_1min m CROSS JOIN forecast f ON f.ts = m.ts"
      "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
      "   AND g.issued_at <= m.ts - ((m.ts % 86400) + 86400) % 86400)"
      " WHERE m.valid IS NULL OR m.valid != 0)"
      " SELECT day, AVG(ABS(err_p)), AVG(ABS(err_q)),"
      "  AVG(ABS(err_p)) / AVG(ABS(CASE WHEN err_p IS NOT NULL THEN meas_p END)),"
      "  AVG(ABS(err_q)) / AVG(ABS(CASE WHEN err_q IS NOT NULL THEN meas_q END))"
      " FROM pairs GROUP BY day",
      "CREATE TABLE weather_forecast(ts INTEGER PRIMARY KEY" + ColumnDefs(kWeatherChannels) + ")",
      "CREATE TABLE operation_plan(ts INTEGER PRIMARY KEY" + ColumnDefs(kOperationChannels) + ")",
  };
}

// Version 2: data of a logger step above 1 min, kept at that step.
std::vector<std::string> SchemaV2() {
  return {"CREATE TABLE measurement_interval(ts INTEGER PRIMARY KEY, step_s INTEGER NOT NULL" +
          ChannelColumnDefs() + ", qc_flags INTEGER NOT NULL DEFAULT 0)"};
}

// Version 3: the identified parameters of every calibration, one row each,
// and their history with the calibration's time and acceptance.
std::vector<std::string> SchemaV3() {
  return {
      "CREATE TABLE calibration_param(calibration_id INTEGER NOT NULL REFERENCES "
      "calibration(id), name TEXT NOT NULL, value REAL, std_error REAL, unit TEXT, status TEXT, "
      "PRIMARY KEY(calibration_id, name)) WITHOUT ROWID",
      "CREATE VIEW parameter_history(run_at, calibration_id, accepted, name, value, std_error, "
      "unit, status) AS SELECT c.run_at, p.calibration_id, c.accepted, p.name, p.value, "
      "p.std_error, p.unit, p.status FROM calibration_param p JOIN calibration c ON c.id = "
      "p.calibration_id",
  };
}

// The QC flags of measurement_1min, one named 0/1 column each, for the
// measurement_qc view (core/aggregate.h).
std::string QcFlagColumns() {
  const std::pair<const char*, unsigned> kFlags[] = {
      {"few_samples", 0},          {"required_missing", 1}, {"rejected_values", 2},
      {"irradiance_corrected", 3}, {"flow_corrected", 4},   {"thermal_power_computed", 5},
      {"invalid_samples", 6},      {"imported", 7}};
  std::string names = "ts", exprs = "ts";
  for (const auto& [name, bit] : kFlags) {
    names += std::string(", ") + name;
    exprs += ", (qc_flags >> " + std::to_string(bit) + ") & 1";
  }
  for (const ChannelInfo& info : kChannels) {
    if (info.channel == Channel::kValid) continue;
    names += ", missing_" + std::string(info.name);
    exprs += ", (qc_flags >> " +
             std::to_string(kQcChannelMissingShift + static_cast<unsigned>(info.channel)) + ") & 1";
  }
  return "CREATE VIEW measurement_qc(" + names + ") AS SELECT " + exprs + " FROM measurement_1min";
}

// Version 4: what the twin watches day by day (core/monitoring.h) and the
// one list of events an operator reads first.
std::vector<std::string> SchemaV4() {
  return {
      QcFlagColumns(),
      "CREATE TABLE performance_daily(day INTEGER PRIMARY KEY, e_el_meas_wh REAL, "
      "e_el_model_wh REAL, e_th_meas_wh REAL, e_th_model_wh REAL, pi_el REAL, pi_th REAL, "
      "pi_el_low REAL, pi_el_high REAL, pi_th_low REAL, pi_th_high REAL, valid_minutes INTEGER, "
      "calibration_id INTEGER REFERENCES calibration(id))",
      "CREATE TABLE qc_event(id INTEGER PRIMARY KEY, channel TEXT NOT NULL, start_ts INTEGER NOT "
      "NULL, end_ts INTEGER NOT NULL, kind TEXT NOT NULL, detail TEXT)",
      "CREATE UNIQUE INDEX qc_event_key ON qc_event(channel, kind, start_ts)",
      "CREATE TABLE monitor_event(id INTEGER PRIMARY KEY, ts INTEGER NOT NULL, kind TEXT NOT "
      "NULL, severity TEXT NOT NULL, message TEXT)",
      "CREATE TABLE diagnosis(id INTEGER PRIMARY KEY, run_at INTEGER NOT NULL, calibration_id "
      "INTEGER, window_start INTEGER, window_end INTEGER, base_variant TEXT, verdict TEXT, "
      "low_confidence INTEGER, shrink_pct REAL, bias_p_el_w REAL, bias_q_th_w REAL, "
      "report_json TEXT)",
      "CREATE VIEW event(ts, kind, severity, message) AS"
      " SELECT ts, kind, severity, message FROM monitor_event"
      " UNION ALL SELECT start_ts, 'qc_' || kind, 'warning', channel || ': ' || detail"
      "  FROM qc_event"
      " UNION ALL SELECT run_at, 'calibration_' || status,"
      "  CASE WHEN accepted = 1 THEN 'info' ELSE 'warning' END,"
      "  'calibration ' || id || ' (' || variant || '): ' || status ||"
      "  COALESCE(': ' || reason, '') FROM calibration"
      " UNION ALL SELECT run_at, 'diagnosis',"
      "  CASE WHEN verdict = 'none' THEN 'info' ELSE 'warning' END,"
      "  'diagnosis of ' || base_variant || ': ' || verdict ||"
      "  CASE WHEN low_confidence = 1 THEN ' (low confidence)' ELSE '' END FROM diagnosis"
      " ORDER BY 1 DESC",
  };
}

// Version 5: where each weather_forecast row came from (import-weather, the
// daemon's fetch; NULL for rows other programs wrote), and the plant the
// store belongs to, so that commands given only the store know the site.
std::vector<std::string> SchemaV5() {
  return {
      "ALTER TABLE weather_forecast ADD COLUMN source TEXT",
      "CREATE TABLE plant_config(key TEXT PRIMARY KEY, value REAL NOT NULL) WITHOUT ROWID",
  };
}

// Version 6: forecasts with uncertainty bands and the reference forecast
// they are scored against (issue 15, core/forecast/forecast_bands.h); the
// views gain the bands, the skill against the reference, the band's
// coverage and the scored minutes. Views are dropped and created again with
// their old columns first.
std::vector<std::string> SchemaV6() {
  std::vector<std::string> s;
  for (const char* column :
       {"p_el_w_p10", "p_el_w_p90", "q_th_w_p10", "q_th_w_p90", "p_el_w_ref", "q_th_w_ref"}) {
    s.push_back(std::string("ALTER TABLE forecast ADD COLUMN ") + column + " REAL");
  }
  s.push_back("DROP VIEW forecast_latest");
  s.push_back(
      "CREATE VIEW forecast_latest(ts, issued_at, p_el_w, q_th_w, t_pv_c, t_out_c, p_el_w_p10, "
      "p_el_w_p90, q_th_w_p10, q_th_w_p90) AS "
      "SELECT f.ts, f.issued_at, f.p_el_w, f.q_th_w, f.t_pv_c, f.t_out_c, f.p_el_w_p10, "
      "f.p_el_w_p90, f.q_th_w_p10, f.q_th_w_p90 FROM forecast f "
      "WHERE f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = f.ts)");
  s.push_back("DROP VIEW forecast_skill");
  // The pairs of version 1, plus per minute: the reference's error where the
  // forecast has a value, and whether the measurement lies in a band of
  // width (NULL without one). Skill compares MAEs over the minutes where
  // both are known; skill and coverage need kMinScoredMinutes scored minutes.
  const std::string min_minutes = std::to_string(kMinScoredMinutes);
  s.push_back(
      "CREATE VIEW forecast_skill(day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, skill_p_el, "
      "skill_q_th, coverage_p10_p90, minutes) AS "
      "WITH pairs AS ("
      " SELECT m.ts - ((m.ts % 86400) + 86400) % 86400 AS day,"
      "  f.p_el_w - m.p_el_w AS err_p, CASE WHEN f.p_el_w IS NOT NULL THEN m.p_el_w END AS meas_p,"
      "  f.q_th_w - m.q_th_w AS err_q, CASE WHEN f.q_th_w IS NOT NULL THEN m.q_th_w END AS meas_q,"
      "  CASE WHEN f.p_el_w IS NOT NULL THEN f.p_el_w_ref - m.p_el_w END AS ref_p,"
      "  CASE WHEN f.q_th_w IS NOT NULL THEN f.q_th_w_ref - m.q_th_w END AS ref_q,"
      "  CASE WHEN f.p_el_w_p90 > f.p_el_w_p10 AND m.p_el_w IS NOT NULL"
      "   THEN m.p_el_w BETWEEN f.p_el_w_p10 AND f.p_el_w_p90 END AS in_p,"
      "  CASE WHEN f.q_th_w_p90 > f.q_th_w_p10 AND m.q_th_w IS NOT NULL"
      "   THEN m.q_th_w BETWEEN f.q_th_w_p10 AND f.q_th_w_p90 END AS in_q"
      " FROM measurement_1min m CROSS JOIN forecast f ON f.ts = m.ts"
      "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
      "   AND g.issued_at <= m.ts - ((m.ts % 86400) + 86400) % 86400)"
      " WHERE m.valid IS NULL OR m.valid != 0)"
      " SELECT day, AVG(ABS(err_p)), AVG(ABS(err_q)),"
      "  AVG(ABS(err_p)) / AVG(ABS(CASE WHEN err_p IS NOT NULL THEN meas_p END)),"
      "  AVG(ABS(err_q)) / AVG(ABS(CASE WHEN err_q IS NOT NULL THEN meas_q END)),"
      "  CASE WHEN COUNT(*) >= " +
      min_minutes +
      " THEN 1.0 -"
      "   SUM(CASE WHEN ref_p IS NOT NULL THEN ABS(err_p) END) /"
      "   NULLIF(SUM(CASE WHEN err_p IS NOT NULL THEN ABS(ref_p) END), 0) END,"
      "  CASE WHEN COUNT(*) >= " +
      min_minutes +
      " THEN 1.0 -"
      "   SUM(CASE WHEN ref_q IS NOT NULL THEN ABS(err_q) END) /"
      "   NULLIF(SUM(CASE WHEN err_q IS NOT NULL THEN ABS(ref_q) END), 0) END,"
      "  CASE WHEN COUNT(*) >= " +
      min_minutes +
      " THEN"
      "   (TOTAL(in_p) + TOTAL(in_q)) / NULLIF(COUNT(in_p) + COUNT(in_q), 0) END,"
      "  COUNT(*)"
      " FROM pairs GROUP BY day");
  return s;
}

// Version 7: the store's identity, a random id made once when the schema
// reaches version 7 (at creation, or at the migration of an older store).
// The fleet upload sends it, so that two stores under one plant_id are told
// apart centrally (io/fleet/upload.h).
std::vector<std::string> SchemaV7() {
  return {
      "CREATE TABLE store_identity(id INTEGER PRIMARY KEY CHECK(id = 1), store_id TEXT NOT NULL, "
      "created_at INTEGER NOT NULL)",
      "INSERT INTO store_identity(id, store_id, created_at) VALUES(1, lower(hex(randomblob(16))), "
      "CAST(strftime('%s', 'now') AS INTEGER))",
  };
}

// Version 8: the median of each output beside the band (the point forecast
// is the model's run on the expected inputs; p50 = point + the median of its
// held-out errors, core/forecast/forecast_bands.h), and the band's coverage
// per output in forecast_skill. The views are created again with their old
// columns first.
std::vector<std::string> SchemaV8() {
  std::vector<std::string> s;
  for (const char* column : {"p_el_w_p50", "q_th_w_p50"}) {
    s.push_back(std::string("ALTER TABLE forecast ADD COLUMN ") + column + " REAL");
  }
  s.push_back("DROP VIEW forecast_latest");
  s.push_back(
      "CREATE VIEW forecast_latest(ts, issued_at, p_el_w, q_th_w, t_pv_c, t_out_c, p_el_w_p10, "
      "p_el_w_p90, q_th_w_p10, q_th_w_p90, p_el_w_p50, q_th_w_p50) AS "
      "SELECT f.ts, f.issued_at, f.p_el_w, f.q_th_w, f.t_pv_c, f.t_out_c, f.p_el_w_p10, "
      "f.p_el_w_p90, f.q_th_w_p10, f.q_th_w_p90, f.p_el_w_p50, f.q_th_w_p50 FROM forecast f "
      "WHERE f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = f.ts)");
  s.push_back("DROP VIEW forecast_skill");
  const std::string min_minutes = std::to_string(kMinScoredMinutes);
  const std::string enough = " CASE WHEN COUNT(*) >= " + min_minutes + " THEN";
  s.push_back(
      "CREATE VIEW forecast_skill(day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, skill_p_el, "
      "skill_q_th, coverage_p10_p90, minutes, coverage_p_el, coverage_q_th) AS "
      "WITH pairs AS ("
      " SELECT m.ts - ((m.ts % 86400) + 86400) % 86400 AS day,"
      "  f.p_el_w - m.p_el_w AS err_p, CASE WHEN f.p_el_w IS NOT NULL THEN m.p_el_w END AS meas_p,"
      "  f.q_th_w - m.q_th_w AS err_q, CASE WHEN f.q_th_w IS NOT NULL THEN m.q_th_w END AS meas_q,"
      "  CASE WHEN f.p_el_w IS NOT NULL THEN f.p_el_w_ref - m.p_el_w END AS ref_p,"
      "  CASE WHEN f.q_th_w IS NOT NULL THEN f.q_th_w_ref - m.q_th_w END AS ref_q,"
      "  CASE WHEN f.p_el_w_p90 > f.p_el_w_p10 AND m.p_el_w IS NOT NULL"
      "   THEN m.p_el_w BETWEEN f.p_el_w_p10 AND f.p_el_w_p90 END AS in_p,"
      "  CASE WHEN f.q_th_w_p90 > f.q_th_w_p10 AND m.q_th_w IS NOT NULL"
      "   THEN m.q_th_w BETWEEN f.q_th_w_p10 AND f.q_th_w_p90 END AS in_q"
      " FROM measurement_1min m CROSS JOIN forecast f ON f.ts = m.ts"
      "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
      "   AND g.issued_at <= m.ts - ((m.ts % 86400) + 86400) % 86400)"
      " WHERE m.valid IS NULL OR m.valid != 0)"
      " SELECT day, AVG(ABS(err_p)), AVG(ABS(err_q)),"
      "  AVG(ABS(err_p)) / AVG(ABS(CASE WHEN err_p IS NOT NULL THEN meas_p END)),"
      "  AVG(ABS(err_q)) / AVG(ABS(CASE WHEN err_q IS NOT NULL THEN meas_q END)),"
      "  " +
      enough +
      " 1.0 -"
      "   SUM(CASE WHEN ref_p IS NOT NULL THEN ABS(err_p) END) /"
      "   NULLIF(SUM(CASE WHEN err_p IS NOT NULL THEN ABS(ref_p) END), 0) END,"
      "  " +
      enough +
      " 1.0 -"
      "   SUM(CASE WHEN ref_q IS NOT NULL THEN ABS(err_q) END) /"
      "   NULLIF(SUM(CASE WHEN err_q IS NOT NULL THEN ABS(ref_q) END), 0) END,"
      "  " +
      enough +
      "   (TOTAL(in_p) + TOTAL(in_q)) / NULLIF(COUNT(in_p) + COUNT(in_q), 0) END,"
      "  COUNT(*),"
      "  " +
      enough +
      " TOTAL(in_p) / NULLIF(COUNT(in_p), 0) END,"
      "  " +
      enough +
      " TOTAL(in_q) / NULLIF(COUNT(in_q), 0) END"
      " FROM pairs GROUP BY day");
  return s;
}

struct Migration {
  int to_version;
  std::vector<std::string> (*statements)();
};
const Migration kMigrations[] = {{1, &SchemaV1}, {2, &SchemaV2}, {3, &SchemaV3}, {4, &SchemaV4},
                                 {5, &SchemaV5}, {6, &SchemaV6}, {7, &SchemaV7}, {8, &SchemaV8}};
static_assert(sizeof(kMigrations) / sizeof(kMigrations[0]) == kStoreSchemaVersion,
              "one migration per schema version");

// The outcome of one database step: an SQLite result code and what was done.
struct DbStatus {
  int rc = SQLITE_OK;
  std::string what;
  std::string message;  // sqlite3_errmsg at the failure
  bool ok() const { return rc == SQLITE_OK; }
  bool busy() const { return rc == SQLITE_BUSY || rc == SQLITE_LOCKED; }
};

}  // namespace

struct Store::Impl {
  sqlite3* db = nullptr;
  std::string path;
  StoreOptions options;
  std::mutex mutex;
  std::unordered_map<std::string, sqlite3_stmt*> statements;
  // AggregateMinutes looks for unaggregated samples from here on: the start
  // of the first minute not yet known to be done in this process (the whole
  // table after Open).
  std::int64_t aggregate_scan_from = kNoLowerBound;

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
    const fs::path file(path);
    const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
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

  // Writes the rows of `minutes` into measurement_1min (inside a transaction).
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
  // Deletes the forecast rows in [from_ts, to_ts) that neither view uses.
  DbStatus PruneForecasts(std::int64_t from_ts, std::int64_t to_ts);
  bool ReadInputTable(const std::string& table, std::span<const Channel> channels,
                      std::int64_t from, std::int64_t to, Series* out, std::string* error,
                      TextCells* text_cells);
};

namespace {

void BindReal(sqlite3_stmt* stmt, int index, double x) {
  if (std::isfinite(x)) {
    sqlite3_bind_double(stmt, index, x);
  } else {
    sqlite3_bind_null(stmt, index);
  }
}

double ColumnReal(sqlite3_stmt* stmt, int index) {
  return sqlite3_column_type(stmt, index) == SQLITE_NULL ? std::nan("")
                                                         : sqlite3_column_double(stmt, index);
}

// Columns 1, 2, … of the current row into *fields[0], *fields[1], … (NULL: NaN).
void ColumnReals(sqlite3_stmt* stmt, std::initializer_list<double*> fields) {
  int index = 1;
  for (double* field : fields) *field = ColumnReal(stmt, index++);
}

std::string ColumnText(sqlite3_stmt* stmt, int index) {
  const unsigned char* text = sqlite3_column_text(stmt, index);
  return text == nullptr ? std::string() : reinterpret_cast<const char*>(text);
}

// Drops the columns that are NaN in every row.
void DropEmptyColumns(Series* s) {
  for (auto& col : s->columns) {
    if (std::all_of(col.begin(), col.end(), [](double x) { return std::isnan(x); })) col.clear();
  }
}

const std::string& SelectSamplesSql() {
  static const std::string sql = "SELECT ts, " + ChannelColumns() +
                                 ", rejected_mask FROM sample_5s WHERE ts >= ? AND ts < ? "
                                 "ORDER BY ts";
  return sql;
}

void ReadSampleRow(sqlite3_stmt* stmt, Sample* s) {
  s->ts_s = sqlite3_column_int64(stmt, 0);
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    s->value[c] = FromSql(static_cast<Channel>(c), ColumnReal(stmt, static_cast<int>(c) + 1));
  }
  s->rejected_mask =
      static_cast<std::uint32_t>(sqlite3_column_int64(stmt, static_cast<int>(kNumChannels) + 1));
}

}  // namespace

Store::Store(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Store::~Store() = default;

const std::string& Store::path() const { return impl_->path; }

bool Store::BackupTo(const std::string& target_path, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  sqlite3* target = nullptr;
  int rc = sqlite3_open_v2(target_path.c_str(), &target, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE,
                           nullptr);
  if (rc == SQLITE_OK) {
    sqlite3_backup* backup = sqlite3_backup_init(target, "main", db.db, "main");
    if (backup == nullptr) {
      rc = sqlite3_errcode(target);
    } else {
      sqlite3_backup_step(backup, -1);
      rc = sqlite3_backup_finish(backup);
    }
  }
  if (rc != SQLITE_OK) {
    *error =
        target_path + ": backup failed: " + (target ? sqlite3_errmsg(target) : "out of memory");
  }
  sqlite3_close(target);
  return rc == SQLITE_OK;
}

std::unique_ptr<Store> Store::Open(const std::string& path, std::string* error) {
  return Open(path, StoreOptions{}, error);
}

std::unique_ptr<Store> Store::Open(const std::string& path, const StoreOptions& options,
                                   std::string* error) {
  assert(error != nullptr);
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->options = options;
  const int rc =
      sqlite3_open_v2(path.c_str(), &impl->db,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    *error = impl->Describe(impl->Fail(rc, "cannot open database"));
    return nullptr;
  }
  sqlite3_extended_result_codes(impl->db, 0);
  sqlite3_busy_timeout(impl->db, options.busy_timeout_ms);
  // Everything the store refuses is refused before it writes anything (the
  // switch to WAL below is a write).
  if (!impl->CheckWritable(error) || !impl->CheckIntegrityAndOwner(error)) return nullptr;

  // WAL is persistent in the file; switching needs a moment without other
  // writers, so it is retried like a transaction.
  std::string mode;
  const bool wal_ok = impl->Run(
      false, "set journal_mode = WAL",
      [&impl, &mode]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        const int prc =
            sqlite3_prepare_v2(impl->db, "PRAGMA journal_mode = WAL", -1, &stmt, nullptr);
        if (prc != SQLITE_OK) return impl->Fail(prc, "PRAGMA journal_mode");
        const int src = sqlite3_step(stmt);
        if (src == SQLITE_ROW) mode = ColumnText(stmt, 0);
        sqlite3_finalize(stmt);
        return src == SQLITE_ROW ? DbStatus{} : impl->Fail(src, "PRAGMA journal_mode");
      },
      error);
  if (!wal_ok) return nullptr;
  if (mode != "wal") {
    *error = path + ": journal_mode = " + mode +
             ": the store needs WAL (is it on a network "
             "file system?)";
    return nullptr;
  }
  if (!impl->Run(
          false, "set synchronous = NORMAL",
          [&impl] { return impl->Exec("PRAGMA synchronous = NORMAL"); }, error)) {
    return nullptr;
  }

  for (const Migration& migration : kMigrations) {
    Impl& db = *impl;
    const bool migrated = db.Run(
        true, "migrate to schema version " + std::to_string(migration.to_version),
        [&db, &migration]() -> DbStatus {
          sqlite3_stmt* stmt = nullptr;
          DbStatus s = db.Prepare("PRAGMA user_version", &stmt);
          if (!s.ok()) return s;
          const int src = sqlite3_step(stmt);
          if (src != SQLITE_ROW) return db.Fail(src, "PRAGMA user_version");
          const int version = sqlite3_column_int(stmt, 0);
          sqlite3_reset(stmt);
          if (version > kStoreSchemaVersion) {
            return {SQLITE_ERROR,
                    "schema version " + std::to_string(version) +
                        " is newer than this pvtwin knows (" + std::to_string(kStoreSchemaVersion) +
                        "); use a newer pvtwin",
                    ""};
          }
          if (version >= migration.to_version) return {};
          if (version != migration.to_version - 1) {
            return {SQLITE_ERROR, "schema version " + std::to_string(version) + " is unknown", ""};
          }
          for (const std::string& sql : migration.statements()) {
            s = db.Exec(sql);
            if (!s.ok()) return s;
          }
          return db.Exec("PRAGMA user_version = " + std::to_string(migration.to_version));
        },
        error);
    if (!migrated) return nullptr;
  }
  return std::unique_ptr<Store>(new Store(std::move(impl)));
}

bool Store::InsertSamples(const std::vector<Sample>& batch, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  static const std::string sql = "INSERT OR REPLACE INTO sample_5s(ts, " + ChannelColumns() +
                                 ", rejected_mask) VALUES(" + Placeholders(kNumChannels + 2) + ")";
  const bool ok = db.Run(
      true, "insert " + std::to_string(batch.size()) + " samples",
      [&db, &batch]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(sql, &stmt);
        if (!s.ok()) return s;
        for (const Sample& sample : batch) {
          sqlite3_reset(stmt);
          sqlite3_bind_int64(stmt, 1, sample.ts_s);
          for (std::size_t c = 0; c < kNumChannels; ++c) {
            BindReal(stmt, static_cast<int>(c) + 2,
                     ToSql(static_cast<Channel>(c), sample.value[c]));
          }
          sqlite3_bind_int64(stmt, static_cast<int>(kNumChannels) + 2, sample.rejected_mask);
          s = db.StepDone(stmt, "insert sample ts " + std::to_string(sample.ts_s));
          if (!s.ok()) return s;
        }
        return {};
      },
      error);
  if (ok) {
    for (const Sample& sample : batch) {
      db.aggregate_scan_from = std::min(db.aggregate_scan_from, MinuteStart(sample.ts_s));
    }
  }
  return ok;
}

bool Store::ReadSamples(std::int64_t from_ts, std::int64_t to_ts, std::vector<Sample>* out,
                        std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::vector<Sample> samples;
  const bool ok = db.Run(
      false, "read samples",
      [&]() -> DbStatus {
        samples.clear();
        return db.SelectRange(
            SelectSamplesSql(), from_ts, to_ts,
            [&samples](sqlite3_stmt* stmt) { ReadSampleRow(stmt, &samples.emplace_back()); },
            "read samples");
      },
      error);
  if (ok) *out = std::move(samples);
  return ok;
}

DbStatus Store::Impl::WriteMinuteRows(const MinuteRows& minutes, bool replace, bool imported) {
  Impl& db = *this;
  static const std::string tail = " INTO measurement_1min(ts, " + ChannelColumns() +
                                  ", n_samples, qc_flags) VALUES(" +
                                  Placeholders(kNumChannels + 3) + ")";
  static const std::string insert_sql = "INSERT" + tail;
  static const std::string replace_sql = "INSERT OR REPLACE" + tail;
  sqlite3_stmt* stmt = nullptr;
  DbStatus s = db.Prepare(replace ? replace_sql : insert_sql, &stmt);
  if (!s.ok()) return s;
  const Series& rows = minutes.rows;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    sqlite3_reset(stmt);
    sqlite3_bind_int64(stmt, 1, rows.time_s[i]);
    for (std::size_t c = 0; c < kNumChannels; ++c) {
      const auto channel = static_cast<Channel>(c);
      BindReal(stmt, static_cast<int>(c) + 2, ToSql(channel, rows.At(channel, i)));
    }
    const int n_index = static_cast<int>(kNumChannels) + 2;
    if (imported) {
      sqlite3_bind_null(stmt, n_index);
    } else {
      sqlite3_bind_int(stmt, n_index, minutes.n_samples[i]);
    }
    sqlite3_bind_int64(stmt, n_index + 1, minutes.qc_flags[i]);
    s = db.StepDone(stmt, "write 1-min row ts " + std::to_string(rows.time_s[i]));
    if (!s.ok()) return s;
  }
  return {};
}

DbStatus Store::Impl::AggregateRange(std::int64_t from_ts, std::int64_t to_ts, bool all,
                                     int* minutes_written) {
  Impl& db = *this;
  static const std::string pending_sql =
      "SELECT s.ts, " + ChannelColumns("s.") +
      ", s.rejected_mask FROM sample_5s s WHERE s.ts >= ? AND s.ts < ? AND NOT EXISTS ("
      "SELECT 1 FROM measurement_1min m WHERE m.ts = s.ts - ((s.ts % 60) + 60) % 60) "
      "ORDER BY s.ts";
  std::vector<Sample> samples;
  DbStatus s = db.SelectRange(
      all ? SelectSamplesSql() : pending_sql, from_ts, to_ts,
      [&samples](sqlite3_stmt* stmt) { ReadSampleRow(stmt, &samples.emplace_back()); },
      "read samples to aggregate");
  if (!s.ok()) return s;
  MinuteRows minutes;
  std::string error;
  if (!AggregateSamples(samples, db.options.aggregate, &minutes, &error)) {
    return {SQLITE_ERROR, "aggregate", error};
  }
  s = WriteMinuteRows(minutes, all, false);
  if (s.ok()) *minutes_written = static_cast<int>(minutes.rows.size());
  return s;
}

bool Store::AggregateMinutes(std::int64_t up_to_ts, int* minutes_written, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  const std::int64_t end_ts = MinuteStart(up_to_ts);  // minutes before it are complete
  int written = 0;
  const bool ok = db.Run(
      true, "aggregate minutes",
      [&] { return db.AggregateRange(db.aggregate_scan_from, end_ts, false, &written); }, error);
  if (ok) db.aggregate_scan_from = std::max(db.aggregate_scan_from, end_ts);
  if (minutes_written != nullptr) *minutes_written = ok ? written : 0;
  return ok;
}

bool Store::ReaggregateMinutes(std::int64_t from_ts, std::int64_t to_ts, int* minutes_written,
                               std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  const std::int64_t begin = MinuteStart(from_ts);
  const std::int64_t end = MinuteStart(to_ts) + (to_ts == MinuteStart(to_ts) ? 0 : kMinuteS);
  int written = 0;
  const bool ok = db.Run(
      true, "re-aggregate minutes", [&] { return db.AggregateRange(begin, end, true, &written); },
      error);
  if (minutes_written != nullptr) *minutes_written = ok ? written : 0;
  return ok;
}

namespace {

// qc_flags of an imported row: kQcImported, a bit per missing channel and
// kQcRequiredMissing when a required one is among them.
std::uint32_t ImportedRowFlags(const Series& rows, std::size_t i) {
  std::uint32_t f = kQcImported;
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    const auto channel = static_cast<Channel>(c);
    if (channel != Channel::kValid && std::isnan(rows.At(channel, i))) {
      f |= QcChannelMissingBit(channel);
    }
  }
  if (!RequiredChannelsPresent(f)) f |= kQcRequiredMissing;
  return f;
}

}  // namespace

bool Store::WriteMinutes(const Series& rows_1min, std::string* error) {
  MinuteRows minutes;
  minutes.rows = rows_1min;
  minutes.n_samples.assign(rows_1min.size(), 0);
  minutes.qc_flags.assign(rows_1min.size(), kQcImported);
  for (std::size_t i = 0; i < rows_1min.size(); ++i) {
    if (rows_1min.time_s[i] != MinuteStart(rows_1min.time_s[i])) {
      *error = impl_->path + ": 1-min row " + std::to_string(i) + " at ts " +
               std::to_string(rows_1min.time_s[i]) + ": not the start of a minute";
      return false;
    }
    minutes.qc_flags[i] = ImportedRowFlags(rows_1min, i);
  }
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "write " + std::to_string(rows_1min.size()) + " 1-min rows",
      [&] { return db.WriteMinuteRows(minutes, true, true); }, error);
}

bool Store::ReadMinuteRows(std::int64_t from_ts, std::int64_t to_ts, MinuteRows* out,
                           std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  static const std::string sql = "SELECT ts, " + ChannelColumns() +
                                 ", n_samples, qc_flags FROM measurement_1min "
                                 "WHERE ts >= ? AND ts < ? ORDER BY ts";
  MinuteRows result;
  const bool ok = db.Run(
      false, "read 1-min rows",
      [&]() -> DbStatus {
        result = MinuteRows{};
        Series& rows = result.rows;
        rows.step_s = static_cast<double>(kMinuteS);
        auto on_row = [&result, &rows](sqlite3_stmt* stmt) {
          rows.time_s.push_back(sqlite3_column_int64(stmt, 0));
          for (std::size_t c = 0; c < kNumChannels; ++c) {
            rows.columns[c].push_back(
                FromSql(static_cast<Channel>(c), ColumnReal(stmt, static_cast<int>(c) + 1)));
          }
          const int n_index = static_cast<int>(kNumChannels) + 1;
          result.n_samples.push_back(sqlite3_column_int(stmt, n_index));
          result.qc_flags.push_back(
              static_cast<std::uint32_t>(sqlite3_column_int64(stmt, n_index + 1)));
        };
        return db.SelectRange(sql, from_ts, to_ts, on_row, "read 1-min rows");
      },
      error);
  if (!ok) return false;
  // Rows written by other programs (SQL) pass the physical limits too.
  ApplyPhysicalLimits(&result.rows, db.options.aggregate.area_m2);
  DropEmptyColumns(&result.rows);
  *out = std::move(result);
  return true;
}

bool Store::WritePerformanceDay(const DayPerformance& d, std::int64_t calibration_id,
                                std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "write performance_daily",
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "INSERT OR REPLACE INTO performance_daily(day, e_el_meas_wh, e_el_model_wh, "
            "e_th_meas_wh, e_th_model_wh, pi_el, pi_th, pi_el_low, pi_el_high, pi_th_low, "
            "pi_th_high, valid_minutes, calibration_id) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, "
            "?, ?)",
            &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_int64(stmt, 1, d.day_start_s);
        const double reals[] = {d.e_el_meas_wh, d.e_el_model_wh, d.e_th_meas_wh, d.e_th_model_wh,
                                d.pi_el,        d.pi_th,         d.pi_el_low,    d.pi_el_high,
                                d.pi_th_low,    d.pi_th_high};
        for (int k = 0; k < 10; ++k) BindReal(stmt, k + 2, reals[k]);
        sqlite3_bind_int(stmt, 12, d.valid_minutes);
        if (calibration_id > 0) {
          sqlite3_bind_int64(stmt, 13, calibration_id);
        } else {
          sqlite3_bind_null(stmt, 13);
        }
        return db.StepDone(stmt, "write performance day " + std::to_string(d.day_start_s));
      },
      error);
}

bool Store::ReadPerformanceDays(std::int64_t from_ts, std::int64_t to_ts,
                                std::vector<DayPerformance>* out, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::vector<DayPerformance> days;
  const bool ok = db.Run(
      false, "read performance_daily",
      [&]() -> DbStatus {
        days.clear();
        return db.SelectRange(
            "SELECT day, e_el_meas_wh, e_el_model_wh, e_th_meas_wh, e_th_model_wh, pi_el, pi_th, "
            "pi_el_low, pi_el_high, pi_th_low, pi_th_high, valid_minutes FROM performance_daily "
            "WHERE day >= ? AND day < ? ORDER BY day",
            from_ts, to_ts,
            [&days](sqlite3_stmt* stmt) {
              DayPerformance& d = days.emplace_back();
              d.day_start_s = sqlite3_column_int64(stmt, 0);
              double* reals[] = {&d.e_el_meas_wh,  &d.e_el_model_wh, &d.e_th_meas_wh,
                                 &d.e_th_model_wh, &d.pi_el,         &d.pi_th,
                                 &d.pi_el_low,     &d.pi_el_high,    &d.pi_th_low,
                                 &d.pi_th_high};
              for (int k = 0; k < 10; ++k) *reals[k] = ColumnReal(stmt, k + 1);
              d.valid_minutes = sqlite3_column_int(stmt, 11);
              d.scored_el = std::isfinite(d.pi_el);
              d.scored_th = std::isfinite(d.pi_th);
            },
            "read performance_daily");
      },
      error);
  if (ok) *out = std::move(days);
  return ok;
}

bool Store::RecordSensorFaults(const std::vector<SensorFault>& faults, std::string* error) {
  if (faults.empty()) return true;
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "record sensor faults",
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "INSERT INTO qc_event(channel, start_ts, end_ts, kind, detail) VALUES(?, ?, ?, ?, ?) "
            "ON CONFLICT(channel, kind, start_ts) DO UPDATE SET end_ts = MAX(end_ts, "
            "excluded.end_ts), detail = excluded.detail",
            &stmt);
        if (!s.ok()) return s;
        for (const SensorFault& f : faults) {
          sqlite3_reset(stmt);
          sqlite3_bind_text(stmt, 1, f.channel.c_str(), -1, SQLITE_TRANSIENT);
          sqlite3_bind_int64(stmt, 2, f.start_s);
          sqlite3_bind_int64(stmt, 3, f.end_s);
          sqlite3_bind_text(stmt, 4, f.kind.c_str(), -1, SQLITE_TRANSIENT);
          sqlite3_bind_text(stmt, 5, f.detail.c_str(), -1, SQLITE_TRANSIENT);
          s = db.StepDone(stmt, "record " + f.kind + " of " + f.channel);
          if (!s.ok()) return s;
        }
        return DbStatus{};
      },
      error);
}

bool Store::InsertMonitorEvent(std::int64_t ts, const std::string& kind,
                               const std::string& severity, const std::string& message,
                               std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "insert monitor_event",
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "INSERT INTO monitor_event(ts, kind, severity, message) VALUES(?, ?, ?, ?)", &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_int64(stmt, 1, ts);
        sqlite3_bind_text(stmt, 2, kind.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(stmt, 3, severity.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(stmt, 4, message.c_str(), -1, SQLITE_TRANSIENT);
        return db.StepDone(stmt, "insert monitor_event " + kind);
      },
      error);
}

bool Store::LatestMonitorEventSeverity(const std::string& kind, std::string* severity, bool* found,
                                       std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::string result;
  bool any = false;
  const bool ok = db.Run(
      false, "read monitor_event",
      [&]() -> DbStatus {
        any = false;
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "SELECT severity FROM monitor_event WHERE kind = ? ORDER BY ts DESC, id DESC LIMIT 1",
            &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_text(stmt, 1, kind.c_str(), -1, SQLITE_TRANSIENT);
        const int rc = sqlite3_step(stmt);
        if (rc == SQLITE_ROW) {
          any = true;
          result = ColumnText(stmt, 0);
        }
        sqlite3_reset(stmt);
        return rc == SQLITE_ROW || rc == SQLITE_DONE ? DbStatus{}
                                                     : db.Fail(rc, "read monitor_event");
      },
      error);
  if (!ok) return false;
  *found = any;
  if (any) *severity = result;
  return true;
}

bool Store::ReadAcceptedParameters(std::int64_t since_ts,
                                   std::map<std::string, std::vector<ParameterPoint>>* out,
                                   std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::map<std::string, std::vector<ParameterPoint>> points;
  const bool ok = db.Run(
      false, "read parameter_history",
      [&]() -> DbStatus {
        points.clear();
        return db.SelectRange(
            "SELECT name, run_at, value, std_error FROM parameter_history WHERE accepted = 1 AND "
            "run_at >= ? AND run_at < ? ORDER BY run_at",
            since_ts, std::numeric_limits<std::int64_t>::max(),
            [&points](sqlite3_stmt* stmt) {
              points[ColumnText(stmt, 0)].push_back(
                  {sqlite3_column_int64(stmt, 1), ColumnReal(stmt, 2), ColumnReal(stmt, 3)});
            },
            "read parameter_history");
      },
      error);
  if (ok) *out = std::move(points);
  return ok;
}

bool Store::InsertDiagnosis(DiagnosisRow* row, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::int64_t id = 0;
  const bool ok = db.Run(
      true, "insert diagnosis",
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "INSERT INTO diagnosis(run_at, calibration_id, window_start, window_end, "
            "base_variant, verdict, low_confidence, shrink_pct, bias_p_el_w, bias_q_th_w, "
            "report_json) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_int64(stmt, 1, row->run_at);
        if (row->calibration_id > 0) {
          sqlite3_bind_int64(stmt, 2, row->calibration_id);
        } else {
          sqlite3_bind_null(stmt, 2);
        }
        sqlite3_bind_int64(stmt, 3, row->window_start);
        sqlite3_bind_int64(stmt, 4, row->window_end);
        sqlite3_bind_text(stmt, 5, row->base_variant.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(stmt, 6, row->verdict.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_int(stmt, 7, row->low_confidence ? 1 : 0);
        BindReal(stmt, 8, row->shrink_pct);
        BindReal(stmt, 9, row->bias_p_el_w);
        BindReal(stmt, 10, row->bias_q_th_w);
        sqlite3_bind_text(stmt, 11, row->report_json.c_str(), -1, SQLITE_TRANSIENT);
        s = db.StepDone(stmt, "insert diagnosis");
        if (s.ok()) id = sqlite3_last_insert_rowid(db.db);
        return s;
      },
      error);
  if (ok) row->id = id;
  return ok;
}

bool Store::LatestDiagnosis(DiagnosisRow* row, bool* found, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  DiagnosisRow result;
  bool any = false;
  const bool ok = db.Run(
      false, "read latest diagnosis",
      [&]() -> DbStatus {
        any = false;
        return db.SelectRange(
            "SELECT id, run_at, calibration_id, window_start, window_end, base_variant, verdict, "
            "low_confidence, shrink_pct, bias_p_el_w, bias_q_th_w FROM diagnosis WHERE run_at >= "
            "? AND run_at < ? ORDER BY run_at DESC, id DESC LIMIT 1",
            std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max(),
            [&](sqlite3_stmt* stmt) {
              any = true;
              result.id = sqlite3_column_int64(stmt, 0);
              result.run_at = sqlite3_column_int64(stmt, 1);
              result.calibration_id = sqlite3_column_int64(stmt, 2);
              result.window_start = sqlite3_column_int64(stmt, 3);
              result.window_end = sqlite3_column_int64(stmt, 4);
              result.base_variant = ColumnText(stmt, 5);
              result.verdict = ColumnText(stmt, 6);
              result.low_confidence = sqlite3_column_int(stmt, 7) != 0;
              result.shrink_pct = ColumnReal(stmt, 8);
              result.bias_p_el_w = ColumnReal(stmt, 9);
              result.bias_q_th_w = ColumnReal(stmt, 10);
            },
            "read latest diagnosis");
      },
      error);
  if (!ok) return false;
  *found = any;
  if (any) *row = std::move(result);
  return true;
}

bool Store::WriteIntervalRows(const Series& rows, std::string* error) {
  const auto step_s = static_cast<std::int64_t>(rows.step_s);
  if (static_cast<double>(step_s) != rows.step_s || step_s <= kMinuteS || step_s % kMinuteS != 0) {
    *error = impl_->path + ": measurement_interval: step " + std::to_string(rows.step_s) +
             " s is not a whole number of minutes above one";
    return false;
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows.time_s[i] != MinuteStart(rows.time_s[i])) {
      *error = impl_->path + ": interval row " + std::to_string(i) + " at ts " +
               std::to_string(rows.time_s[i]) + ": not the start of a minute";
      return false;
    }
  }
  static const std::string sql = "INSERT OR REPLACE INTO measurement_interval(ts, step_s, " +
                                 ChannelColumns() + ", qc_flags) VALUES(" +
                                 Placeholders(kNumChannels + 3) + ")";
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "write " + std::to_string(rows.size()) + " interval rows",
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(sql, &stmt);
        if (!s.ok()) return s;
        for (std::size_t i = 0; i < rows.size(); ++i) {
          sqlite3_reset(stmt);
          sqlite3_bind_int64(stmt, 1, rows.time_s[i]);
          sqlite3_bind_int64(stmt, 2, step_s);
          for (std::size_t c = 0; c < kNumChannels; ++c) {
            const auto channel = static_cast<Channel>(c);
            BindReal(stmt, static_cast<int>(c) + 3, ToSql(channel, rows.At(channel, i)));
          }
          sqlite3_bind_int64(stmt, static_cast<int>(kNumChannels) + 3, ImportedRowFlags(rows, i));
          s = db.StepDone(stmt, "write interval row ts " + std::to_string(rows.time_s[i]));
          if (!s.ok()) return s;
        }
        return DbStatus{};
      },
      error);
}

bool Store::ReadIntervalRows(std::int64_t from_ts, std::int64_t to_ts, Series* out,
                             std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  static const std::string sql = "SELECT ts, step_s, " + ChannelColumns() +
                                 " FROM measurement_interval WHERE ts >= ? AND ts < ? ORDER BY ts";
  Series rows;
  std::map<std::int64_t, std::size_t> steps;  // step_s -> rows
  const bool ok = db.Run(
      false, "read interval rows",
      [&]() -> DbStatus {
        rows = Series{};
        steps.clear();
        return db.SelectRange(
            sql, from_ts, to_ts,
            [&rows, &steps](sqlite3_stmt* stmt) {
              rows.time_s.push_back(sqlite3_column_int64(stmt, 0));
              ++steps[sqlite3_column_int64(stmt, 1)];
              for (std::size_t c = 0; c < kNumChannels; ++c) {
                rows.columns[c].push_back(
                    FromSql(static_cast<Channel>(c), ColumnReal(stmt, static_cast<int>(c) + 2)));
              }
            },
            "read interval rows");
      },
      error);
  if (!ok) return false;
  rows.step_s = static_cast<double>(kMinuteS);
  std::size_t most = 0;
  for (const auto& [step_s, n] : steps) {
    if (n > most) {
      most = n;
      rows.step_s = static_cast<double>(step_s);
    }
  }
  ApplyPhysicalLimits(&rows, db.options.aggregate.area_m2);
  DropEmptyColumns(&rows);
  *out = std::move(rows);
  return true;
}

bool Store::ReadMinutes(std::int64_t from_ts, std::int64_t to_ts, Series* out, std::string* error) {
  MinuteRows rows;
  if (!ReadMinuteRows(from_ts, to_ts, &rows, error)) return false;
  *out = std::move(rows.rows);
  return true;
}

bool Store::ApplyRetention(std::int64_t now_ts, int raw_retention_days, std::string* error) {
  Impl& db = *impl_;
  if (raw_retention_days < 1) {
    *error = "raw_retention_days = " + std::to_string(raw_retention_days) + ": must be >= 1";
    return false;
  }
  std::lock_guard lock(db.mutex);
  const std::int64_t cutoff_ts = MinuteStart(now_ts - raw_retention_days * kSecondsPerDay);
  return db.Run(
      true, "apply retention",
      [&]() -> DbStatus {
        int written = 0;
        DbStatus s = db.AggregateRange(kNoLowerBound, cutoff_ts, false, &written);
        if (!s.ok()) return s;
        sqlite3_stmt* stmt = nullptr;
        s = db.Prepare("DELETE FROM sample_5s WHERE ts < ?", &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_int64(stmt, 1, cutoff_ts);
        s = db.StepDone(stmt, "delete samples before " + std::to_string(cutoff_ts));
        if (!s.ok()) return s;
        // A week back: rows before that were pruned by earlier daily calls,
        // and the DELETE stays short while it holds the write lock.
        return db.PruneForecasts(cutoff_ts - 7 * kSecondsPerDay, cutoff_ts);
      },
      error);
}

bool Store::PruneForecasts(std::int64_t from_ts, std::int64_t to_ts, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "prune forecasts", [&] { return db.PruneForecasts(from_ts, to_ts); }, error);
}

DbStatus Store::Impl::PruneForecasts(std::int64_t from_ts, std::int64_t to_ts) {
  // A row survives if forecast_latest shows it or forecast_skill scores it.
  sqlite3_stmt* stmt = nullptr;
  DbStatus s = Prepare(
      "DELETE FROM forecast WHERE ts >= ? AND ts < ?"
      " AND issued_at != (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = forecast.ts)"
      " AND issued_at IS NOT (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = forecast.ts"
      "  AND g.issued_at <= forecast.ts - ((forecast.ts % 86400) + 86400) % 86400)",
      &stmt);
  if (!s.ok()) return s;
  sqlite3_bind_int64(stmt, 1, from_ts);
  sqlite3_bind_int64(stmt, 2, to_ts);
  return StepDone(stmt, "delete superseded forecasts before " + std::to_string(to_ts));
}

bool Store::InsertCalibration(CalibrationRow* row, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::int64_t id = 0;
  const bool ok = db.Run(
      true, "insert calibration",
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "INSERT INTO calibration(run_at, variant, window_start, window_end, status, "
            "mae_p_el_w, mae_q_th_w, runtime_s, n_evals, params_json, reason, heldout_mae_w, "
            "accepted) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_int64(stmt, 1, row->run_at);
        sqlite3_bind_text(stmt, 2, row->variant.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_int64(stmt, 3, row->window_start);
        sqlite3_bind_int64(stmt, 4, row->window_end);
        sqlite3_bind_text(stmt, 5, row->status.c_str(), -1, SQLITE_TRANSIENT);
        BindReal(stmt, 6, row->mae_p_el_w);
        BindReal(stmt, 7, row->mae_q_th_w);
        BindReal(stmt, 8, row->runtime_s);
        sqlite3_bind_int64(stmt, 9, row->n_evals);
        sqlite3_bind_text(stmt, 10, row->params_json.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(stmt, 11, row->reason.c_str(), -1, SQLITE_TRANSIENT);
        BindReal(stmt, 12, row->heldout_mae_w);
        sqlite3_bind_int(stmt, 13, row->accepted ? 1 : 0);
        s = db.StepDone(stmt, "insert calibration");
        if (!s.ok()) return s;
        id = sqlite3_last_insert_rowid(db.db);
        return db.InsertCalibrationParams(id, row->params);
      },
      error);
  if (ok) row->id = id;
  return ok;
}

bool Store::UpdateCalibrationParams(std::int64_t id, const std::string& params_json,
                                    const std::vector<CalibrationParamRow>& params,
                                    const std::string& reason_note, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "update calibration " + std::to_string(id),
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "UPDATE calibration SET params_json = ?, reason = COALESCE(reason, '') || ? WHERE id "
            "= ?",
            &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_text(stmt, 1, params_json.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(stmt, 2, reason_note.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_int64(stmt, 3, id);
        s = db.StepDone(stmt, "update calibration " + std::to_string(id));
        if (!s.ok()) return s;
        s = db.Prepare("DELETE FROM calibration_param WHERE calibration_id = ?", &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_int64(stmt, 1, id);
        s = db.StepDone(stmt, "replace the parameters of calibration " + std::to_string(id));
        if (!s.ok()) return s;
        return db.InsertCalibrationParams(id, params);
      },
      error);
}

DbStatus Store::Impl::InsertCalibrationParams(std::int64_t calibration_id,
                                              const std::vector<CalibrationParamRow>& params) {
  if (params.empty()) return {};
  sqlite3_stmt* stmt = nullptr;
  DbStatus s = Prepare(
      "INSERT OR REPLACE INTO calibration_param(calibration_id, name, value, std_error, unit, "
      "status) VALUES(?, ?, ?, ?, ?, ?)",
      &stmt);
  if (!s.ok()) return s;
  for (const CalibrationParamRow& p : params) {
    sqlite3_reset(stmt);
    sqlite3_bind_int64(stmt, 1, calibration_id);
    sqlite3_bind_text(stmt, 2, p.name.c_str(), -1, SQLITE_TRANSIENT);
    BindReal(stmt, 3, p.value);
    BindReal(stmt, 4, p.std_error);
    sqlite3_bind_text(stmt, 5, p.unit.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(stmt, 6, p.status.c_str(), -1, SQLITE_TRANSIENT);
    s = StepDone(
        stmt, "insert parameter " + p.name + " of calibration " + std::to_string(calibration_id));
    if (!s.ok()) return s;
  }
  return {};
}

bool Store::LatestAcceptedCalibration(CalibrationRow* row, bool* found, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  CalibrationRow result;
  bool any = false;
  const bool ok = db.Run(
      false, "read latest accepted calibration",
      [&]() -> DbStatus {
        any = false;
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "SELECT id, run_at, variant, window_start, window_end, status, mae_p_el_w, "
            "mae_q_th_w, runtime_s, n_evals, params_json, reason, heldout_mae_w, accepted "
            "FROM calibration WHERE accepted != 0 ORDER BY run_at DESC, id DESC LIMIT 1",
            &stmt);
        if (!s.ok()) return s;
        const int rc = sqlite3_step(stmt);
        if (rc == SQLITE_DONE) return {};
        if (rc != SQLITE_ROW) return db.Fail(rc, "read calibration");
        any = true;
        result.id = sqlite3_column_int64(stmt, 0);
        result.run_at = sqlite3_column_int64(stmt, 1);
        result.variant = ColumnText(stmt, 2);
        result.window_start = sqlite3_column_int64(stmt, 3);
        result.window_end = sqlite3_column_int64(stmt, 4);
        result.status = ColumnText(stmt, 5);
        result.mae_p_el_w = ColumnReal(stmt, 6);
        result.mae_q_th_w = ColumnReal(stmt, 7);
        result.runtime_s = ColumnReal(stmt, 8);
        result.n_evals = static_cast<long>(sqlite3_column_int64(stmt, 9));
        result.params_json = ColumnText(stmt, 10);
        result.reason = ColumnText(stmt, 11);
        result.heldout_mae_w = ColumnReal(stmt, 12);
        result.accepted = sqlite3_column_int(stmt, 13) != 0;
        sqlite3_reset(stmt);
        return {};
      },
      error);
  if (!ok) return false;
  *found = any;
  if (any) *row = std::move(result);
  return true;
}

bool Store::InsertForecast(std::int64_t issued_at, std::int64_t calibration_id,
                           const std::string& inputs, const std::vector<ForecastRow>& rows,
                           std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "insert forecast issued at " + std::to_string(issued_at),
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "INSERT OR REPLACE INTO forecast(issued_at, ts, calibration_id, p_el_w, q_th_w, "
            "t_pv_c, t_out_c, inputs, p_el_w_p10, p_el_w_p90, q_th_w_p10, q_th_w_p90, "
            "p_el_w_ref, q_th_w_ref, p_el_w_p50, q_th_w_p50) "
            "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            &stmt);
        if (!s.ok()) return s;
        for (const ForecastRow& row : rows) {
          sqlite3_reset(stmt);
          sqlite3_bind_int64(stmt, 1, issued_at);
          sqlite3_bind_int64(stmt, 2, row.ts);
          if (calibration_id > 0) {
            sqlite3_bind_int64(stmt, 3, calibration_id);
          } else {
            sqlite3_bind_null(stmt, 3);
          }
          int column = 4;
          for (double v : {row.p_el_w, row.q_th_w, row.t_pv_c, row.t_out_c}) {
            BindReal(stmt, column++, v);
          }
          sqlite3_bind_text(stmt, column++, inputs.c_str(), -1, SQLITE_TRANSIENT);
          for (double v : {row.p_el_w_p10, row.p_el_w_p90, row.q_th_w_p10, row.q_th_w_p90,
                           row.p_el_w_ref, row.q_th_w_ref, row.p_el_w_p50, row.q_th_w_p50}) {
            BindReal(stmt, column++, v);
          }
          s = db.StepDone(stmt, "insert forecast row ts " + std::to_string(row.ts));
          if (!s.ok()) return s;
        }
        return {};
      },
      error);
}

template <typename Row, typename FromStatement>
bool Store::Impl::ReadRows(const std::string& sql, const std::string& what, std::int64_t from,
                           std::int64_t to, FromStatement from_statement, std::vector<Row>* out,
                           std::string* error) {
  Impl& db = *this;
  std::vector<Row> rows;
  const bool ok = db.Run(
      false, what,
      [&]() -> DbStatus {
        rows.clear();
        auto on_row = [&](sqlite3_stmt* stmt) { rows.push_back(from_statement(stmt)); };
        return db.SelectRange(sql, from, to, on_row, what);
      },
      error);
  if (ok) *out = std::move(rows);
  return ok;
}

bool Store::ReadLatestForecast(std::int64_t from_ts, std::int64_t to_ts,
                               std::vector<ForecastRow>* out, std::string* error) {
  return impl_->ReadRows(
      "SELECT ts, p_el_w, q_th_w, t_pv_c, t_out_c, p_el_w_p10, p_el_w_p90, q_th_w_p10, "
      "q_th_w_p90, p_el_w_p50, q_th_w_p50 FROM forecast_latest WHERE ts >= ? AND ts < ? "
      "ORDER BY ts",
      "read forecast_latest", from_ts, to_ts,
      [](sqlite3_stmt* stmt) {
        ForecastRow r;
        r.ts = sqlite3_column_int64(stmt, 0);
        ColumnReals(stmt,
                    {&r.p_el_w, &r.q_th_w, &r.t_pv_c, &r.t_out_c, &r.p_el_w_p10, &r.p_el_w_p90,
                     &r.q_th_w_p10, &r.q_th_w_p90, &r.p_el_w_p50, &r.q_th_w_p50});
        return r;
      },
      out, error);
}

bool Store::ReadForecastSkill(std::int64_t from_day, std::int64_t to_day,
                              std::vector<SkillRow>* out, std::string* error) {
  return impl_->ReadRows(
      "SELECT day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, skill_p_el, skill_q_th, "
      "coverage_p10_p90, minutes, coverage_p_el, coverage_q_th FROM forecast_skill "
      "WHERE day >= ? AND day < ? ORDER BY day",
      "read forecast_skill", from_day, to_day,
      [](sqlite3_stmt* stmt) {
        SkillRow r;
        r.day = sqlite3_column_int64(stmt, 0);
        ColumnReals(stmt, {&r.mae_p_el_w, &r.mae_q_th_w, &r.nmae_p_el, &r.nmae_q_th, &r.skill_p_el,
                           &r.skill_q_th, &r.coverage_p10_p90});
        r.minutes = sqlite3_column_int64(stmt, 8);
        r.coverage_p_el =
            sqlite3_column_type(stmt, 9) == SQLITE_NULL ? kNoValue : sqlite3_column_double(stmt, 9);
        r.coverage_q_th = sqlite3_column_type(stmt, 10) == SQLITE_NULL
                              ? kNoValue
                              : sqlite3_column_double(stmt, 10);
        return r;
      },
      out, error);
}

namespace {

// A forecast input cell: NULL is missing; INTEGER and REAL are numbers; TEXT
// and BLOB (which sqlite3_column_double would turn into 0, or into the
// number a text starts with) are missing unless the whole text, blanks
// around it aside, is a finite decimal number. *text is set for a cell read
// as missing because it held text.
double InputCell(sqlite3_stmt* stmt, int index, bool* text) {
  *text = false;
  const int type = sqlite3_column_type(stmt, index);
  if (type == SQLITE_NULL) return std::nan("");
  if (type != SQLITE_TEXT && type != SQLITE_BLOB) return sqlite3_column_double(stmt, index);
  const auto* chars = reinterpret_cast<const char*>(sqlite3_column_text(stmt, index));
  std::string cell(chars == nullptr ? "" : chars,
                   static_cast<std::size_t>(sqlite3_column_bytes(stmt, index)));
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!cell.empty() && blank(cell.back())) cell.pop_back();
  std::size_t first = 0;
  while (first < cell.size() && blank(cell[first])) ++first;
  cell.erase(0, first);
  // Decimal digits, sign, point and exponent only: no hex, inf or nan,
  // which strtod would also take.
  const bool decimal =
      !cell.empty() && cell.find_first_not_of("0123456789+-.eE") == std::string::npos;
  char* end = nullptr;
  const double value = decimal ? std::strtod(cell.c_str(), &end) : 0.0;
  if (decimal && end == cell.c_str() + cell.size() && std::isfinite(value)) return value;
  *text = true;
  return std::nan("");
}

}  // namespace

std::size_t Store::TextCells::Total() const {
  std::size_t total = 0;
  for (const std::size_t n : count) total += n;
  return total;
}

std::string Store::TextCells::Warning(const std::string& table) const {
  std::string list;
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    if (count[c] == 0) continue;
    list += list.empty() ? std::to_string(count[c]) + " cells of "
                         : ", " + std::to_string(count[c]) + " of ";
    list += std::string(ChannelName(static_cast<Channel>(c)));
  }
  return list.empty() ? "" : table + ": " + list + " hold text, read as missing";
}

bool Store::Impl::ReadInputTable(const std::string& table, std::span<const Channel> channels,
                                 std::int64_t from, std::int64_t to, Series* out,
                                 std::string* error, TextCells* text_cells) {
  Impl& db = *this;
  std::string sql = "SELECT ts";
  for (const Channel c : channels) sql += ", " + std::string(ChannelName(c));
  sql += " FROM " + table + " WHERE ts >= ? AND ts < ? ORDER BY ts";
  Series result;
  TextCells texts;
  const bool ok = db.Run(
      false, "read " + table,
      [&]() -> DbStatus {
        result = Series{};
        texts = TextCells{};
        auto on_row = [&result, &texts, channels](sqlite3_stmt* stmt) {
          result.time_s.push_back(sqlite3_column_int64(stmt, 0));
          for (std::size_t k = 0; k < channels.size(); ++k) {
            bool text = false;
            const double value = InputCell(stmt, static_cast<int>(k) + 1, &text);
            texts.count[static_cast<std::size_t>(channels[k])] += text ? 1 : 0;
            result[channels[k]].push_back(FromSql(channels[k], value));
          }
        };
        return db.SelectRange(sql, from, to, on_row, "read " + table);
      },
      error);
  if (!ok) return false;
  if (text_cells != nullptr) *text_cells = texts;
  ApplyPhysicalLimits(&result, options.aggregate.area_m2);
  DropEmptyColumns(&result);
  result.step_s = 0.0;
  for (std::size_t i = 1; i < result.size(); ++i) {
    const auto dt_s = static_cast<double>(result.time_s[i] - result.time_s[i - 1]);
    if (result.step_s == 0.0 || dt_s < result.step_s) result.step_s = dt_s;
  }
  *out = std::move(result);
  return true;
}

bool Store::ReadWeatherForecast(std::int64_t from, std::int64_t to, Series* out, std::string* error,
                                TextCells* text_cells) {
  std::lock_guard lock(impl_->mutex);
  return impl_->ReadInputTable("weather_forecast", kWeatherChannels, from, to, out, error,
                               text_cells);
}

bool Store::ReadOperationPlan(std::int64_t from, std::int64_t to, Series* out, std::string* error,
                              TextCells* text_cells) {
  std::lock_guard lock(impl_->mutex);
  return impl_->ReadInputTable("operation_plan", kOperationChannels, from, to, out, error,
                               text_cells);
}

bool Store::WriteWeatherForecast(const Series& rows, const std::string& source,
                                 std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::string sql = "INSERT OR REPLACE INTO weather_forecast(ts";
  for (const Channel c : kWeatherChannels) sql += ", " + std::string(ChannelName(c));
  sql += ", source) VALUES(" + Placeholders(std::size(kWeatherChannels) + 2) + ")";
  return db.Run(
      true, "write weather_forecast",
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(sql, &stmt);
        if (!s.ok()) return s;
        for (std::size_t i = 0; i < rows.size(); ++i) {
          sqlite3_reset(stmt);
          sqlite3_bind_int64(stmt, 1, rows.time_s[i]);
          int k = 2;
          for (const Channel c : kWeatherChannels) BindReal(stmt, k++, ToSql(c, rows.At(c, i)));
          sqlite3_bind_text(stmt, k, source.c_str(), -1, SQLITE_TRANSIENT);
          s = db.StepDone(stmt, "write weather_forecast ts " + std::to_string(rows.time_s[i]));
          if (!s.ok()) return s;
        }
        return {};
      },
      error);
}

bool Store::ReadWeatherSources(std::int64_t from, std::int64_t to,
                               std::vector<std::string>* sources, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::vector<std::string> result;
  const bool ok = db.Run(
      false, "read weather_forecast sources",
      [&]() -> DbStatus {
        result.clear();
        return db.SelectRange(
            "SELECT COALESCE(source, 'weather_forecast') FROM weather_forecast WHERE ts >= ? AND "
            "ts < ? GROUP BY 1 ORDER BY COUNT(*) DESC, 1",
            from, to, [&](sqlite3_stmt* stmt) { result.push_back(ColumnText(stmt, 0)); },
            "read weather_forecast sources");
      },
      error);
  if (ok) *sources = std::move(result);
  return ok;
}

bool Store::WritePlantConfig(const std::vector<std::pair<std::string, double>>& values,
                             std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "write plant_config",
      [&]() -> DbStatus {
        DbStatus s = db.Exec("DELETE FROM plant_config");
        if (!s.ok()) return s;
        sqlite3_stmt* stmt = nullptr;
        s = db.Prepare("INSERT INTO plant_config(key, value) VALUES(?, ?)", &stmt);
        if (!s.ok()) return s;
        for (const auto& [key, value] : values) {
          sqlite3_reset(stmt);
          sqlite3_bind_text(stmt, 1, key.c_str(), -1, SQLITE_TRANSIENT);
          sqlite3_bind_double(stmt, 2, value);
          s = db.StepDone(stmt, "write plant_config " + key);
          if (!s.ok()) return s;
        }
        return {};
      },
      error);
}

bool Store::ReadPlantConfig(std::vector<std::pair<std::string, double>>* values,
                            std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::vector<std::pair<std::string, double>> result;
  const bool ok = db.Run(
      false, "read plant_config",
      [&]() -> DbStatus {
        result.clear();
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare("SELECT key, value FROM plant_config ORDER BY key", &stmt);
        if (!s.ok()) return s;
        int rc;
        while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
          result.emplace_back(ColumnText(stmt, 0), sqlite3_column_double(stmt, 1));
        }
        sqlite3_reset(stmt);
        return rc == SQLITE_DONE ? DbStatus{} : db.Fail(rc, "read plant_config");
      },
      error);
  if (ok) *values = std::move(result);
  return ok;
}

bool Store::Checkpoint(std::int64_t* db_bytes, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::int64_t bytes = 0;
  const bool ok = db.Run(
      false, "checkpoint",
      [&]() -> DbStatus {
        int log_frames = 0, checkpointed = 0;
        const int rc = sqlite3_wal_checkpoint_v2(db.db, nullptr, SQLITE_CHECKPOINT_TRUNCATE,
                                                 &log_frames, &checkpointed);
        // BUSY here means a reader holds an old snapshot: the checkpoint did
        // what it could, which is all a best-effort checkpoint promises.
        if (rc != SQLITE_OK && rc != SQLITE_BUSY) return db.Fail(rc, "wal_checkpoint");
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "SELECT (page_count - freelist_count) * page_size "
            "FROM pragma_page_count(), pragma_freelist_count(), pragma_page_size()",
            &stmt);
        if (!s.ok()) return s;
        const int src = sqlite3_step(stmt);
        if (src != SQLITE_ROW) return db.Fail(src, "page_count");
        bytes = sqlite3_column_int64(stmt, 0);
        sqlite3_reset(stmt);
        return {};
      },
      error);
  if (ok && db_bytes != nullptr) *db_bytes = bytes;
  return ok;
}

// --- Read-only open (the verbs that only read) ---

namespace {

// path as the path of an SQLite URI ("file:PATH?…"): '%', '?' and '#' escaped.
std::string UriPath(const std::string& path) {
  std::string out;
  for (const char c : path) {
    if (c == '%') {
      out += "%25";
    } else if (c == '?') {
      out += "%3f";
    } else if (c == '#') {
      out += "%23";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

std::unique_ptr<Store> Store::OpenReadOnly(const std::string& path, const StoreOptions& options,
                                           std::string* error) {
  assert(error != nullptr);
  if (::access(path.c_str(), F_OK) != 0) {
    *error = path + ": no such store (" + std::strerror(errno) + ")";
    return nullptr;
  }
  const auto open = [&](const char* query) -> std::unique_ptr<Impl> {
    auto impl = std::make_unique<Impl>();
    impl->path = path;
    impl->options = options;
    const std::string uri = "file:" + UriPath(path) + "?" + query;
    const int rc = sqlite3_open_v2(uri.c_str(), &impl->db,
                                   SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_NOMUTEX,
                                   nullptr);
    if (rc != SQLITE_OK) {
      *error = impl->Describe(impl->Fail(rc, "cannot open the store read-only"));
      return nullptr;
    }
    sqlite3_extended_result_codes(impl->db, 0);
    sqlite3_busy_timeout(impl->db, options.busy_timeout_ms);
    return impl;
  };
  std::unique_ptr<Impl> impl = open("mode=ro");
  if (impl == nullptr) return nullptr;
  // A WAL store is read through its -shm: without it, and without the right
  // to create it, the first read fails. No -wal and no -shm means no
  // connection has the store open, so its file alone is the whole store.
  int rc = sqlite3_exec(impl->db, "SELECT count(*) FROM sqlite_schema", nullptr, nullptr, nullptr);
  if ((rc == SQLITE_CANTOPEN || rc == SQLITE_READONLY) &&
      ::access((path + "-wal").c_str(), F_OK) != 0 &&
      ::access((path + "-shm").c_str(), F_OK) != 0) {
    impl = open("immutable=1");
    if (impl == nullptr) return nullptr;
    rc = sqlite3_exec(impl->db, "SELECT count(*) FROM sqlite_schema", nullptr, nullptr, nullptr);
  }
  if (rc != SQLITE_OK && rc != SQLITE_NOTADB) {
    *error = impl->Describe(impl->Fail(rc, "cannot read the store")) +
             "; a reader needs read access to the file and to its -wal and -shm files";
    return nullptr;
  }
  if (!impl->CheckIntegrityAndOwner(error)) return nullptr;
  int version = 0;
  sqlite3_exec(
      impl->db, "PRAGMA user_version",
      [](void* out, int, char** values, char**) {
        *static_cast<int*>(out) = values[0] ? std::atoi(values[0]) : 0;
        return 0;
      },
      &version, nullptr);
  if (version == 0) {
    *error = path + ": an empty database, not a pvtwin store yet; nothing to read";
    return nullptr;
  }
  if (version < kStoreSchemaVersion) {
    *error = path + ": store schema " + std::to_string(version) + " is older than this pvtwin's " +
             std::to_string(kStoreSchemaVersion) +
             "; run the daemon or `pvtwin migrate` to upgrade it (this command only reads)";
    return nullptr;
  }
  return std::unique_ptr<Store>(new Store(std::move(impl)));
}

}  // namespace pvtwin
