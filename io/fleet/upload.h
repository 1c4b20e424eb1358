// Replication of the plant's SQLite store into a central PostgreSQL (the
// fleet contract of doc/contracts.md). The SQLite file stays the source of truth;
// the central database holds the same tables with a leading plant_id.
//
// Which rows to send (local side, created by Uploader::Open, idempotent):
//   upload_queue(seq INTEGER PRIMARY KEY AUTOINCREMENT, table_name, k1, k2)
//       one row per local row not yet uploaded, keyed by the table's key
//       columns (k2 = '' for one-column keys). Triggers on INSERT and
//       UPDATE of every uploaded table delete the key's old entry and add a
//       new one, so a row that changes after it was sent (a minute
//       re-aggregated after a restart, a calibration's status) is queued
//       again with a higher seq. Rows present when the triggers were made
//       are queued at that moment, in the same transaction.
//   upload_state(table_name PRIMARY KEY, hwm, rows_uploaded, last_upload_at)
//       the high-water mark: every queue entry with seq <= hwm is in the
//       central database. It is raised, and those entries deleted, only
//       after the PostgreSQL COMMIT of the batch; a crash in between sends
//       the batch again, which the upserts make harmless.
//   upload_connection(id = 1, state, since, last_success, last_error,
//                     last_error_at, server)
//       the uploader's state (starting, connected, down, auth_failed,
//       refused), written on every change of state and success.
//   view upload_status(table_name, state, since, last_success, last_error,
//                      last_error_at, rows_uploaded, rows_pending, hwm)
//       one row per uploaded table, for the operator.
//
// Central side (Uploader::Connect creates or migrates it when anything is
// missing, under an advisory lock, so a role without CREATE can upload into
// a schema made by `pvtwin upload --init`):
//   pvtwin_schema(version, applied_at): version kCentralSchemaVersion.
//   plant(plant_id PRIMARY KEY, first_upload_at, last_upload_at, store_id)
//       store_id (version 2) is the store_identity of the SQLite store that
//       uploads as this plant_id: the first store to upload binds it, and a
//       second store under the same plant_id (a config copied to another
//       site) is refused with both ids named, unless UploadSettings::takeover
//       (`pvtwin upload --takeover`: the plant moved to new hardware).
//   <table>(plant_id TEXT, <the local table's columns, same names>,
//           PRIMARY KEY(plant_id, <central key>)) for every table of
//       UploadTables() that the local store has; SQLite INTEGER → bigint,
//       REAL → double precision, TEXT → text. Columns the local store gains
//       later are added (ALTER TABLE ... ADD COLUMN IF NOT EXISTS).
//       forecast is keyed (plant_id, ts): only the newest issue of each ts
//       is kept, and rows older than [upload] forecast_days before the
//       plant's newest issue are deleted.
//   forecast_day_ahead (version 5): the columns and key of forecast,
//       holding per ts the newest issue made at or before 00:00 UTC of ts's
//       UTC day (the day-ahead issue the store's forecast_skill scores).
//       Every batch of forecast rows upserts its qualifying rows there too,
//       replacing a row only by one at least as new, so that the order of
//       arrival does not matter; pruned as forecast is. The local queue keeps,
//       per ts, the entry of the newest qualifying issue besides the newest
//       one, so that an hourly re-issue does not drop the day-ahead row
//       before it was sent. Made from forecast's rows when it is created.
//   view plant_latest(plant_id, last_upload_at, measurement_ts, p_el_w,
//       q_th_w, t_in_c, t_out_c, g_poa_w_m2, t_amb_c, forecast_issued_at,
//       calibration_id, calibration_run_at, calibration_variant,
//       open_alarms): per plant the newest 1-min row, the newest forecast
//       issue, the newest accepted calibration and the qc_event rows without
//       end_ts (NULL when no plant uploads qc_event).
//   view event(plant_id, ts, kind, severity, message) (version 3): the
//       store's event view over every plant (monitor_event, qc_event,
//       calibration, diagnosis, as far as they exist centrally).
//   view forecast_skill(plant_id, day, mae_p_el_w, mae_q_th_w, nmae_p_el,
//       nmae_q_th, skill_p_el, skill_q_th, coverage_p10_p90, minutes,
//       coverage_p_el, coverage_q_th) (version 4): the store's forecast_skill
//       per plant and UTC day, with the same columns and rules; from
//       version 5 on over forecast_day_ahead, so that it equals the store's
//       for the days whose forecasts are kept centrally.
// A session advisory lock per plant_id lets one uploader at a time send a
// plant's rows (a second one, or two plants configured with one plant_id,
// is refused with a message).
//
// Once the central schema exists, a missing uploaded table is created only
// if this plant never uploaded into it: a table that held the plant's rows
// and is gone (renamed or dropped by someone) is an error naming the rows
// uploaded and queued, never silently re-created empty; `--resend`
// (UploadSettings::resend) queues every local row again. A central table
// without its key columns is an error too.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "io/fleet/pg_client.h"

namespace pvtwin {

inline constexpr int kCentralSchemaVersion = 5;

// One uploaded table. Adding a table of the store to the fleet is one entry
// of UploadTables().
struct UploadTable {
  std::string_view name;
  std::vector<std::string_view> local_key;    // identifies a local row (1 or 2 columns)
  std::vector<std::string_view> central_key;  // after plant_id
  // When set: a central row is only replaced by a row at least as new in
  // this column, only the locally newest row per central key is sent, and
  // rows of keep_column older than forecast_days before the newest value
  // of this column are neither sent nor kept centrally. Then local_key is
  // {central key column, newest_column}, so that the queue holds one entry
  // per central row.
  std::string_view newest_column;
  std::string_view keep_column;
  // When set (with newest_column): a second central table of the same
  // columns and key that keeps, per central key, the newest row whose
  // newest_column is at or before 00:00 UTC of keep_column's UTC day (a
  // day-ahead forecast), which the table itself loses to later issues.
  std::string_view day_ahead_table;
};
const std::vector<UploadTable>& UploadTables();

struct UploadSettings {
  std::string store_path;     // the plant's SQLite file
  std::string url;            // libpq connection string without password
  std::string password_file;  // optional (config/plant_config.h UploadConfig)
  std::string plant_id;
  int batch_rows = 5000;
  int forecast_days = 7;
  // Set by a signal handler or the daemon's stop: every wait on the server
  // ends at once (io/fleet/pg_client.h PgWait); the rows stay queued.
  const std::atomic<bool>* stop = nullptr;
  // Bind plant_id centrally to this store even if another store holds it.
  bool takeover = false;
  // Queue every local row again (after a central table was lost).
  bool resend = false;
  // Called after each central COMMIT, before the high-water mark moves: the
  // moment a crash must lose and duplicate nothing (the tests end the
  // process there). Unset in the product.
  std::function<void()> after_central_commit;
};

enum class UploadState { kStarting, kConnected, kDown, kAuthFailed, kRefused };
std::string_view UploadStateName(UploadState state);
// The state a fault leads to.
UploadState StateForFault(PgFault fault);

struct TablePending {
  std::string table;
  std::int64_t rows = 0;
};

class Uploader {
 public:
  // Opens the store's file (its own connection) and creates the local
  // tables and triggers above. Null with *error when that fails.
  static std::unique_ptr<Uploader> Open(const UploadSettings& settings, std::string* error);
  ~Uploader();
  Uploader(const Uploader&) = delete;
  Uploader& operator=(const Uploader&) = delete;

  // Connects and makes sure the central schema is complete. The password:
  // password_file, else $CREDENTIALS_DIRECTORY/pgpassword, else libpq's own.
  bool Connect(PgError* error);
  bool connected() const;
  void Disconnect();
  std::string server() const;  // of the last connection, for log lines

  // Rows waiting in the queue, per uploaded table.
  bool Pending(std::vector<TablePending>* out, std::string* error);

  // Sends one batch (at most batch_rows queue entries) of every table that
  // has rows waiting. *rows gets the queue entries settled; *more whether
  // some are left. On a fault the connection is dropped.
  bool UploadBatches(std::int64_t* rows, bool* more, PgError* error);

  // Records the state (and last_success when success) in upload_connection.
  void RecordState(UploadState state, const std::string& last_error, bool success);

 private:
  struct Impl;
  explicit Uploader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Reads the password as Connect does; "" when libpq should find it. False
// with *error when password_file is set but unreadable.
bool ReadUploadPassword(const std::string& password_file, std::string* password,
                        std::string* error);

}  // namespace pvtwin
