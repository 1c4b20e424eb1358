#include "daemon/service/service.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <fstream>
#include <sstream>

#include "config/plant_config.h"
#include "core/common/clock.h"
#include "daemon/service/monitor.h"
#include "daemon/service/notify.h"
#include "daemon/service/service_internal.h"
#include "daemon/service/store_cli.h"
#include "io/platform/local_time.h"
#include "io/platform/log.h"
#include "io/platform/time_format.h"

namespace pvtwin::service_detail {

bool Service::LoadAndApplyConfig(bool initial, std::string* outcome) {
  // One read of the file: the text parsed is the text compared at the next
  // reload.
  std::string text;
  Config config;
  Diagnostics errors;
  std::ifstream in(options_.config_path, std::ios::binary);
  std::ostringstream read;
  read << in.rdbuf();
  text = read.str();
  const bool loaded = in ? ParseConfig(text, options_.config_path, &config, &errors)
                         : LoadConfig(options_.config_path, &config, &errors);
  if (!loaded) {
    for (const Diagnostic& d : errors) LogToStderr(kErr, d.ToString());
    *outcome = errors.empty() ? "the config could not be read" : errors.front().ToString();
    if (errors.size() > 1) *outcome += " (and " + std::to_string(errors.size() - 1) + " more)";
    return false;
  }
  ModelSpec spec;
  std::string error;
  [[maybe_unused]] const bool parsed = ParseVariant(config.calibration.variant, &spec, &error);
  assert(parsed && "LoadConfig checks the variant");
  if (!UseTimeZone(config.calibration.timezone, &error)) {
    *outcome = options_.config_path + ": [calibration] " + error;
    LogToStderr(kErr, *outcome);
    return false;
  }
  ParseClockTime(config.calibration.at, &at_hour_, &at_minute_);
  if (!options_.db_path.empty()) config.storage.path = options_.db_path;
  if (!initial) {
    *outcome = LogConfigChanges(config_text_, text);
    // The store, the poller and the upload own a file and connections;
    // they keep the settings they were started with (kNeedsRestart).
    config.upload = config_.upload;
    config.storage = config_.storage;
    config.poll = config_.poll;
    config.modbus = config_.modbus;
  }
  const bool spec_changed = !initial && spec.Name() != spec_.Name();
  config_ = config;
  config_text_ = text;
  spec_ = spec;
  if (spec_changed) {
    LogToStderr(kNotice, "reload: variant is now " + spec_.Name() +
                             "; forecasts use it after the next accepted calibration");
  }
  return true;
}

// A daemon started on another plant's store would write this plant's
// samples into that plant's history and fit one on the other's data.
bool Service::StoreIsThisPlants() {
  std::vector<std::pair<std::string, double>> stored;
  std::string error;
  if (!store_->ReadPlantConfig(&stored, &error)) {
    LogToStderr(kWarning, "reading the store's plant_config failed: " + error);
    return true;
  }
  const std::string differs = PlantMismatch(config_.plant, stored);
  if (differs.empty()) return true;
  if (options_.adopt_store) {
    LogToStderr(kNotice, config_.storage.path + " recorded another plant (" + differs +
                             "); adopted for " + options_.config_path + " (--adopt-store)");
    return true;
  }
  LogToStderr(kErr, config_.storage.path + " belongs to another plant than " +
                        options_.config_path + ": " + differs +
                        ". Point [storage] path at this plant's store; if the plant itself "
                        "changed, start once with --adopt-store");
  return false;
}

void Service::RecordPlant() {
  std::string error;
  if (!store_->WritePlantConfig(PlantKeyValues(config_.plant), &error)) {
    LogToStderr(kWarning, "recording the plant in the store failed: " + error);
  }
}

bool Service::StoreStillAtPath() {
  std::string what;
  if (store_lock_.StillAtPath(&what)) return true;
  const std::string& path = config_.storage.path;
  LogToStderr(kErr, path + " was " + what +
                        " while the daemon ran: later samples would go to a file nobody can "
                        "read. Stopping with exit 1; a restart creates a new store.");
  Shutdown();  // stores the samples held in memory, into the open file
  const std::string rescue =
      path + ".rescued-" + std::to_string(static_cast<std::int64_t>(WallNowS()));
  std::string error;
  if (store_->BackupTo(rescue, &error)) {
    LogToStderr(kErr, "the open store's content, up to the last sample, is saved in " + rescue);
  } else {
    LogToStderr(kErr, "could not save the open store's content: " + error);
  }
  return false;
}

void Service::Shutdown() {
  NotifyStopping();
  LogToStderr(kInfo, "stopping");
  weather_.reset();  // aborts a fetch in progress
  if (poller_) poller_->Stop();
  StoreSamples();
  if (store_) Aggregate();
  if (child_.running() && job_kind_ == JobKind::kRefit) {
    child_.Kill();
    LogToStderr(kInfo,
                "the refit was stopped with the daemon; the held-out-checked parameters "
                "stay");
  } else if (child_.running()) {
    child_.Kill();
    Store::CalibrationRow row = job_;
    row.status = "abandoned";
    row.runtime_s = WallNowS() - child_started_wall_s_;
    row.reason = "the daemon stopped during the fit";
    RecordCalibration(row);
  }
  if (diagnosis_ && diagnosis_->running()) {
    diagnosis_->Stop();
    LogToStderr(kInfo, "the running diagnosis was stopped with the daemon");
  }
  if (!pending_.empty()) {
    LogToStderr(kErr, std::to_string(pending_.size()) + " samples could not be stored");
  }
  // Last: rows stored above stay queued for the next start.
  if (upload_) upload_->Stop();
}

int Service::Run() {
  std::string outcome;
  if (!LoadAndApplyConfig(true, &outcome)) return 2;
  clock_ = options_.sim_start_s > 0
               ? std::make_unique<ScaledClock>(options_.sim_start_s, options_.wall_anchor_s,
                                               options_.speed)
               : std::make_unique<ScaledClock>();
  std::string error;
  // The 1-min aggregation needs the poll period and the fluid's c_p.
  store_ = Store::Open(config_.storage.path, cli::StoreOptionsFor(config_), &error);
  if (!store_) {
    LogToStderr(kErr, error);
    return 1;
  }
  if (!store_lock_.Acquire(config_.storage.path, &error)) {
    LogToStderr(kErr, error);
    return 1;
  }
  if (!StoreIsThisPlants()) return 2;
  RecordPlant();
  work_dir_ = fs::path(config_.storage.path).parent_path() / "calibration";
  diagnosis_ =
      std::make_unique<cli::NightlyDiagnosis>(fs::path(config_.storage.path).parent_path());
  LoadCurrentParameters();
  if (!config_.modbus.devices.empty()) {
    PollerOptions poller_options;
    poller_options.period_s = config_.poll.period_s;
    poller_options.area_m2 = config_.plant.area_m2;
    poller_ = std::make_unique<ModbusPoller>(config_.modbus, poller_options, *clock_,
                                             [this](int priority, const std::string& line) {
                                               LogToStderr(priority, line);
                                               std::lock_guard lock(device_events_mutex_);
                                               device_events_.emplace_back(priority, line);
                                             });
    poller_->Start([this](const Sample& s) { queue_.Push(s); });
    StartDeviceCounts();
  } else {
    LogToStderr(kNotice,
                "no [[modbus.device]] in the config: polling is off; calibrations and "
                "forecasts use the data imported into the database");
  }
  if (config_.upload.enabled) StartUpload();
  UpdateWeatherFetch();
  const double now = Now();
  next_calibration_s_ = !have_params_ && options_.calibrate_when_uncalibrated
                            ? now
                            : static_cast<double>(NextLocalTime(static_cast<std::int64_t>(now),
                                                                at_hour_, at_minute_));
  next_forecast_s_ = now;
  next_retention_s_ = now;
  last_status_s_ = now;
  ArmHealthReport();
  const double watchdog_s = WatchdogIntervalS();
  NotifyReady("polling " + std::to_string(config_.modbus.devices.size()) + " devices into " +
              config_.storage.path);
  if (have_params_) SetState("calibration " + std::to_string(params_id_) + " in use");
  LogToStderr(kInfo, "ready: " + config_.storage.path + ", variant " + spec_.Name() +
                         ", next calibration " +
                         FormatIsoUtc(static_cast<std::int64_t>(next_calibration_s_)));

  const std::atomic<bool> never(false);
  const std::atomic<bool>& stop = options_.stop ? *options_.stop : never;
  // One pass per poll period (simulated time), at least every second of wall
  // time so that signals, the watchdog and the calibration child are served.
  const double pass_s = std::min(config_.poll.period_s, clock_->speed());
  while (!stop.load()) {
    clock_->SleepUntil(Now() + pass_s, stop);
    if (options_.reload && options_.reload->exchange(false)) Reload();
    if (!StoreStillAtPath()) return 1;
    StoreSamples();
    Aggregate();
    CheckCalibration();
    diagnosis_->Check(config_.diagnosis, *store_, LogToStderr);
    MaybeStartCalibration();
    // A fresh weather forecast is used at once, not at the next refresh.
    const bool fresh_weather = weather_ && weather_->TakeFresh();
    if (Now() >= next_forecast_s_ || fresh_weather) IssueForecast();
    if (Now() >= next_retention_s_) {
      next_retention_s_ = Now() + kRetentionPeriodS;
      if (!store_->ApplyRetention(static_cast<std::int64_t>(Now()),
                                  config_.storage.raw_retention_days, &error))
        LogToStderr(kWarning, "retention failed (retried in an hour): " + error);
      // The daily checks materialise forecast_skill after the night's
      // calibration; this covers the nights without one (a skipped or
      // failed calibration) and costs nothing when there is nothing to do.
      if (!store_->RefreshForecastSkill(static_cast<std::int64_t>(Now()), nullptr, &error))
        LogToStderr(kWarning, "forecast_skill refresh failed (retried in an hour): " + error);
    }
    if (watchdog_s > 0 && WallNowS() >= next_watchdog_wall_s_) {
      NotifyWatchdog();
      next_watchdog_wall_s_ = WallNowS() + watchdog_s;
    }
    UpdateDeviceStatus();
    MaybeReportHealth();
    status_.now_s = Now();
    status_.calibration_id = params_id_;
    if (options_.on_tick && !options_.on_tick(status_)) break;
  }
  Shutdown();
  return 0;
}

}  // namespace pvtwin::service_detail

namespace pvtwin {

int RunService(const ServiceOptions& options) {
  service_detail::Service service(options);
  return service.Run();
}

}  // namespace pvtwin
