// The daemon's Service class (daemon/service/service.h), private to this
// folder: one file per job implements its part of it —
//   service.cc              config load and reload, the loop, shutdown, the
//                           store's identity (plant) and path
//   service_samples.cc      samples from the poller into the store, 1-min
//                           aggregation, device status
//   service_calibration.cc  the nightly calibration child, the held-out
//                           check, the refit, calibration rows
//   service_diagnose.cc     the daily checks and the nightly diagnosis
//   service_forecast.cc     forecast issues and the window's replay
//   service_workers.cc      the upload and weather-fetch threads
//   service_reload.cc       SIGHUP: the config read again, its changes logged
//   service_health.cc       the health line and systemd's STATUS=
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "config/plant_config.h"
#include "core/common/clock.h"
#include "core/common/sample.h"
#include "core/forecast/forecast.h"
#include "core/forecast/forecast_bands.h"
#include "core/forecast/start_value_forecast.h"
#include "core/model/variant.h"
#include "daemon/service/calibration_acceptance.h"
#include "daemon/service/nightly_diagnosis.h"
#include "daemon/service/service.h"
#include "daemon/service/upload_worker.h"
#include "daemon/service/weather_worker.h"
#include "daemon/service/window_data.h"
#include "io/modbus/modbus_poller.h"
#include "io/platform/child_process.h"
#include "io/store/store.h"
#include "io/store/store_lock.h"

namespace pvtwin::service_detail {

namespace fs = std::filesystem;

inline constexpr std::int64_t kDayS = 86400;
// Samples kept in memory while the database refuses writes: one day at 5 s.
inline constexpr std::size_t kMaxPendingSamples = 17280;
// A daemon without parameters retries a calibration it lacked data for.
inline constexpr double kUncalibratedRetryS = 3600.0;
// A plant without parameters retries a start-value forecast the model could
// not run yet (no measured minute) this often.
inline constexpr double kStartValueRetryS = 300.0;
inline constexpr double kRetentionPeriodS = 3600.0;
// Calibration run directories kept (calibration/run-<run_at>), the running one included.
inline constexpr std::size_t kKeptCalibrationRuns = 5;

inline std::string Format(const char* fmt, double a) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, a);
  return buf;
}

// Samples handed over by the poller's threads.
class SampleQueue {
 public:
  void Push(const Sample& s) {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(s);
  }
  std::vector<Sample> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Sample> out;
    out.swap(queue_);
    return out;
  }

 private:
  std::mutex mutex_;
  std::vector<Sample> queue_;
};

class Service {
 public:
  explicit Service(const ServiceOptions& options) : options_(options) {}

  int Run();

 private:
  // Reads the config file and applies it: false when it has errors (they
  // are logged, *outcome is the first). On a reload (initial false) the
  // changed keys are logged and *outcome summarises them; what a reload
  // cannot apply keeps its running value (service_reload.cc).
  bool LoadAndApplyConfig(bool initial, std::string* outcome);
  // SIGHUP (service_reload.cc).
  void Reload();
  // Logs each key that differs between the two config texts; returns "no
  // change" or "N keys changed[, M need a restart: …]".
  std::string LogConfigChanges(const std::string& old_text, const std::string& new_text);
  void StoreSamples();
  void Aggregate();
  void MaybeStartCalibration();
  void CheckCalibration();
  void FinishCalibration(int exit_code);
  // Writes data to job_dir_/csv_name and starts `pvtwin calibrate` on it, at
  // [calibration] step_s or, when that is no multiple of data's, at data's.
  bool StartCalibrateChild(const Series& data, const std::string& csv_name, std::string* error);
  void StartRefit();
  void FinishRefit(int exit_code);
  // Writes the config the daemon runs with (config_text_) to
  // <store dir>/config-in-use.toml for the calibrate and diagnose children,
  // and sets *path to it. The file on disk may hold an edit that a reload
  // refused, or one not yet reloaded: a child started on it would fail, or
  // run on settings the daemon does not use.
  bool WriteConfigInUse(std::string* path, std::string* error);
  // Daily checks and the diagnosis, once the night's calibration is done.
  void AfterCalibration();
  // performance_daily, sensor faults, drift and alarms (daemon/service/monitor.h).
  void DailyChecks(bool accepted_now);
  // The nightly diagnosis child (daemon/service/nightly_diagnosis.h), when due.
  void MaybeStartDiagnosis();
  // Inserts the row and returns its id (0 when it could not be stored);
  // logs it at `priority` (default: notice when accepted, else warning).
  std::int64_t RecordCalibration(Store::CalibrationRow row, int priority = -1);
  // A plant without parameters and less than two days of data: the wait is
  // a state (info once, the status line), not a warning per attempt.
  void RecordWaitForHistory(Store::CalibrationRow row, std::int64_t span_s);
  // The daemon's state for the systemd status line and ServiceStatus.
  void SetState(const std::string& state);
  bool LoadCurrentParameters();
  void IssueForecast();
  // Before the first accepted calibration (core/forecast/start_value_forecast.h).
  void IssueStartValueForecast();
  // The measured history of the history_s before now (the 1-min rows, else
  // without one the interval rows at their own step: window_data.h), the
  // request of an issue now at that history's step and on its grid, and the
  // weather forecast and the plan over its horizon; false after logging.
  bool ReadForecastInputs(double now_s, std::int64_t history_s, ForecastRequest* request,
                          cli::WindowData* history, Series* weather, Series* plan);
  // Stores one issue and logs it (brief: the inputs in a few words); false
  // after logging.
  bool WriteForecast(const ForecastRequest& request, ForecastBasis basis,
                     const BandedForecast& banded, const std::string& inputs,
                     const std::string& brief);
  void Shutdown();
  // False (after logging, stopping and saving the open store beside it)
  // when the database file was deleted or replaced under the daemon.
  bool StoreStillAtPath();
  void UpdateDeviceStatus();
  void StartUpload();
  // The [plant] in use into the store's plant_config, for commands given
  // only the store (import-weather --db).
  bool StoreIsThisPlants();
  void RecordPlant();
  // Starts, restarts (after a reload changed them) or stops the weather
  // fetch to match [forecast] weather_url and the plant.
  void UpdateWeatherFetch();
  // The health line (service_health.cc).
  void StartDeviceCounts();
  void CountStoredSamples(const std::vector<Sample>& samples);
  void ArmHealthReport();
  void MaybeReportHealth();
  std::string CalibrationHealth() const;
  std::string ForecastHealth(bool brief) const;
  double Now() const { return clock_->NowS(); }

  ServiceOptions options_;
  Config config_;
  ModelSpec spec_;
  int at_hour_ = 2, at_minute_ = 0;
  std::unique_ptr<ScaledClock> clock_;
  StoreLock store_lock_;  // declared before store_: released after it is closed
  std::unique_ptr<Store> store_;
  std::unique_ptr<ModbusPoller> poller_;
  // [upload]: its own thread, so the loop never waits for the server.
  std::unique_ptr<UploadWorker> upload_;
  // [forecast] weather_url: its own thread too.
  std::unique_ptr<WeatherWorker> weather_;
  SampleQueue queue_;
  std::vector<Sample> pending_;
  bool store_failing_ = false;
  ServiceStatus status_;

  // Calibration.
  fs::path work_dir_;  // <store dir>/calibration
  fs::path job_dir_;   // work_dir_/run-<run_at>: the running calibration's files
  ChildProcess child_;
  double child_started_wall_s_ = 0.0;
  Store::CalibrationRow job_;
  Series job_test_;
  Series job_window_;  // the whole window, for the refit
  enum class JobKind { kHeldOut, kRefit };
  JobKind job_kind_ = JobKind::kHeldOut;
  bool accepted_tonight_ = false;
  cli::HeldOutChoice job_held_out_;
  // "last 2 days held out, 312 rows with the pump on in sunshine".
  std::string HeldOutText() const {
    return (job_held_out_.days == 1 ? std::string("last day")
                                    : "last " + std::to_string(job_held_out_.days) + " days") +
           " held out, " + std::to_string(job_held_out_.informative_rows) +
           " rows with the pump on in sunshine";
  }
  double next_calibration_s_ = 0.0;
  // Current parameters.
  bool have_params_ = false;
  bool waiting_announced_ = false;  // the wait for history was logged and recorded
  std::string start_value_error_;   // why the last start-value forecast could not be made
  std::int64_t params_id_ = 0;
  ParamVector params_{};
  std::string params_json_;
  std::unique_ptr<cli::NightlyDiagnosis> diagnosis_;
  std::mutex device_events_mutex_;
  std::vector<std::pair<int, std::string>> device_events_;  // poller state changes, for events
  // Forecast and housekeeping.
  double next_forecast_s_ = 0.0;
  // What the forecasts learn from the window (operation choice, replayed
  // errors for the bands, replayed at the issue's time of day): recomputed
  // for each issue.
  ForecastWindowStats forecast_stats_;
  std::int64_t forecast_stats_issued_at_ = -1;
  std::string text_cells_warned_;  // the forecast inputs' text cells last warned of
  std::int64_t forecast_stats_params_id_ = -1;
  void UpdateForecastStats(const Series& history, const ForecastRequest& request);
  double next_retention_s_ = 0.0;
  double next_watchdog_wall_s_ = 0.0;
  // The config file's text as last applied, compared at the next reload.
  std::string config_text_;
  // Health line: samples per device since the last line (a channel mask of
  // each device's points), the last calibration attempt and forecast.
  struct DeviceCounts {
    std::string name;
    std::uint32_t channels = 0;
    std::uint64_t stored = 0;
    std::uint64_t rejected = 0;
  };
  std::vector<DeviceCounts> device_counts_;
  std::uint64_t samples_since_status_ = 0;
  double last_status_s_ = 0.0;
  double next_status_s_ = 0.0;
  struct LastCalibration {
    std::int64_t id = 0;
    std::string status;  // empty: none seen
    double run_at_s = 0.0;
  } last_calibration_;
  std::int64_t last_forecast_issued_at_ = -1;
};

}  // namespace pvtwin::service_detail
