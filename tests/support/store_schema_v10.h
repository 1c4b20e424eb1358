// What store schema version 10 was, for tests that compare version 11 with
// it or take a store back to it: forecast_skill's query of version 10 (the
// scan of measurement_1min on every read that version 11 materialises per
// day), written out as it was, and the statements that remove version 11's
// objects from a store.
#pragma once

#include <string>
#include <vector>

namespace pvtwin::testing {

// The columns of forecast_skill (version 8 on).
inline const char* const kForecastSkillColumns =
    "(day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, skill_p_el, skill_q_th, "
    "coverage_p10_p90, minutes, coverage_p_el, coverage_q_th)";

// The columns of forecast_skill's pairs (forecast minus measured minute,
// the reference's error and whether the band holds it) in versions 8 to 11,
// after the day.
inline const std::string kForecastSkillPairsV8ToV11 =
    "  f.p_el_w - m.p_el_w AS err_p, CASE WHEN f.p_el_w IS NOT NULL THEN m.p_el_w END AS meas_p,"
    "  f.q_th_w - m.q_th_w AS err_q, CASE WHEN f.q_th_w IS NOT NULL THEN m.q_th_w END AS meas_q,"
    "  CASE WHEN f.p_el_w IS NOT NULL THEN f.p_el_w_ref - m.p_el_w END AS ref_p,"
    "  CASE WHEN f.q_th_w IS NOT NULL THEN f.q_th_w_ref - m.q_th_w END AS ref_q,"
    "  CASE WHEN f.p_el_w_p90 > f.p_el_w_p10 AND m.p_el_w IS NOT NULL"
    "   THEN m.p_el_w BETWEEN f.p_el_w_p10 AND f.p_el_w_p90 END AS in_p,"
    "  CASE WHEN f.q_th_w_p90 > f.q_th_w_p10 AND m.q_th_w IS NOT NULL"
    "   THEN m.q_th_w BETWEEN f.q_th_w_p10 AND f.q_th_w_p90 END AS in_q";

// The scoring of forecast_skill's pairs (err_p, meas_p, …, in_q per day) in
// versions 8 to 11, both the UTC and the local day's (kMinScoredMinutes =
// 360).
inline const std::string kForecastSkillScoresV8ToV11 =
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

// forecast_skill of versions 8 to 10: each valid minute scored against the
// newest issue at or before 00:00 UTC of its day (kMinScoredMinutes = 360).
inline const std::string kForecastSkillV10 =
    "WITH pairs AS ("
    " SELECT m.ts - ((m.ts % 86400) + 86400) % 86400 AS day," +
    kForecastSkillPairsV8ToV11 +
    " FROM measurement_1min m CROSS JOIN forecast f ON f.ts = m.ts"
    "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
    "   AND g.issued_at <= m.ts - ((m.ts % 86400) + 86400) % 86400)"
    " WHERE m.valid IS NULL OR m.valid != 0)" +
    kForecastSkillScoresV8ToV11;

// forecast_skill's rows in day order: the store's view, and version 10's
// definition above on the same tables.
inline const std::string kForecastSkillRowsByDay = "SELECT * FROM forecast_skill ORDER BY day";
inline const std::string kForecastSkillV10RowsByDay = kForecastSkillV10 + " ORDER BY day";

// Removes version 11's tables and triggers (its forecast_skill view stays:
// the caller replaces or drops it).
inline std::vector<std::string> DropSchemaV11() {
  std::vector<std::string> sql;
  for (const char* table : {"measurement", "forecast"}) {
    for (const char* change : {"insert", "update", "delete"}) {
      sql.push_back(std::string("DROP TRIGGER forecast_skill_") + table + "_" + change);
    }
  }
  for (const char* table : {"forecast_skill_day", "forecast_skill_dirty", "forecast_skill_state"}) {
    sql.push_back(std::string("DROP TABLE ") + table);
  }
  return sql;
}

}  // namespace pvtwin::testing
