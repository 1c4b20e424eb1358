// The SQLite store of the daemon: raw 5 s samples, 1-min measurements,
// calibration runs and forecasts. SQL is pvtwin's user interface, so the
// schema below is a contract (doc/contracts.md "SQLite"): extend it, never rename.
//
// Schema (version 1, PRAGMA user_version = 1):
//   sample_5s(ts INTEGER PRIMARY KEY, <channel> REAL ..., rejected_mask INTEGER)
//       one row per poll period; <channel> is every canonical channel of
//       core/channels.h kChannels, in that order, named as there. A missing
//       or rejected reading is NULL; bit c of rejected_mask is set when
//       channel c was read but failed the poller's checks (core/sample.h).
//   measurement_1min(ts INTEGER PRIMARY KEY, <channel> REAL ...,
//                    n_samples INTEGER, qc_flags INTEGER)
//       one row per minute with samples: means of the valid samples after the
//       paper's corrections (core/aggregate.h, which also lists the qc_flags
//       bits). n_samples is NULL for rows imported from a 1-min CSV
//       (qc_flags has kQcImported).
//   calibration(id INTEGER PRIMARY KEY, run_at INTEGER, variant TEXT,
//               window_start INTEGER, window_end INTEGER, status TEXT,
//               mae_p_el_w REAL, mae_q_th_w REAL, runtime_s REAL,
//               n_evals INTEGER, params_json TEXT,
//               reason TEXT, heldout_mae_w REAL, accepted INTEGER)
//       every calibration attempt; reason says why it was (not) accepted,
//       heldout_mae_w is MAE(P_el) + MAE(Q_u) on the held-out day(s),
//       accepted is 0/1.
//   forecast(issued_at INTEGER, ts INTEGER, calibration_id INTEGER,
//            p_el_w REAL, q_th_w REAL, t_pv_c REAL, t_out_c REAL,
//            inputs TEXT, PRIMARY KEY(issued_at, ts))
//       inputs names what the forecast was driven by (e.g.
//       "weather=weather_forecast;operation=operation_plan").
//   view forecast_latest(ts, issued_at, p_el_w, q_th_w, t_pv_c, t_out_c)
//       for each ts, the row of the newest forecast (largest issued_at).
//   view forecast_skill(day, mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th)
//       per UTC day (day = unix seconds of 00:00 UTC), a day-ahead skill:
//       each minute ts of the day is scored with the newest forecast issued
//       at or before the start of that day (so only forecasts that were real
//       forecasts for the whole day count), against the measurement_1min row
//       at the same ts with valid not 0. MAE = mean |forecast − measured|
//       over the minutes where both are known; nMAE = MAE / mean |measured|
//       over the same minutes (paper 3.2.2, as core/identification.h).
//       Days without such forecasts and measurements have no row.
//   weather_forecast(ts INTEGER PRIMARY KEY, g_poa_w_m2, ghi_w_m2, dhi_w_m2,
//                    g_poa_diffuse_w_m2, t_amb_c, wind_m_s, t_sky_c,
//                    lw_down_w_m2 REAL)
//   operation_plan(ts INTEGER PRIMARY KEY, t_in_c REAL, flow_kg_s REAL)
//       forecast inputs: weather_forecast is filled by `pvtwin
//       import-weather`, the daemon's fetch ([forecast] weather_url) or
//       outside programs by SQL; operation_plan by outside programs. A NULL
//       is a missing value.
//
// Version 2 adds:
//   measurement_interval(ts INTEGER PRIMARY KEY, step_s INTEGER,
//                        <channel> REAL ..., qc_flags INTEGER)
//       rows imported at their own step when that step is a whole number of
//       minutes above one (2-, 10-, 15-min logger data): the values stand for
//       the interval [ts, ts + step_s) as the logger gave them. They are not
//       split into 1-min rows, which would invent what happened inside the
//       interval. A window without 1-min rows is read from here at the rows'
//       step (daemon/service/window_data.h).
//
// Version 3 adds:
//   calibration_param(calibration_id INTEGER, name TEXT, value REAL,
//                     std_error REAL, unit TEXT, status TEXT,
//                     PRIMARY KEY(calibration_id, name))
//       every parameter of every calibration that produced parameters
//       (accepted or not): value and standard error in the parameter's unit
//       (std_error NULL when not estimated: fixed, undetermined), status as
//       `pvtwin calibrate` prints it.
//   view parameter_history(run_at, calibration_id, accepted, name, value,
//                          std_error, unit, status)
//       calibration_param with its calibration's time and acceptance.
//
// Version 4 adds (core/monitoring.h says how each is computed):
//   performance_daily(day INTEGER PRIMARY KEY, e_el_meas_wh, e_el_model_wh,
//                     e_th_meas_wh, e_th_model_wh, pi_el, pi_th, pi_el_low,
//                     pi_el_high, pi_th_low, pi_th_high REAL,
//                     valid_minutes INTEGER, calibration_id INTEGER)
//       per UTC day (as forecast_skill), measured and expected energies in
//       Wh; pi NULL when the day is not scored for that output.
//   qc_event(id, channel, start_ts, end_ts, kind, detail)
//       sensor faults as intervals [start_ts, end_ts).
//   monitor_event(id, ts, kind, severity, message)
//       what the daemon found: parameter drift, performance alarms, device
//       outages.
//   diagnosis(id, run_at, calibration_id, window_start, window_end,
//             base_variant, verdict, low_confidence, shrink_pct,
//             bias_p_el_w, bias_q_th_w, report_json)
//   view measurement_qc(ts, few_samples, required_missing, ...,
//                       missing_<channel> ...)
//       measurement_1min's qc_flags as one 0/1 column per flag.
//   view event(ts, kind, severity, message)
//       newest first: monitor_event, qc_event, every calibration (accepted:
//       info, otherwise warning) and every diagnosis.
//
// Version 5 adds:
//   weather_forecast.source TEXT
//       where the row came from: "import-weather <file> (<format>)" or
//       "fetch <url> (<format>)"; NULL for rows other programs wrote.
//       import-weather and the daemon's fetch write 1-min rows, each fetch
//       or import replacing the rows of its minutes (io/weather/weather_file.h,
//       core/forecast/weather_resample.h).
//   plant_config(key TEXT PRIMARY KEY, value REAL)
//       the [plant] keys of the config the daemon (or import-weather
//       --config) last ran with, in the config's units (degrees), so that a
//       command given only the store knows the site.
//
// Version 6 adds (issue 15, core/forecast/forecast_bands.h):
//   forecast.p_el_w_p10, p_el_w_p90, q_th_w_p10, q_th_w_p90 REAL
//       the 10–90 % band of each output: empirical quantiles of the
//       replayed day-ahead errors of the window by regime and weather
//       source; NULL where no band could be made.
//   forecast.p_el_w_ref, q_th_w_ref REAL
//       the reference forecast issued with it: smart persistence of the
//       weather with the typical day's operation (core/forecast/forecast.h).
//   view forecast_latest gains p_el_w_p10, p_el_w_p90, q_th_w_p10, q_th_w_p90.
//   view forecast_skill gains skill_p_el, skill_q_th = 1 − MAE / MAE of the
//       reference over the minutes where both are known; coverage_p10_p90 =
//       the share of measured values inside their band, over both outputs'
//       minutes whose band has a width (p90 > p10); minutes = the day's
//       scored minutes. skill and coverage are NULL on days with fewer than
//       kMinScoredMinutes (core/forecast/forecast.h) scored minutes (and where the reference is
//       exact).
//
// Version 7 adds:
//   store_identity(id = 1, store_id TEXT, created_at INTEGER)
//       a random 128-bit id (32 hex digits) made once, when the store is
//       created or migrated to version 7. The fleet upload sends it with
//       plant_id, so that a second store under the same plant_id is refused
//       centrally (io/fleet/upload.h). A copy of the file keeps the id: a store
//       copied to another site must not upload under the original's
//       plant_id.
//
// Version 8 adds (issue 53, core/forecast/forecast_bands.h):
//   forecast.p_el_w_p50, q_th_w_p50 REAL
//       the median of each output: the forecast (the model's run on the
//       expected inputs) plus the median of its held-out errors in the
//       row's regime, within the band. The band now always holds the
//       forecast: p10 ≤ p_el_w ≤ p90 (and q_th_w alike).
//   view forecast_latest gains p_el_w_p50, q_th_w_p50.
//   view forecast_skill gains coverage_p_el, coverage_q_th: the band's
//       coverage of each output alone (coverage_p10_p90 pools both).
//
// Version 9 adds (issue 54; doc/sql.md "Local days"):
//   local_day(day TEXT PRIMARY KEY, start_ts INTEGER, end_ts INTEGER)
//       the civil days of StoreOptions::time_zone ([calibration] timezone,
//       UTC for a store that was never given one):
//       day the local date 'YYYY-MM-DD', [start_ts, end_ts) its UTC
//       seconds from one local midnight to the next (86400 s, or 82800 /
//       90000 on the days daylight saving time begins / ends). The store
//       writes the days from the first to the last measurement (1-min and
//       interval rows) and two days ahead, when it writes measurements and
//       at Open; a store opened with another zone than the one its rows
//       were made in (local_day_zone) makes them again, one opened without
//       a zone keeps them.
//   local_day_zone(id = 1, zone TEXT)
//       the zone local_day was made in.
//   view forecast_skill_local(day, <the columns of forecast_skill after day>)
//       forecast_skill per local day: day the local date (TEXT), each minute
//       scored with the newest forecast issued at or before the local
//       midnight that starts its day.
//   view performance_daily_local(day, e_el_meas_wh, e_el_model_wh,
//                                e_th_meas_wh, e_th_model_wh, pi_el, pi_th,
//                                valid_minutes)
//       per local day: measured energies summed from measurement_1min (valid
//       not 0); model energies apportioned from the performance_daily rows
//       of the UTC days the local day overlaps, each by the share of that
//       UTC day's in-plane irradiation (g_poa_w_m2 above 0) measured within
//       the local day (by its share of minutes when the UTC day has none);
//       pi = measured / model when every such UTC day is scored for the
//       output and the model energy is not 0, else NULL.
//
// Version 10 adds (issue 53, day one; core/forecast/start_value_forecast.h):
//   forecast.basis TEXT NOT NULL DEFAULT 'calibrated'
//       'calibrated' (the accepted calibration's parameters; every row
//       written before) or 'start_values' (a plant without an accepted
//       calibration: Table 3's start values, calibration_id NULL, the band
//       the start-value envelope).
//   view forecast_latest gains basis.
//   view event leaves out the calibrations skipped before the first
//       accepted one (a new plant waiting for its two days of history);
//       the daemon marks that wait with one monitor_event of kind
//       calibration_waiting, severity info.
//
// Version 11 adds (forecast_skill materialised per day; doc/sql.md):
//   forecast_skill_day(day INTEGER PRIMARY KEY, <the columns of
//                      forecast_skill after day>)
//       forecast_skill's rows of closed UTC days, written by
//       RefreshForecastSkill (store_skill.cc) and by the migration for the
//       days before the current one.
//   forecast_skill_dirty(day INTEGER PRIMARY KEY)
//       materialised days changed since: triggers on measurement_1min
//       (insert, update, delete) and on forecast (an issue the day scores,
//       or scored, inserted, updated or deleted) mark them.
//   forecast_skill_state(id = 1, done_before INTEGER)
//       the 00:00 UTC of the first day not materialised.
//   view forecast_skill keeps its columns and values: the materialised rows
//       of clean days, and computed from the measurements only the days from
//       done_before on and the dirty ones.
//
// Version 12 adds (issue 53 item 5: forecasts from interval history scored;
// doc/sql.md):
//   view forecast_skill and forecast_skill_local score a day that has no
//       measurement_1min row (valid or not) from its measurement_interval
//       rows, each weighted by its step (step_s / 60 minutes) in MAE, nMAE,
//       skill and coverage, so that minutes stays minutes (an integer where
//       the steps sum to whole minutes); a day with 1-min rows keeps the
//       values of version 11. The columns are those of version 8.
//   triggers forecast_skill_interval_{insert,update,delete} on
//       measurement_interval mark a materialised day without 1-min rows
//       dirty. The migration materialises the closed days only interval
//       rows score.
//
// Units and time: every time is unix seconds UTC (INTEGER) and marks the
// start of the row's interval (5 s, 1 min); powers in W, temperatures in °C,
// irradiance in W/m², flow in kg/s, wind in m/s. The column aoi_deg holds
// degrees, as its name says (core's Sample and Series hold radians; the store
// converts).
//
// WAL and crash behaviour: the database runs in WAL mode, so readers (a
// dashboard, the sqlite3 shell holding a read transaction) never block the
// writer and the writer never blocks them; a reader only keeps the WAL from
// being checkpointed past its snapshot. synchronous = NORMAL: in WAL mode a
// commit is not fsync'ed, the WAL is synced at checkpoints. The database
// stays consistent after a crash of the process or of the machine; a crash
// of the process loses nothing committed, a power cut may lose the last
// transactions committed before it (seconds of samples), which a 5 s logger
// can afford and which spares the flash storage of a plant controller an
// fsync every 5 s. Writes run in BEGIN IMMEDIATE transactions with prepared
// statements; SQLITE_BUSY (another writer, e.g. a program filling
// weather_forecast) is waited for by busy_timeout and the whole transaction
// is retried StoreOptions::busy_retries times; then the call returns false
// with the reason and the database is unchanged and readable. No call aborts
// on a database error.
//
// Retention: ApplyRetention deletes sample_5s rows older than
// raw_retention_days (config [storage]), after aggregating any of their
// minutes that have no measurement_1min row yet. 1-min rows and calibrations
// are kept. Of the forecast rows older than that, only the (up to three)
// that the views use are kept for each ts (the newest issue, shown by
// forecast_latest, the newest issue before the UTC day began, scored by
// forecast_skill, and the newest issue before the local day began, scored
// by forecast_skill_local): hourly 24 h forecasts would otherwise add 1440
// rows per hour (about 3 MiB a day, pvtwin-bench store), and the views
// return the same rows before and after pruning. The issues forecast_skill
// scores stay after their day is materialised (a late import makes the day
// dirty, and it is scored again from them); pruning an issue no day scores
// marks nothing dirty.
//
// Threads: one Store is one connection, guarded by a mutex; another thread
// (the calibration worker) may share it or, better for long reads, open its
// own Store on the same file.
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/common/sample.h"
#include "core/common/series.h"
#include "core/data/aggregate.h"
#include "core/monitor/monitoring.h"
#include "io/platform/log.h"

namespace pvtwin {

inline constexpr int kStoreSchemaVersion = 12;
// NULL in a row struct.
inline constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

// What a forecast issue's parameters are (forecast.basis, version 10): an
// accepted calibration's, or the start values of a plant without one
// (core/forecast/start_value_forecast.h).
enum class ForecastBasis { kCalibrated, kStartValues };
inline const char* ForecastBasisName(ForecastBasis basis) {
  return basis == ForecastBasis::kStartValues ? "start_values" : "calibrated";
}

struct StoreOptions {
  // SQLite waits busy_timeout_ms for a lock, per attempt; the whole
  // transaction is retried busy_retries times. The defaults give up after
  // about 3 s, within a 5 s poll period: the daemon keeps the batch and
  // tries again with the next one.
  int busy_timeout_ms = 1000;
  int busy_retries = 2;
  // How AggregateMinutes averages: poll period and fluid c_p (plant config).
  AggregateOptions aggregate;
  // The IANA zone of the local days (local_day and the *_local views):
  // [calibration] timezone. Empty: the zone the store's local days were
  // made in, UTC for a new store (a caller that does not know the config
  // leaves them as they are). "UTC" is reckoned without the process's zone;
  // any other zone becomes the process's TZ when it is not already
  // (io/platform/local_time.h LocalDaysOverlapping). Open refuses a zone the
  // tz database does not have.
  std::string time_zone;
  // Where Open says that it migrates an existing store (one kNotice line,
  // "<db>: migrating store schema <old> → <new> (backup: <db>.schema-v<old>.bak)"):
  // the daemon's log on stderr unless the caller says otherwise; empty:
  // silent (Store::upgrade() tells the same).
  LogFn log = LogToStderr;
};

class Store {
 public:
  // One identified parameter of a calibration (calibration_param).
  struct CalibrationParamRow {
    std::string name;
    double value = 0.0;
    double std_error = 0.0;  // in the parameter's unit; NaN (NULL) when not estimated
    std::string unit;
    std::string status;  // as calibrate prints it: identified, fixed, at lower bound, ...
  };

  struct CalibrationRow {
    std::int64_t id = 0, run_at = 0;
    std::string variant;
    std::int64_t window_start = 0, window_end = 0;
    std::string status;
    double mae_p_el_w = 0.0, mae_q_th_w = 0.0, runtime_s = 0.0;  // NaN is stored as NULL
    long n_evals = 0;
    std::string params_json;
    std::string reason;
    bool accepted = false;
    double heldout_mae_w = 0.0;
    std::vector<CalibrationParamRow> params;  // written to calibration_param with the row
  };

  struct ForecastRow {
    std::int64_t ts = 0;
    double p_el_w = 0.0, q_th_w = 0.0, t_pv_c = 0.0, t_out_c = 0.0;
    // The 10–90 % band and the reference forecast (version 6); NaN: NULL.
    double p_el_w_p10 = kNoValue, p_el_w_p90 = kNoValue, q_th_w_p10 = kNoValue,
           q_th_w_p90 = kNoValue;
    double p_el_w_ref = kNoValue, q_th_w_ref = kNoValue;  // written, not read back
    // The median of each output (version 8), within the band; NaN: NULL.
    double p_el_w_p50 = kNoValue, q_th_w_p50 = kNoValue;
  };

  // One row of the forecast_skill view (NaN: NULL).
  struct SkillRow {
    std::int64_t day = 0;  // unix s of 00:00 UTC
    double mae_p_el_w = 0.0, mae_q_th_w = 0.0, nmae_p_el = 0.0, nmae_q_th = 0.0;
    double skill_p_el = kNoValue, skill_q_th = kNoValue, coverage_p10_p90 = kNoValue;
    std::int64_t minutes = 0;
    double coverage_p_el = kNoValue, coverage_q_th = kNoValue;  // version 8
  };

  // What Open did to the schema of an existing store.
  struct SchemaUpgrade {
    int from_version = 0;  // 0: nothing migrated (a new or a current store)
    int to_version = 0;
    std::string backup_path;  // the copy made before migrating
  };

  // Opens (creating if needed) and migrates the database at path. Before it
  // migrates an existing store (user_version 1 … kStoreSchemaVersion − 1,
  // not at creation) it copies it with SQLite's online backup to
  // "<path>.schema-v<old>.bak" (".schema-v<old>.<n>.bak" when that file
  // exists already, never overwriting one) and logs one line through
  // options.log; no backup, no migration. Returns null and sets *error when
  // it cannot be opened, is not a pvtwin database of a known version, the
  // backup or the migration fails.
  static std::unique_ptr<Store> Open(const std::string& path, std::string* error);
  static std::unique_ptr<Store> Open(const std::string& path, const StoreOptions& options,
                                     std::string* error);
  // Opens an existing store for reading only (export, diagnose --db): never
  // creates, migrates or writes it, and needs no write access. SQLite's
  // `mode=ro`, which reads a live WAL store (the daemon running) with read
  // access to the file, -wal and -shm; when those cannot be opened and no
  // -wal or -shm file exists (no connection has the store open),
  // `immutable=1`. Refuses, with what to do, a store of an older schema
  // (the daemon or `pvtwin migrate` upgrades it), a newer one, a damaged
  // file or one that is not a pvtwin store. The write calls of a store
  // opened so fail.
  static std::unique_ptr<Store> OpenReadOnly(const std::string& path, const StoreOptions& options,
                                             std::string* error);
  ~Store();
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  const std::string& path() const;
  // What Open's migration did (from_version 0 when it migrated nothing).
  const SchemaUpgrade& upgrade() const;

  // Copies the database, as this connection sees it, into a new file at
  // target_path with SQLite's online backup (the rescue of a store whose
  // file was deleted while it was open).
  bool BackupTo(const std::string& target_path, std::string* error);

  // Upserts the batch into sample_5s in one transaction (a sample whose ts is
  // already stored replaces it).
  bool InsertSamples(const std::vector<Sample>& batch, std::string* error);
  // Samples with from_ts <= ts < to_ts, in time order.
  bool ReadSamples(std::int64_t from_ts, std::int64_t to_ts, std::vector<Sample>* out,
                   std::string* error);

  // Aggregates every complete minute (minute start + 60 <= up_to_ts) that has
  // samples and no measurement_1min row yet, in one transaction. A minute is
  // written once: a minute whose samples were partly stored before a crash
  // is aggregated, completely, on the first call after restart. The caller
  // passes the end of the newest poll period it has stored (last ts +
  // period), so a minute still being polled is left for a later call.
  bool AggregateMinutes(std::int64_t up_to_ts, int* minutes_written, std::string* error);
  // Re-computes (replaces) the row of every minute in [from_ts, to_ts) that
  // has samples, e.g. after importing samples into minutes already stored.
  bool ReaggregateMinutes(std::int64_t from_ts, std::int64_t to_ts, int* minutes_written,
                          std::string* error);
  // Upserts 1-min rows (import of a 1-min CSV): channels of the series, NULL
  // for the absent ones, n_samples NULL, qc_flags kQcImported.
  bool WriteMinutes(const Series& rows_1min, std::string* error);
  // Rows with from_ts <= ts < to_ts as a canonical Series (step_s = 60); a
  // channel that is NULL in every row is left absent.
  bool ReadMinutes(std::int64_t from_ts, std::int64_t to_ts, Series* out, std::string* error);
  // As ReadMinutes, plus n_samples (0 where NULL) and qc_flags per row.
  bool ReadMinuteRows(std::int64_t from_ts, std::int64_t to_ts, MinuteRows* out,
                      std::string* error);
  // --- Monitoring (schema version 4, core/monitoring.h) ---
  // Upserts the performance_daily row of day.day_start_s.
  bool WritePerformanceDay(const DayPerformance& day, std::int64_t calibration_id,
                           std::string* error);
  // performance_daily rows with from_ts <= day < to_ts, in time order; a day
  // is scored for an output when its pi is not NULL.
  bool ReadPerformanceDays(std::int64_t from_ts, std::int64_t to_ts,
                           std::vector<DayPerformance>* out, std::string* error);
  // qc_event rows: a fault already recorded with the same channel, kind and
  // start gets its (longer) end and detail; others are inserted.
  bool RecordSensorFaults(const std::vector<SensorFault>& faults, std::string* error);
  // A monitor_event row (drift, alarm, device outage; severity info,
  // warning or error).
  bool InsertMonitorEvent(std::int64_t ts, const std::string& kind, const std::string& severity,
                          const std::string& message, std::string* error);
  // The newest monitor_event of kind whose message starts with
  // message_prefix ("" for any): its severity; *found false when none.
  bool LatestMonitorEventSeverity(const std::string& kind, const std::string& message_prefix,
                                  std::string* severity, bool* found, std::string* error);
  // Parameters of the accepted calibrations with run_at >= since_ts, per
  // name, in time order, with their calibration's window (0, 0 when NULL).
  bool ReadAcceptedParameters(std::int64_t since_ts,
                              std::map<std::string, std::vector<ParameterPoint>>* out,
                              std::string* error);
  struct DiagnosisRow {
    std::int64_t id = 0, run_at = 0, calibration_id = 0;  // calibration_id 0: NULL
    std::int64_t window_start = 0, window_end = 0;
    std::string base_variant, verdict;
    bool low_confidence = false;
    double shrink_pct = 0.0, bias_p_el_w = 0.0, bias_q_th_w = 0.0;  // NaN: NULL
    std::string report_json;
  };
  bool InsertDiagnosis(DiagnosisRow* row, std::string* error);
  // The newest diagnosis row (largest run_at) without its report_json;
  // *found false when there is none.
  bool LatestDiagnosis(DiagnosisRow* row, bool* found, std::string* error);

  // Upserts rows of a coarser step (measurement_interval): every row's ts a
  // whole minute, step_s = rows.step_s (a whole number of minutes > 1),
  // qc_flags kQcImported plus the missing-channel bits as WriteMinutes.
  bool WriteIntervalRows(const Series& rows, std::string* error);
  // measurement_interval rows with from_ts <= ts < to_ts; step_s of the
  // series is the most common step_s among them (60 when there are none).
  bool ReadIntervalRows(std::int64_t from_ts, std::int64_t to_ts, Series* out, std::string* error);

  // Deletes sample_5s rows with ts < cut = now_ts − raw_retention_days·86400
  // (after aggregating their minutes that have no 1-min row), and prunes the
  // forecasts of [cut − 7 days, cut) (meant to run daily).
  bool ApplyRetention(std::int64_t now_ts, int raw_retention_days, std::string* error);
  // Deletes the forecast rows with from_ts <= ts < to_ts that neither
  // forecast_latest, forecast_skill nor forecast_skill_local uses.
  bool PruneForecasts(std::int64_t from_ts, std::int64_t to_ts, std::string* error);

  bool InsertCalibration(CalibrationRow* row, std::string* error);  // sets row->id
  // Replaces the parameters of calibration id (params_json and its
  // calibration_param rows) and appends reason_note to its reason: the
  // daemon's refit on the whole window after the held-out check.
  bool UpdateCalibrationParams(std::int64_t id, const std::string& params_json,
                               const std::vector<CalibrationParamRow>& params,
                               const std::string& reason_note, std::string* error);
  bool LatestAcceptedCalibration(CalibrationRow* row, bool* found, std::string* error);
  // The newest accepted calibration whose window ended at or before
  // window_end_max: the model of the plant before a change (NightlyDiagnosis).
  bool LatestAcceptedCalibrationBefore(std::int64_t window_end_max, CalibrationRow* row,
                                       bool* found, std::string* error);
  // Calibration `id` when it was accepted (*found false otherwise).
  bool AcceptedCalibrationById(std::int64_t id, CalibrationRow* row, bool* found,
                               std::string* error);

  // Upserts one forecast issue (all rows in one transaction); without a
  // basis, a calibrated one. calibration_id 0: NULL.
  bool InsertForecast(std::int64_t issued_at, std::int64_t calibration_id,
                      const std::string& inputs, const std::vector<ForecastRow>& rows,
                      std::string* error);
  bool InsertForecast(std::int64_t issued_at, std::int64_t calibration_id, ForecastBasis basis,
                      const std::string& inputs, const std::vector<ForecastRow>& rows,
                      std::string* error);

  // forecast_latest rows with from_ts <= ts < to_ts, in time order.
  bool ReadLatestForecast(std::int64_t from_ts, std::int64_t to_ts, std::vector<ForecastRow>* out,
                          std::string* error);
  // forecast_skill rows with from_day <= day < to_day (unix s of 00:00 UTC).
  bool ReadForecastSkill(std::int64_t from_day, std::int64_t to_day, std::vector<SkillRow>* out,
                         std::string* error);

  // Materialises forecast_skill (schema version 11) in forecast_skill_day
  // for every UTC day before the one of now_ts that is not materialised yet
  // or is dirty (its measurements or scored forecasts changed since), in one
  // transaction; *days_written (may be null) gets the rows written. The view
  // is right without it: it computes the days not materialised from the
  // measurements, which is what this spares its readers (meant to run
  // daily, and after an import).
  bool RefreshForecastSkill(std::int64_t now_ts, int* days_written, std::string* error);

  // Cells of weather_forecast or operation_plan that hold text (or a blob)
  // where a number belongs: what `sqlite3 .import` writes for an empty CSV
  // cell (''), or "12,5" or "n/a". Such a cell is read as missing, never as
  // the 0 SQLite would turn it into; a text that is a whole finite decimal
  // number ("12.5", "-3e2", blanks around it) is read as that number and not
  // counted.
  struct TextCells {
    std::array<std::size_t, kNumChannels> count{};  // per channel

    std::size_t Total() const;
    // One line for the caller to warn with, "" when no cell held text:
    // "weather_forecast: 1440 cells of t_amb_c, 12 of wind_m_s hold text,
    // read as missing".
    std::string Warning(const std::string& table) const;
  };

  // weather_forecast / operation_plan rows with from <= ts < to as a Series
  // (step_s = the smallest spacing of the rows, 0 for fewer than 2); a column
  // that is NULL in every row is absent. *text_cells (may be null) gets the
  // cells that held text (TextCells), for the caller to warn once per read.
  bool ReadWeatherForecast(std::int64_t from, std::int64_t to, Series* out, std::string* error,
                           TextCells* text_cells = nullptr);
  bool ReadOperationPlan(std::int64_t from, std::int64_t to, Series* out, std::string* error,
                         TextCells* text_cells = nullptr);
  // Upserts 1-min weather_forecast rows (the table's channels of `rows`,
  // NULL for the absent ones) with their source, in one transaction.
  bool WriteWeatherForecast(const Series& rows, const std::string& source, std::string* error);
  // The distinct sources of the weather_forecast rows with from <= ts < to,
  // most rows first ("weather_forecast" for rows without a source).
  bool ReadWeatherSources(std::int64_t from, std::int64_t to, std::vector<std::string>* sources,
                          std::string* error);
  // plant_config: replaced as a whole / all rows, by key.
  bool WritePlantConfig(const std::vector<std::pair<std::string, double>>& values,
                        std::string* error);
  bool ReadPlantConfig(std::vector<std::pair<std::string, double>>* values, std::string* error);

  // Writes the WAL back into the database file and truncates it (best effort
  // while readers hold old snapshots). *db_bytes (may be null) gets the bytes
  // in use: (page_count − freelist_count) · page_size.
  bool Checkpoint(std::int64_t* db_bytes, std::string* error);

 private:
  // The first accepted calibration row of "… WHERE accepted != 0 AND
  // <condition> ORDER BY run_at DESC, id DESC", its one `?` bound to value.
  bool ReadAcceptedCalibration(const char* condition, std::int64_t value, CalibrationRow* row,
                               bool* found, std::string* error);

  struct Impl;
  explicit Store(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace pvtwin
