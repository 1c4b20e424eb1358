// The store's monitoring rows: monitor events, sensor faults (qc_event) and
// gap diagnoses (io/store/store.h).
#include <sqlite3.h>

#include <string>
#include <vector>

#include "io/store/store_impl.h"

namespace pvtwin {

using namespace store_detail;

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

bool Store::LatestMonitorEventSeverity(const std::string& kind, const std::string& message_prefix,
                                       std::string* severity, bool* found, std::string* error) {
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
            "SELECT severity FROM monitor_event WHERE kind = ? AND (? = '' OR instr(message, ?) = "
            "1) "
            "ORDER BY ts DESC, id DESC LIMIT 1",
            &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_text(stmt, 1, kind.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(stmt, 2, message_prefix.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(stmt, 3, message_prefix.c_str(), -1, SQLITE_TRANSIENT);
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

}  // namespace pvtwin
