// What store schema version 11 was, for tests that compare version 12 with
// it or take a store back to it: forecast_skill_local's query of versions 9
// to 11 (1-min rows only), written out as it was, and the statements that
// remove version 12's triggers. Version 11's forecast_skill returned what
// version 10's query (store_schema_v10.h) returns.
#pragma once

#include <string>
#include <vector>

namespace pvtwin::testing {

// forecast_skill_local of versions 9 to 11: each valid minute of a local
// day scored against the newest issue at or before its local midnight.
inline const char* const kForecastSkillLocalV11 =
    "WITH pairs AS ("
    " SELECT d.day AS day,"
    "  f.p_el_w - m.p_el_w AS err_p, CASE WHEN f.p_el_w IS NOT NULL THEN m.p_el_w END AS meas_p,"
    "  f.q_th_w - m.q_th_w AS err_q, CASE WHEN f.q_th_w IS NOT NULL THEN m.q_th_w END AS meas_q,"
    "  CASE WHEN f.p_el_w IS NOT NULL THEN f.p_el_w_ref - m.p_el_w END AS ref_p,"
    "  CASE WHEN f.q_th_w IS NOT NULL THEN f.q_th_w_ref - m.q_th_w END AS ref_q,"
    "  CASE WHEN f.p_el_w_p90 > f.p_el_w_p10 AND m.p_el_w IS NOT NULL"
    "   THEN m.p_el_w BETWEEN f.p_el_w_p10 AND f.p_el_w_p90 END AS in_p,"
    "  CASE WHEN f.q_th_w_p90 > f.q_th_w_p10 AND m.q_th_w IS NOT NULL"
    "   THEN m.q_th_w BETWEEN f.q_th_w_p10 AND f.q_th_w_p90 END AS in_q"
    " FROM local_day d CROSS JOIN measurement_1min m ON m.ts >= d.start_ts"
    "  AND m.ts < d.end_ts"
    " CROSS JOIN forecast f ON f.ts = m.ts"
    "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
    "   AND g.issued_at <= d.start_ts)"
    " WHERE m.valid IS NULL OR m.valid != 0)"
    " SELECT day, AVG(ABS(err_p)), AVG(ABS(err_q)),"
    "  AVG(ABS(err_p)) / AVG(ABS(CASE WHEN err_p IS NOT NULL THEN meas_p END)),"
    "  AVG(ABS(err_q)) / AVG(ABS(CASE WHEN err_q IS NOT NULL THEN meas_q END)),"
    "  CASE WHEN COUNT(*) >= 360 THEN 1.0 -"
    "   SUM(CASE WHEN ref_p IS NOT NULL THEN ABS(err_p) END) /"
    "   NULLIF(SUM(CASE WHEN err_p IS NOT NULL THEN ABS(ref_p) END), 0) END,"
    "  CASE WHEN COUNT(*) >= 360 THEN 1.0 -"
    "   SUM(CASE WHEN ref_q IS NOT NULL THEN ABS(err_q) END) /"
    "   NULLIF(SUM(CASE WHEN err_q IS NOT NULL THEN ABS(ref_q) END), 0) END,"
    "  CASE WHEN COUNT(*) >= 360 THEN"
    "   (TOTAL(in_p) + TOTAL(in_q)) / NULLIF(COUNT(in_p) + COUNT(in_q), 0) END,"
    "  COUNT(*),"
    "  CASE WHEN COUNT(*) >= 360 THEN TOTAL(in_p) / NULLIF(COUNT(in_p), 0) END,"
    "  CASE WHEN COUNT(*) >= 360 THEN TOTAL(in_q) / NULLIF(COUNT(in_q), 0) END"
    " FROM pairs GROUP BY day";

// Removes version 12's triggers (its views stay: the caller replaces or
// drops them).
inline std::vector<std::string> DropSchemaV12() {
  std::vector<std::string> sql;
  for (const char* change : {"insert", "update", "delete"}) {
    sql.push_back(std::string("DROP TRIGGER forecast_skill_interval_") + change);
  }
  return sql;
}

}  // namespace pvtwin::testing
