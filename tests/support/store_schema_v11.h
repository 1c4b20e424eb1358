// What store schema version 11 was, for tests that compare version 12 with
// it or take a store back to it: forecast_skill_local's query of versions 9
// to 11 (1-min rows only), written out as it was, and the statements that
// remove version 12's triggers. Version 11's forecast_skill returned what
// version 10's query (store_schema_v10.h) returns; both form and score their
// pairs alike (kForecastSkillPairsV8ToV11, kForecastSkillScoresV8ToV11).
#pragma once

#include <string>
#include <vector>

#include "tests/support/store_schema_v10.h"

namespace pvtwin::testing {

// forecast_skill_local of versions 9 to 11: each valid minute of a local
// day scored against the newest issue at or before its local midnight.
inline const std::string kForecastSkillLocalV11 =
    "WITH pairs AS ("
    " SELECT d.day AS day," +
    kForecastSkillPairsV8ToV11 +
    " FROM local_day d CROSS JOIN measurement_1min m ON m.ts >= d.start_ts"
    "  AND m.ts < d.end_ts"
    " CROSS JOIN forecast f ON f.ts = m.ts"
    "  AND f.issued_at = (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = m.ts"
    "   AND g.issued_at <= d.start_ts)"
    " WHERE m.valid IS NULL OR m.valid != 0)" +
    kForecastSkillScoresV8ToV11;

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
