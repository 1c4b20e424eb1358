// The store's schema, version by version, and the migrations that bring an
// older store up to kStoreSchemaVersion (the schema is described at the head
// of io/store/store.h and in doc/sql.md).
#include <sqlite3.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "core/data/physical_limits.h"
#include "core/forecast/forecast.h"
#include "io/store/store_impl.h"

namespace pvtwin {

using namespace store_detail;

namespace {

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

// The view event: monitor_event, qc_event, the calibrations that
// calibration_filter (a condition on calibration row c, "1" for all) keeps,
// and the diagnoses, newest first.
std::string EventView(const std::string& calibration_filter) {
  return "CREATE VIEW event(ts, kind, severity, message) AS"
         " SELECT ts, kind, severity, message FROM monitor_event"
         " UNION ALL SELECT start_ts, 'qc_' || kind, 'warning', channel || ': ' || detail"
         "  FROM qc_event"
         " UNION ALL SELECT run_at, 'calibration_' || status,"
         "  CASE WHEN accepted = 1 THEN 'info' ELSE 'warning' END,"
         "  'calibration ' || id || ' (' || variant || '): ' || status ||"
         "  COALESCE(': ' || reason, '') FROM calibration" +
         std::string(calibration_filter == "1" ? "" : " c WHERE " + calibration_filter) +
         " UNION ALL SELECT run_at, 'diagnosis',"
         "  CASE WHEN verdict = 'none' THEN 'info' ELSE 'warning' END,"
         "  'diagnosis of ' || base_variant || ': ' || verdict ||"
         "  CASE WHEN low_confidence = 1 THEN ' (low confidence)' ELSE '' END FROM diagnosis"
         " ORDER BY 1 DESC";
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
      EventView("1"),
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

// One scored minute of forecast_skill (version 6 on) after its day: the
// errors, the reference's errors where the forecast has a value, and whether
// the measurement lies in a band of width (NULL without one); m the
// measurement, f the forecast.
constexpr const char* kSkillPairColumns =
    "  f.p_el_w - m.p_el_w AS err_p, CASE WHEN f.p_el_w IS NOT NULL THEN m.p_el_w END AS meas_p,"
    "  f.q_th_w - m.q_th_w AS err_q, CASE WHEN f.q_th_w IS NOT NULL THEN m.q_th_w END AS meas_q,"
    "  CASE WHEN f.p_el_w IS NOT NULL THEN f.p_el_w_ref - m.p_el_w END AS ref_p,"
    "  CASE WHEN f.q_th_w IS NOT NULL THEN f.q_th_w_ref - m.q_th_w END AS ref_q,"
    "  CASE WHEN f.p_el_w_p90 > f.p_el_w_p10 AND m.p_el_w IS NOT NULL"
    "   THEN m.p_el_w BETWEEN f.p_el_w_p10 AND f.p_el_w_p90 END AS in_p,"
    "  CASE WHEN f.q_th_w_p90 > f.q_th_w_p10 AND m.q_th_w IS NOT NULL"
    "   THEN m.q_th_w BETWEEN f.q_th_w_p10 AND f.q_th_w_p90 END AS in_q";

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
      " SELECT m.ts - ((m.ts % 86400) + 86400) % 86400 AS day," +
      std::string(kSkillPairColumns) +
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

// The columns of forecast_skill from version 8 on (and of
// forecast_skill_local, version 9).
constexpr const char* kSkillColumnsV8 =
    "(day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, skill_p_el, skill_q_th, "
    "coverage_p10_p90, minutes, coverage_p_el, coverage_q_th)";

// forecast_skill's columns (version 8 on) from its CTE `pairs`, per day.
std::string SkillAggregatesV8() {
  const std::string min_minutes = std::to_string(kMinScoredMinutes);
  const std::string enough = " CASE WHEN COUNT(*) >= " + min_minutes + " THEN";
  return " SELECT day, AVG(ABS(err_p)), AVG(ABS(err_q)),"
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
         " FROM pairs GROUP BY day";
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
  s.push_back(std::string("CREATE VIEW forecast_skill") + kSkillColumnsV8 +
              " AS "
              "WITH pairs AS ("
              " SELECT m.ts - ((m.ts % 86400) + 86400) % 86400 AS day," +
              kSkillPairColumns +
              " FROM measurement_1min m CROSS JOIN forecast f ON f.ts = m.ts"
              "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
              "   AND g.issued_at <= m.ts - ((m.ts % 86400) + 86400) % 86400)"
              " WHERE m.valid IS NULL OR m.valid != 0)" +
              SkillAggregatesV8());
  return s;
}

// performance_daily_local (version 9, io/store/store.h): `part` is a local
// day's valid minutes within one UTC day, `shared` adds that UTC day's
// performance_daily row and the share of its irradiation (or, without
// irradiation, of its minutes) that falls in the local day.
std::string PerformanceDailyLocal() {
  const std::string valid = "(m.valid IS NULL OR m.valid != 0)";
  const std::string utc_day_minutes =
      "FROM measurement_1min m WHERE m.ts >= p.utc_day AND m.ts < p.utc_day + 86400 AND " + valid;
  return "CREATE VIEW performance_daily_local(day, e_el_meas_wh, e_el_model_wh, e_th_meas_wh, "
         "e_th_model_wh, pi_el, pi_th, valid_minutes) AS "
         "WITH part AS ("
         " SELECT d.day AS day, m.ts - ((m.ts % 86400) + 86400) % 86400 AS utc_day,"
         "  TOTAL(m.p_el_w) / 60.0 AS e_el, TOTAL(m.q_th_w) / 60.0 AS e_th,"
         "  TOTAL(MAX(m.g_poa_w_m2, 0)) AS g, COUNT(*) AS n"
         " FROM local_day d CROSS JOIN measurement_1min m ON m.ts >= d.start_ts"
         "  AND m.ts < d.end_ts WHERE " +
         valid +
         " GROUP BY d.day, utc_day),"
         " whole AS ("
         " SELECT p.*, (SELECT TOTAL(MAX(m.g_poa_w_m2, 0)) " +
         utc_day_minutes + ") AS day_g, (SELECT COUNT(*) " + utc_day_minutes +
         ") AS day_n FROM part p),"
         " shared AS ("
         " SELECT w.day, w.e_el, w.e_th, w.n, pd.day AS pd_day, pd.pi_el, pd.pi_th,"
         "  pd.e_el_model_wh, pd.e_th_model_wh,"
         "  CASE WHEN w.day_g > 0 THEN w.g / w.day_g ELSE CAST(w.n AS REAL) / w.day_n END AS share"
         " FROM whole w LEFT JOIN performance_daily pd ON pd.day = w.utc_day)"
         " SELECT day, SUM(e_el),"
         "  CASE WHEN COUNT(pd_day) = COUNT(*) THEN SUM(e_el_model_wh * share) END, SUM(e_th),"
         "  CASE WHEN COUNT(pd_day) = COUNT(*) THEN SUM(e_th_model_wh * share) END,"
         "  CASE WHEN COUNT(pi_el) = COUNT(*) THEN SUM(e_el) / SUM(e_el_model_wh * share) END,"
         "  CASE WHEN COUNT(pi_th) = COUNT(*) THEN SUM(e_th) / SUM(e_th_model_wh * share) END,"
         "  SUM(n)"
         " FROM shared GROUP BY day";
}

// Version 9: local days (issue 54). SQLite knows no time zones, so the store
// writes each local day's UTC bounds (store_local_day.cc) and the local views
// group minutes by joining them. forecast_skill_local scores each minute
// against the newest issue at or before its local midnight.
std::vector<std::string> SchemaV9() {
  return {
      "CREATE TABLE local_day(day TEXT PRIMARY KEY, start_ts INTEGER NOT NULL, end_ts INTEGER "
      "NOT NULL) WITHOUT ROWID",
      "CREATE UNIQUE INDEX local_day_by_start ON local_day(start_ts)",
      "CREATE TABLE local_day_zone(id INTEGER PRIMARY KEY CHECK(id = 1), zone TEXT NOT NULL)",
      std::string("CREATE VIEW forecast_skill_local") + kSkillColumnsV8 +
          " AS "
          "WITH pairs AS ("
          " SELECT d.day AS day," +
          kSkillPairColumns +
          " FROM local_day d CROSS JOIN measurement_1min m ON m.ts >= d.start_ts"
          "  AND m.ts < d.end_ts"
          " CROSS JOIN forecast f ON f.ts = m.ts"
          "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
          "   AND g.issued_at <= d.start_ts)"
          " WHERE m.valid IS NULL OR m.valid != 0)" +
          SkillAggregatesV8(),
      PerformanceDailyLocal(),
  };
}

// Version 10 (issue 53, day one): each forecast says whether it comes from
// an accepted calibration or from the start values of a plant without one
// (core/forecast/start_value_forecast.h); rows written before were
// calibrated. forecast_latest shows it last. A new plant's wait for its two
// days of history (calibrations skipped before the first accepted one) is
// no warning in event: the daemon writes one info event for it instead.
std::vector<std::string> SchemaV10() {
  return {
      "ALTER TABLE forecast ADD COLUMN basis TEXT NOT NULL DEFAULT 'calibrated'",
      "DROP VIEW forecast_latest",
      "CREATE VIEW forecast_latest(ts, issued_at, p_el_w, q_th_w, t_pv_c, t_out_c, p_el_w_p10, "
      "p_el_w_p90, q_th_w_p10, q_th_w_p90, p_el_w_p50, q_th_w_p50, basis) AS "
      "SELECT f.ts, f.issued_at, f.p_el_w, f.q_th_w, f.t_pv_c, f.t_out_c, f.p_el_w_p10, "
      "f.p_el_w_p90, f.q_th_w_p10, f.q_th_w_p90, f.p_el_w_p50, f.q_th_w_p50, f.basis FROM "
      "forecast f WHERE f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = f.ts)",
      "DROP VIEW event",
      EventView("c.status != 'skipped' OR EXISTS (SELECT 1 FROM calibration a WHERE a.accepted = "
                "1 AND a.run_at <= c.run_at)"),
  };
}

}  // namespace

// Day-ahead pairs of version 11 (those of version 8) of the measurements
// `from` (an SQL FROM list naming the measurement_1min row m) where `where`.
std::string store_detail::SkillPairsV11(const std::string& from, const std::string& where) {
  return " SELECT m.ts - ((m.ts % 86400) + 86400) % 86400 AS day," +
         std::string(kSkillPairColumns) + " FROM " + from +
         " CROSS JOIN forecast f ON f.ts = m.ts"
         "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
         "   AND g.issued_at <= m.ts - ((m.ts % 86400) + 86400) % 86400)"
         " WHERE (m.valid IS NULL OR m.valid != 0) AND " +
         where;
}

std::string store_detail::SkillAggregatesV11() { return SkillAggregatesV8(); }

namespace {

// The first UTC day forecast_skill_day does not hold (version 11): closed
// days before it are materialised unless forecast_skill_dirty names them.
// Without a state row (a damaged store), none is.
constexpr const char* kSkillDoneBefore =
    "COALESCE((SELECT done_before FROM forecast_skill_state WHERE id = 1), "
    "-9223372036854775807 - 1)";

// The UTC day (00:00, unix s) of the SQL time expression t.
std::string UtcDayOf(const std::string& t) {
  return "(" + t + " - ((" + t + " % 86400) + 86400) % 86400)";
}

// Marks the UTC day of time `ts` (an OLD or NEW column) dirty when it is
// materialised (before done_before) and `also` holds.
std::string MarkDirty(const std::string& ts, const std::string& also) {
  return " INSERT OR IGNORE INTO forecast_skill_dirty(day) SELECT " + UtcDayOf(ts) + " WHERE " +
         ts + " < " + kSkillDoneBefore + " AND " + also + ";";
}

// Whether the forecast row `row` (OLD or NEW) is, or was, the issue
// forecast_skill scores at its ts: issued at or before its UTC day began,
// and no later such issue of that ts exists. A prune that deletes only
// superseded issues marks nothing.
std::string IsScoredIssue(const std::string& row) {
  const std::string day = UtcDayOf(row + ".ts");
  return row + ".issued_at <= " + day +
         " AND NOT EXISTS (SELECT 1 FROM forecast g WHERE g.ts = " + row +
         ".ts AND g.issued_at > " + row + ".issued_at AND g.issued_at <= " + day + ")";
}

// forecast_skill over forecast_skill_day (versions 11 on): the materialised
// rows of clean closed days, and the aggregates of live_pairs (the pairs of
// the minutes from done_before on and of the dirty days) for the rest.
std::string MaterialisedSkillView(const std::string& live_pairs, const std::string& aggregates) {
  return std::string("CREATE VIEW forecast_skill") + kSkillColumnsV8 +
         " AS SELECT day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, skill_p_el, skill_q_th, "
         "coverage_p10_p90, minutes, coverage_p_el, coverage_q_th FROM forecast_skill_day"
         " WHERE day < " +
         kSkillDoneBefore +
         " AND day NOT IN (SELECT day FROM forecast_skill_dirty)"
         " UNION ALL SELECT * FROM (WITH pairs AS (" +
         live_pairs + ")" + aggregates + ")";
}

// forecast_skill of version 11: the live computation as version 8's.
std::string ForecastSkillViewV11() {
  const std::string done = kSkillDoneBefore;
  return MaterialisedSkillView(
      store_detail::SkillPairsV11("measurement_1min m", "m.ts >= " + done) + " UNION ALL" +
          store_detail::SkillPairsV11(
              "forecast_skill_dirty x CROSS JOIN measurement_1min m ON m.ts >= x.day AND m.ts < "
              "x.day + 86400",
              "x.day < " + done),
      SkillAggregatesV8());
}

// Version 11 (forecast_skill materialised per UTC day): forecast_skill_day
// holds the rows of closed days (filled by Store::RefreshForecastSkill,
// store_skill.cc), forecast_skill_dirty the materialised days whose
// measurements or scored forecasts changed since (marked by triggers), and
// forecast_skill_state the first day not yet materialised. The migration
// materialises the days before the current UTC day (before the day after
// the newest measurement, when that is earlier).
std::vector<std::string> SchemaV11() {
  std::vector<std::string> s = {
      "CREATE TABLE forecast_skill_day(day INTEGER PRIMARY KEY, mae_p_el_w REAL, mae_q_th_w REAL, "
      "nmae_p_el REAL, nmae_q_th REAL, skill_p_el REAL, skill_q_th REAL, coverage_p10_p90 REAL, "
      "minutes INTEGER, coverage_p_el REAL, coverage_q_th REAL)",
      "CREATE TABLE forecast_skill_dirty(day INTEGER PRIMARY KEY)",
      "CREATE TABLE forecast_skill_state(id INTEGER PRIMARY KEY CHECK(id = 1), done_before "
      "INTEGER NOT NULL)",
      "INSERT INTO forecast_skill_state(id, done_before) SELECT 1, MIN(" +
          UtcDayOf("CAST(strftime('%s', 'now') AS INTEGER)") + ", COALESCE(" + UtcDayOf("MAX(ts)") +
          " + 86400, 0)) FROM measurement_1min",
      "WITH pairs AS (" +
          store_detail::SkillPairsV11("measurement_1min m",
                                      std::string("m.ts < ") + kSkillDoneBefore) +
          ") INSERT INTO forecast_skill_day" + SkillAggregatesV8(),
      "DROP VIEW forecast_skill",
      ForecastSkillViewV11(),
  };
  const std::string any = "1";
  s.push_back(
      "CREATE TRIGGER forecast_skill_measurement_insert AFTER INSERT ON measurement_1min "
      "BEGIN" +
      MarkDirty("NEW.ts", any) + " END");
  s.push_back(
      "CREATE TRIGGER forecast_skill_measurement_update AFTER UPDATE ON measurement_1min "
      "BEGIN" +
      MarkDirty("OLD.ts", any) + MarkDirty("NEW.ts", any) + " END");
  s.push_back(
      "CREATE TRIGGER forecast_skill_measurement_delete AFTER DELETE ON measurement_1min "
      "BEGIN" +
      MarkDirty("OLD.ts", any) + " END");
  s.push_back("CREATE TRIGGER forecast_skill_forecast_insert AFTER INSERT ON forecast BEGIN" +
              MarkDirty("NEW.ts", IsScoredIssue("NEW")) + " END");
  s.push_back("CREATE TRIGGER forecast_skill_forecast_update AFTER UPDATE ON forecast BEGIN" +
              MarkDirty("OLD.ts", "OLD.issued_at <= " + UtcDayOf("OLD.ts")) +
              MarkDirty("NEW.ts", "NEW.issued_at <= " + UtcDayOf("NEW.ts")) + " END");
  s.push_back("CREATE TRIGGER forecast_skill_forecast_delete AFTER DELETE ON forecast BEGIN" +
              MarkDirty("OLD.ts", IsScoredIssue("OLD")) + " END");
  return s;
}

// The rows m of measurement_interval (version 12) a day-ahead score reads:
// those of UTC days (or of the local day `d`) without any measurement_1min
// row. A day with 1-min rows is scored from them alone, as before.
std::string NoMinuteRowsIn(const std::string& start, const std::string& end) {
  return "NOT EXISTS (SELECT 1 FROM measurement_1min o WHERE o.ts >= " + start + " AND o.ts < " +
         end + ")";
}

std::string ReplaceAll(std::string text, const std::string& token, const std::string& by) {
  for (std::size_t at = text.find(token); at != std::string::npos;
       at = text.find(token, at + by.size())) {
    text.replace(at, token.size(), by);
  }
  return text;
}

}  // namespace

// Day-ahead pairs of version 12: those of version 11 from measurement_1min,
// and those of the measurement_interval rows of UTC days without 1-min
// rows, each pair with the seconds it stands for (step_s: 60 for a
// minute, the row's step_s for an interval row). `from` names the
// measurement row m and writes its table {m}.
std::string store_detail::SkillPairsV12(const std::string& from, const std::string& where) {
  const std::string day = UtcDayOf("m.ts");
  const auto pairs = [&](const char* table, const char* step_s, const std::string& also) {
    return " SELECT " + day + " AS day, " + step_s + " AS step_s," + kSkillPairColumns + " FROM " +
           ReplaceAll(from, "{m}", table) +
           " CROSS JOIN forecast f ON f.ts = m.ts"
           "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
           "   AND g.issued_at <= " +
           day + ") WHERE (m.valid IS NULL OR m.valid != 0) AND " + where + also;
  };
  return pairs("measurement_1min", "60", "") + " UNION ALL" +
         pairs("measurement_interval", "m.step_s", " AND " + NoMinuteRowsIn(day, day + " + 86400"));
}

// forecast_skill's columns (version 12) from its CTE `pairs` (with
// step_s), per day: each pair weighted by its minutes w = step_s / 60, so
// that a 10-min row counts as ten minutes in every mean and in `minutes`.
// For 1-min pairs (w = 1.0) every sum and quotient is the one of version 8
// (SUM(1.0 * x) / SUM(1.0) is AVG(x) in SQLite's arithmetic), and minutes
// stays COUNT(*), an integer.
std::string store_detail::SkillAggregatesV12() {
  const std::string w = "(step_s / 60.0)";
  const auto weight_of = [&](const std::string& x) {
    return "SUM(CASE WHEN " + x + " IS NOT NULL THEN " + w + " END)";
  };
  const auto mean_abs = [&](const std::string& x, const std::string& over) {
    return "(SUM(CASE WHEN " + over + " IS NOT NULL THEN " + w + " * ABS(" + x + ") END) / " +
           weight_of(over) + ")";
  };
  const auto skill = [&](const char* err, const char* ref) {
    return " 1.0 - SUM(CASE WHEN " + std::string(ref) + " IS NOT NULL THEN " + w + " * ABS(" + err +
           ") END) / NULLIF(SUM(CASE WHEN " + err + " IS NOT NULL THEN " + w + " * ABS(" + ref +
           ") END), 0) END,";
  };
  const auto inside = [&](const char* in) { return "TOTAL(" + w + " * " + in + ")"; };
  const auto banded = [&](const char* in) {
    return "TOTAL(CASE WHEN " + std::string(in) + " IS NOT NULL THEN " + w + " END)";
  };
  const std::string enough =
      " CASE WHEN SUM(step_s) >= " + std::to_string(kMinScoredMinutes * 60) + " THEN";
  return " SELECT day, " + mean_abs("err_p", "err_p") + ", " + mean_abs("err_q", "err_q") + ", " +
         mean_abs("err_p", "err_p") + " / " + mean_abs("meas_p", "err_p") + ", " +
         mean_abs("err_q", "err_q") + " / " + mean_abs("meas_q", "err_q") + "," + enough +
         skill("err_p", "ref_p") + enough + skill("err_q", "ref_q") + enough + " (" +
         inside("in_p") + " + " + inside("in_q") + ") / NULLIF(" + banded("in_p") + " + " +
         banded("in_q") +
         ", 0) END,"
         " CASE WHEN SUM(step_s) % 60 = 0 THEN SUM(step_s) / 60 ELSE SUM(step_s) / 60.0 END," +
         enough + " " + inside("in_p") + " / NULLIF(" + banded("in_p") + ", 0) END," + enough +
         " " + inside("in_q") + " / NULLIF(" + banded("in_q") + ", 0) END FROM pairs GROUP BY day";
}

namespace {

// forecast_skill of version 12: as version 11's, with the pairs of
// version 12 (interval rows of days without 1-min rows) in the live part.
std::string ForecastSkillViewV12() {
  const std::string done = kSkillDoneBefore;
  return MaterialisedSkillView(
      store_detail::SkillPairsV12("{m} m", "m.ts >= " + done) + " UNION ALL" +
          store_detail::SkillPairsV12(
              "forecast_skill_dirty x CROSS JOIN {m} m ON m.ts >= x.day AND m.ts < x.day + 86400",
              "x.day < " + done),
      store_detail::SkillAggregatesV12());
}

// forecast_skill_local of version 12: version 9's pairs per local day, and
// those of the interval rows of local days without 1-min rows.
std::string ForecastSkillLocalViewV12() {
  const auto pairs = [](const char* table, const char* step_s, const std::string& also) {
    return std::string(" SELECT d.day AS day, ") + step_s + " AS step_s," + kSkillPairColumns +
           " FROM local_day d CROSS JOIN " + table +
           " m ON m.ts >= d.start_ts AND m.ts < d.end_ts"
           " CROSS JOIN forecast f ON f.ts = m.ts"
           "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
           "   AND g.issued_at <= d.start_ts)"
           " WHERE (m.valid IS NULL OR m.valid != 0)" +
           also;
  };
  return std::string("CREATE VIEW forecast_skill_local") + kSkillColumnsV8 + " AS WITH pairs AS (" +
         pairs("measurement_1min", "60", "") + " UNION ALL" +
         pairs("measurement_interval", "m.step_s",
               " AND " + NoMinuteRowsIn("d.start_ts", "d.end_ts")) +
         ")" + store_detail::SkillAggregatesV12();
}

// Version 12 (issue 53 item 5: skill of forecasts from interval history):
// forecast_skill and forecast_skill_local score the measurement_interval
// rows of days without 1-min rows, each weighted by its step; triggers on
// measurement_interval mark such days dirty. The migration materialises
// the closed days that only interval rows score (version 11 has no row for
// them) and leaves every other row as it was.
std::vector<std::string> SchemaV12() {
  const std::string done = kSkillDoneBefore;
  std::vector<std::string> s = {
      "DROP VIEW forecast_skill",
      ForecastSkillViewV12(),
      "DROP VIEW forecast_skill_local",
      ForecastSkillLocalViewV12(),
      "WITH pairs AS (" +
          store_detail::SkillPairsV12(
              "{m} m", "m.ts < " + done +
                           " AND m.ts - ((m.ts % 86400) + 86400) % 86400 NOT IN (SELECT day FROM "
                           "forecast_skill_dirty)") +
          ") INSERT OR IGNORE INTO forecast_skill_day" + store_detail::SkillAggregatesV12(),
  };
  // A change of an interval row matters only to a day without 1-min rows.
  const auto unscored = [](const std::string& ts) {
    return NoMinuteRowsIn(UtcDayOf(ts), UtcDayOf(ts) + " + 86400");
  };
  s.push_back(
      "CREATE TRIGGER forecast_skill_interval_insert AFTER INSERT ON measurement_interval "
      "BEGIN" +
      MarkDirty("NEW.ts", unscored("NEW.ts")) + " END");
  s.push_back(
      "CREATE TRIGGER forecast_skill_interval_update AFTER UPDATE ON measurement_interval "
      "BEGIN" +
      MarkDirty("OLD.ts", unscored("OLD.ts")) + MarkDirty("NEW.ts", unscored("NEW.ts")) + " END");
  s.push_back(
      "CREATE TRIGGER forecast_skill_interval_delete AFTER DELETE ON measurement_interval "
      "BEGIN" +
      MarkDirty("OLD.ts", unscored("OLD.ts")) + " END");
  return s;
}

struct Migration {
  int to_version;
  std::vector<std::string> (*statements)();
};
const Migration kMigrations[] = {{1, &SchemaV1},   {2, &SchemaV2},   {3, &SchemaV3},
                                 {4, &SchemaV4},   {5, &SchemaV5},   {6, &SchemaV6},
                                 {7, &SchemaV7},   {8, &SchemaV8},   {9, &SchemaV9},
                                 {10, &SchemaV10}, {11, &SchemaV11}, {12, &SchemaV12}};
static_assert(sizeof(kMigrations) / sizeof(kMigrations[0]) == kStoreSchemaVersion,
              "one migration per schema version");

// The schema version of the open store (PRAGMA user_version), -1 when it
// cannot be read.
int UserVersion(sqlite3* db) {
  int version = -1;
  sqlite3_exec(
      db, "PRAGMA user_version",
      [](void* out, int, char** values, char**) {
        *static_cast<int*>(out) = values[0] ? std::atoi(values[0]) : 0;
        return 0;
      },
      &version, nullptr);
  return version;
}

// "<db>.schema-v<version>.bak", or the first "<db>.schema-v<version>.<n>.bak"
// that does not exist: an earlier backup is never overwritten.
std::string BackupPathFor(const std::string& db_path, int version) {
  const std::string stem = db_path + ".schema-v" + std::to_string(version);
  std::string candidate = stem + ".bak";
  for (int n = 1; std::filesystem::exists(candidate); ++n) {
    candidate = stem + "." + std::to_string(n) + ".bak";
  }
  return candidate;
}

}  // namespace

bool Store::Impl::Migrate(std::string* error) {
  const int version = UserVersion(db);
  if (version > 0 && version < kStoreSchemaVersion) {
    const std::string backup = BackupPathFor(path, version);
    std::string why;
    if (!BackupTo(backup, &why)) {
      std::error_code ignored;
      std::filesystem::remove(backup, ignored);
      *error = path + ": not migrating store schema " + std::to_string(version) + " → " +
               std::to_string(kStoreSchemaVersion) + " without a backup: " + why;
      return false;
    }
    upgrade = {version, kStoreSchemaVersion, backup};
    if (options.log) {
      options.log(kNotice, path + ": migrating store schema " + std::to_string(version) + " → " +
                               std::to_string(kStoreSchemaVersion) + " (backup: " + backup + ")");
    }
  }
  for (const Migration& migration : kMigrations) {
    Impl& db = *this;
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
    if (!migrated) return false;
  }
  return true;
}

}  // namespace pvtwin
