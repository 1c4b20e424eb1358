// The views of the central schema (io/fleet/upload.h): SQL text only.
#include "io/fleet/central_views.h"

#include <utility>
#include <vector>

#include "core/forecast/forecast.h"

namespace pvtwin {

std::string PlantLatestDdl(bool has_qc_event) {
  const std::string alarms =
      has_qc_event
          ? "(SELECT count(*) FROM qc_event e WHERE e.plant_id = p.plant_id AND e.end_ts IS NULL)"
          : "NULL::bigint";
  return "CREATE OR REPLACE VIEW plant_latest AS SELECT p.plant_id, p.last_upload_at, "
         "m.ts AS measurement_ts, m.p_el_w, m.q_th_w, m.t_in_c, m.t_out_c, m.g_poa_w_m2, "
         "m.t_amb_c, f.issued_at AS forecast_issued_at, c.id AS calibration_id, "
         "c.run_at AS calibration_run_at, c.variant AS calibration_variant, " +
         alarms +
         " AS open_alarms FROM plant p "
         "LEFT JOIN LATERAL (SELECT * FROM measurement_1min x WHERE x.plant_id = p.plant_id "
         "ORDER BY x.ts DESC LIMIT 1) m ON true "
         "LEFT JOIN LATERAL (SELECT max(x.issued_at) AS issued_at FROM forecast x "
         "WHERE x.plant_id = p.plant_id) f ON true "
         "LEFT JOIN LATERAL (SELECT * FROM calibration x WHERE x.plant_id = p.plant_id "
         "AND x.accepted <> 0 ORDER BY x.run_at DESC, x.id DESC LIMIT 1) c ON true;";
}

// view event(plant_id, ts, kind, severity, message): the store's event view
// (io/store/store.h) over every plant, from the tables that exist.
std::string EventDdl(const std::set<std::string>& present) {
  const std::vector<std::pair<std::string, std::string>> branches = {
      {"monitor_event", "SELECT plant_id, ts, kind, severity, message FROM monitor_event"},
      {"qc_event",
       "SELECT plant_id, start_ts, 'qc_' || kind, 'warning', channel || ': ' || detail "
       "FROM qc_event"},
      {"calibration",
       "SELECT plant_id, run_at, 'calibration_' || status, CASE WHEN accepted = 1 THEN 'info' "
       "ELSE 'warning' END, 'calibration ' || id || ' (' || variant || '): ' || status || "
       "COALESCE(': ' || reason, '') FROM calibration"},
      {"diagnosis",
       "SELECT plant_id, run_at, 'diagnosis', CASE WHEN verdict = 'none' THEN 'info' ELSE "
       "'warning' END, 'diagnosis of ' || base_variant || ': ' || verdict || CASE WHEN "
       "low_confidence = 1 THEN ' (low confidence)' ELSE '' END FROM diagnosis"},
  };
  std::string body;
  for (const auto& [table, select] : branches) {
    if (present.count(table)) body += (body.empty() ? "" : " UNION ALL ") + select;
  }
  if (body.empty()) {
    body = "SELECT NULL::text, NULL::bigint, NULL::text, NULL::text, NULL::text WHERE false";
  }
  return "CREATE OR REPLACE VIEW event(plant_id, ts, kind, severity, message) AS " + body + ";";
}

// view forecast_skill(plant_id, day, ...): the store's forecast_skill
// (io/store/store.h) over every plant: each minute scored against the
// newest issue made at or before 00:00 UTC of its day, which
// forecast_day_ahead keeps (version 5; version 4 read forecast, where
// hourly re-issues replaced most of them). Columns a plant's store does not
// have yet are NULL.
std::string ForecastSkillDdl(const std::set<std::string>& present,
                             const std::set<std::string>& forecast_columns) {
  const std::string head =
      "CREATE OR REPLACE VIEW forecast_skill(plant_id, day, mae_p_el_w, mae_q_th_w, nmae_p_el, "
      "nmae_q_th, skill_p_el, skill_q_th, coverage_p10_p90, minutes, coverage_p_el, "
      "coverage_q_th) AS ";
  if (!present.count("forecast_day_ahead") || !present.count("measurement_1min")) {
    return head +
           "SELECT NULL::text, NULL::bigint, NULL::double precision, NULL::double precision, "
           "NULL::double precision, NULL::double precision, NULL::double precision, NULL::double "
           "precision, NULL::double precision, NULL::bigint, NULL::double precision, NULL::double "
           "precision WHERE false;";
  }
  const auto f = [&forecast_columns](const std::string& column) {
    return forecast_columns.count(column) ? "f." + column : std::string("NULL::double precision");
  };
  const std::string enough =
      " CASE WHEN count(*) >= " + std::to_string(kMinScoredMinutes) + " THEN";
  return head +
         "WITH pairs AS (SELECT m.plant_id, m.ts - mod(mod(m.ts, 86400) + 86400, 86400) AS day,"
         " f.p_el_w - m.p_el_w AS err_p,"
         " CASE WHEN f.p_el_w IS NOT NULL THEN m.p_el_w END AS meas_p,"
         " f.q_th_w - m.q_th_w AS err_q,"
         " CASE WHEN f.q_th_w IS NOT NULL THEN m.q_th_w END AS meas_q,"
         " CASE WHEN f.p_el_w IS NOT NULL THEN " +
         f("p_el_w_ref") +
         " - m.p_el_w END AS ref_p,"
         " CASE WHEN f.q_th_w IS NOT NULL THEN " +
         f("q_th_w_ref") +
         " - m.q_th_w END AS ref_q,"
         " CASE WHEN " +
         f("p_el_w_p90") + " > " + f("p_el_w_p10") +
         " AND m.p_el_w IS NOT NULL THEN (m.p_el_w BETWEEN " + f("p_el_w_p10") + " AND " +
         f("p_el_w_p90") +
         ")::int END AS in_p,"
         " CASE WHEN " +
         f("q_th_w_p90") + " > " + f("q_th_w_p10") +
         " AND m.q_th_w IS NOT NULL THEN (m.q_th_w BETWEEN " + f("q_th_w_p10") + " AND " +
         f("q_th_w_p90") +
         ")::int END AS in_q"
         " FROM measurement_1min m JOIN forecast_day_ahead f"
         " ON f.plant_id = m.plant_id AND f.ts = m.ts"
         " AND f.issued_at <= m.ts - mod(mod(m.ts, 86400) + 86400, 86400)"
         " WHERE m.valid IS NULL OR m.valid <> 0)"
         " SELECT plant_id, day, avg(abs(err_p)), avg(abs(err_q)),"
         " avg(abs(err_p)) / nullif(avg(abs(CASE WHEN err_p IS NOT NULL THEN meas_p END)), 0),"
         " avg(abs(err_q)) / nullif(avg(abs(CASE WHEN err_q IS NOT NULL THEN meas_q END)), 0)," +
         enough +
         " 1.0 - sum(CASE WHEN ref_p IS NOT NULL THEN abs(err_p) END) /"
         " nullif(sum(CASE WHEN err_p IS NOT NULL THEN abs(ref_p) END), 0) END," +
         enough +
         " 1.0 - sum(CASE WHEN ref_q IS NOT NULL THEN abs(err_q) END) /"
         " nullif(sum(CASE WHEN err_q IS NOT NULL THEN abs(ref_q) END), 0) END," +
         enough +
         " (coalesce(sum(in_p), 0) + coalesce(sum(in_q), 0))::double precision /"
         " nullif(count(in_p) + count(in_q), 0) END,"
         " count(*)," +
         enough + " sum(in_p)::double precision / nullif(count(in_p), 0) END," + enough +
         " sum(in_q)::double precision / nullif(count(in_q), 0) END"
         " FROM pairs GROUP BY plant_id, day;";
}

}  // namespace pvtwin
