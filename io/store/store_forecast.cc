// The store's calibrations and what follows from them: calibration rows and
// their parameters, forecasts, forecast skill and daily performance
// (io/store/store.h).
#include <sqlite3.h>

#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/forecast/forecast.h"
#include "io/store/store_impl.h"

namespace pvtwin {

using namespace store_detail;

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
            "SELECT h.name, h.run_at, h.value, h.std_error, c.window_start, c.window_end "
            "FROM parameter_history h JOIN calibration c ON c.id = h.calibration_id "
            "WHERE h.accepted = 1 AND h.run_at >= ? AND h.run_at < ? ORDER BY h.run_at",
            since_ts, std::numeric_limits<std::int64_t>::max(),
            [&points](sqlite3_stmt* stmt) {
              points[ColumnText(stmt, 0)].push_back(
                  {sqlite3_column_int64(stmt, 1), ColumnReal(stmt, 2), ColumnReal(stmt, 3),
                   sqlite3_column_int64(stmt, 4), sqlite3_column_int64(stmt, 5)});
            },
            "read parameter_history");
      },
      error);
  if (ok) *out = std::move(points);
  return ok;
}

bool Store::PruneForecasts(std::int64_t from_ts, std::int64_t to_ts, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "prune forecasts", [&] { return db.PruneForecasts(from_ts, to_ts); }, error);
}

DbStatus Store::Impl::PruneForecasts(std::int64_t from_ts, std::int64_t to_ts) {
  // A row survives if forecast_latest shows it or forecast_skill or
  // forecast_skill_local scores it (the local day of ts: the local_day row
  // with the latest start at or before it).
  sqlite3_stmt* stmt = nullptr;
  DbStatus s = Prepare(
      "DELETE FROM forecast WHERE ts >= ? AND ts < ?"
      " AND issued_at != (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = forecast.ts)"
      " AND issued_at IS NOT (SELECT MAX(g.issued_at) FROM forecast g WHERE g.ts = forecast.ts"
      "  AND g.issued_at <= forecast.ts - ((forecast.ts % 86400) + 86400) % 86400)"
      " AND issued_at IS NOT (SELECT MAX(g.issued_at) FROM local_day d CROSS JOIN forecast g"
      "  ON g.ts = forecast.ts AND g.issued_at <= d.start_ts"
      "  WHERE d.start_ts = (SELECT MAX(e.start_ts) FROM local_day e"
      "   WHERE e.start_ts <= forecast.ts) AND d.end_ts > forecast.ts)",
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
  return LatestAcceptedCalibrationBefore(std::numeric_limits<std::int64_t>::max(), row, found,
                                         error);
}

bool Store::LatestAcceptedCalibrationBefore(std::int64_t window_end_max, CalibrationRow* row,
                                            bool* found, std::string* error) {
  return ReadAcceptedCalibration("window_end <= ?", window_end_max, row, found, error);
}

bool Store::AcceptedCalibrationById(std::int64_t id, CalibrationRow* row, bool* found,
                                    std::string* error) {
  return ReadAcceptedCalibration("id = ?", id, row, found, error);
}

bool Store::ReadAcceptedCalibration(const char* condition, std::int64_t value, CalibrationRow* row,
                                    bool* found, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  CalibrationRow result;
  bool any = false;
  const bool ok = db.Run(
      false, "read accepted calibration",
      [&]() -> DbStatus {
        any = false;
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "SELECT id, run_at, variant, window_start, window_end, status, mae_p_el_w, "
            "mae_q_th_w, runtime_s, n_evals, params_json, reason, heldout_mae_w, accepted "
            "FROM calibration WHERE accepted != 0 AND " +
                std::string(condition) + " ORDER BY run_at DESC, id DESC LIMIT 1",
            &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_int64(stmt, 1, value);
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
  return InsertForecast(issued_at, calibration_id, ForecastBasis::kCalibrated, inputs, rows, error);
}

bool Store::InsertForecast(std::int64_t issued_at, std::int64_t calibration_id, ForecastBasis basis,
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
            "p_el_w_ref, q_th_w_ref, p_el_w_p50, q_th_w_p50, basis) "
            "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
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
          sqlite3_bind_text(stmt, column++, ForecastBasisName(basis), -1, SQLITE_STATIC);
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

}  // namespace pvtwin
