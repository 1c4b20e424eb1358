// The views of the central schema (io/fleet/upload.h describes them): the
// CREATE OR REPLACE VIEW statements, made from the tables and columns that
// exist centrally. SQL text only; io/fleet/upload.cc runs them.
#pragma once

#include <set>
#include <string>

namespace pvtwin {

// view plant_latest: per plant the newest 1-min row, forecast issue and
// accepted calibration, and the open alarms (NULL without qc_event).
std::string PlantLatestDdl(bool has_qc_event);

// view event(plant_id, ts, kind, severity, message): the store's event view
// (io/store/store.h) over every plant, from the tables in present.
std::string EventDdl(const std::set<std::string>& present);

// view forecast_skill(plant_id, day, ...): the store's forecast_skill over
// every plant, scoring each minute against its day-ahead issue in
// forecast_day_ahead (version 5). Columns that no plant's forecast has are
// NULL.
std::string ForecastSkillDdl(const std::set<std::string>& present,
                             const std::set<std::string>& forecast_columns);

}  // namespace pvtwin
