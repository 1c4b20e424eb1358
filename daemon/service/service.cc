#include "daemon/service/service.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "config/plant_config.h"
#include "core/common/clock.h"
#include "core/common/sample.h"
#include "core/fit/identification.h"
#include "core/forecast/forecast.h"
#include "core/forecast/forecast_bands.h"
#include "core/model/thermal_model.h"
#include "core/model/variant.h"
#include "daemon/service/calibration_acceptance.h"
#include "daemon/service/monitor.h"
#include "daemon/service/nightly_diagnosis.h"
#include "daemon/service/notify.h"
#include "daemon/service/store_cli.h"
#include "daemon/service/upload_worker.h"
#include "daemon/service/weather_worker.h"
#include "io/platform/child_process.h"
#include "io/files/csv.h"
#include "io/weather/http_client.h"
#include "io/platform/local_time.h"
#include "io/platform/log.h"
#include "io/modbus/modbus_poller.h"
#include "io/files/params_json.h"
#include "io/store/store.h"
#include "io/store/store_lock.h"
#include "io/platform/time_format.h"

namespace pvtwin {

namespace {

namespace fs = std::filesystem;

constexpr std::int64_t kDayS = 86400;
// Samples kept in memory while the database refuses writes: one day at 5 s.
constexpr std::size_t kMaxPendingSamples = 17280;
// A daemon without parameters retries a calibration it lacked data for.
constexpr double kUncalibratedRetryS = 3600.0;
constexpr double kRetentionPeriodS = 3600.0;
// Calibration run directories kept (calibration/run-<run_at>), the running one included.
constexpr std::size_t kKeptCalibrationRuns = 5;

// Removes all but the newest `keep` - 1 run-* directories of dir (a new one
// is about to be made).
void RemoveOldRunDirectories(const fs::path& dir, std::size_t keep) {
  std::error_code ec;
  std::vector<fs::path> runs;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    if (e.is_directory(ec) && e.path().filename().string().starts_with("run-")) {
      runs.push_back(e.path());
    }
  }
  // run-<unix seconds>: the same number of digits for centuries, so names
  // sort by time.
  std::sort(runs.begin(), runs.end());
  while (runs.size() >= keep && !runs.empty()) {
    fs::remove_all(runs.front(), ec);
    runs.erase(runs.begin());
  }
}

std::string Format(const char* fmt, double a) {
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

// Held-out objective (W/m², paper 3.2.2) of params on a series.
std::optional<ErrorMetrics> HeldOutErrors(const Series& test, const Plant& plant,
                                          const ModelSpec& spec, const ParamVector& params) {
  Drivers drivers;
  std::string error;
  if (!PrepareDrivers(test, plant, spec, &drivers, &error)) return std::nullopt;
  SimOutputs sim;
  Simulate(drivers, params, &sim);
  const Measurements meas = MakeMeasurements(test, drivers);
  if (meas.rows.empty()) return std::nullopt;
  ErrorMetrics e = ComputeErrors(meas, sim, plant.area_m2);
  if (!std::isfinite(e.objective_w_m2())) return std::nullopt;
  return e;
}

// The "parameters" list of calibrate's fit JSON as calibration_param rows;
// entries without a name or a numeric value are skipped.
std::vector<Store::CalibrationParamRow> ParamRowsOf(const nlohmann::json& fit) {
  std::vector<Store::CalibrationParamRow> rows;
  for (const nlohmann::json& p : fit.value("parameters", nlohmann::json::array())) {
    if (!p.is_object() || !p.contains("name") || !p["name"].is_string() || !p.contains("value") ||
        !p["value"].is_number()) {
      continue;
    }
    Store::CalibrationParamRow row;
    row.name = p["name"].get<std::string>();
    row.value = p["value"].get<double>();
    row.std_error = p.contains("std_error") && p["std_error"].is_number()
                        ? p["std_error"].get<double>()
                        : std::nan("");
    row.unit = p.value("unit", "");
    row.status = p.value("status", "");
    rows.push_back(std::move(row));
  }
  return rows;
}

class Service {
 public:
  explicit Service(const ServiceOptions& options) : options_(options) {}

  int Run();

 private:
  bool LoadAndApplyConfig(bool initial);
  void StoreSamples();
  void Aggregate();
  void MaybeStartCalibration();
  void CheckCalibration();
  void FinishCalibration(int exit_code);
  // Writes data to job_dir_/csv_name and starts `pvtwin calibrate` on it.
  bool StartCalibrateChild(const Series& data, const std::string& csv_name, std::string* error);
  void StartRefit();
  void FinishRefit(int exit_code);
  // Daily checks and the diagnosis, once the night's calibration is done.
  void AfterCalibration();
  // performance_daily, sensor faults, drift and alarms (daemon/service/monitor.h).
  void DailyChecks(bool accepted_now);
  // The nightly diagnosis child (daemon/service/nightly_diagnosis.h), when due.
  void MaybeStartDiagnosis();
  // Inserts the row and returns its id (0 when it could not be stored).
  std::int64_t RecordCalibration(Store::CalibrationRow row);
  bool LoadCurrentParameters();
  void IssueForecast();
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
};

bool Service::LoadAndApplyConfig(bool initial) {
  Config config;
  Diagnostics errors;
  if (!LoadConfig(options_.config_path, &config, &errors)) {
    for (const Diagnostic& d : errors) LogToStderr(kErr, d.ToString());
    return false;
  }
  ModelSpec spec;
  std::string error;
  [[maybe_unused]] const bool parsed = ParseVariant(config.calibration.variant, &spec, &error);
  assert(parsed && "LoadConfig checks the variant");
  if (!UseTimeZone(config.calibration.timezone, &error)) {
    LogToStderr(kErr, options_.config_path + ": [calibration] " + error);
    return false;
  }
  ParseClockTime(config.calibration.at, &at_hour_, &at_minute_);
  if (!options_.db_path.empty()) config.storage.path = options_.db_path;
  if (!initial) {
    // The store and the poller own a file and connections; they keep the
    // settings they were started with.
    if (config.storage.path != config_.storage.path ||
        config.poll.period_s != config_.poll.period_s)
      LogToStderr(kWarning, "reload: [storage] and [poll] changes take effect after a restart");
    if (config.plant.fluid_cp_j_kgk != config_.plant.fluid_cp_j_kgk) {
      LogToStderr(kWarning,
                  "reload: the 1-min aggregation uses the new [plant] fluid_cp_j_kgk after a "
                  "restart");
    }
    if (config.upload.enabled != config_.upload.enabled ||
        config.upload.url != config_.upload.url ||
        config.upload.plant_id != config_.upload.plant_id)
      LogToStderr(kWarning, "reload: [upload] changes take effect after a restart");
    config.upload = config_.upload;
    if (config.modbus.devices.size() != config_.modbus.devices.size() ||
        config.modbus.points.size() != config_.modbus.points.size())
      LogToStderr(kWarning, "reload: [[modbus.*]] changes take effect after a restart");
    config.storage = config_.storage;
    config.poll = config_.poll;
    config.modbus = config_.modbus;
  }
  const bool spec_changed = !initial && spec.Name() != spec_.Name();
  config_ = config;
  spec_ = spec;
  if (spec_changed) {
    LogToStderr(kNotice, "reload: variant is now " + spec_.Name() +
                             "; forecasts use it after the next accepted calibration");
  }
  return true;
}

void Service::StoreSamples() {
  std::vector<Sample> fresh = queue_.Take();
  pending_.insert(pending_.end(), fresh.begin(), fresh.end());
  if (pending_.empty()) return;
  if (pending_.size() > kMaxPendingSamples) {
    const std::size_t drop = pending_.size() - kMaxPendingSamples;
    LogToStderr(kErr, "database unwritable for a day: dropping the " + std::to_string(drop) +
                          " oldest samples");
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(drop));
  }
  std::string error;
  if (!store_->InsertSamples(pending_, &error)) {
    if (!store_failing_) {
      LogToStderr(kErr, "storing samples failed (kept in memory, retried): " + error);
      store_failing_ = true;
    }
    return;
  }
  if (store_failing_) LogToStderr(kNotice, "storing samples works again");
  store_failing_ = false;
  status_.samples_stored += pending_.size();
  pending_.clear();
}

void Service::Aggregate() {
  // The sample of the period starting at t arrives at t + period; a minute
  // is complete once its last period has been delivered.
  const double settled_s = Now() - config_.poll.period_s - 1.0;
  const std::int64_t up_to = static_cast<std::int64_t>(std::floor(settled_s / 60.0)) * 60;
  int written = 0;
  std::string error;
  if (!store_->AggregateMinutes(up_to, &written, &error)) {
    LogToStderr(kWarning, "aggregation to 1-min rows failed (retried): " + error);
    return;
  }
  status_.minutes_aggregated += static_cast<std::uint64_t>(written);
}

bool Service::LoadCurrentParameters() {
  Store::CalibrationRow row;
  bool found = false;
  std::string error;
  if (!store_->LatestAcceptedCalibration(&row, &found, &error)) {
    LogToStderr(kErr, "reading the accepted calibration failed: " + error);
    return false;
  }
  if (!found) return false;
  ParamsFile file;
  Diagnostics errors;
  if (!ParseParamsJson(row.params_json, "calibration " + std::to_string(row.id), config_.plant,
                       &file, &errors)) {
    for (const Diagnostic& d : errors) LogToStderr(kErr, d.ToString());
    return false;
  }
  ModelSpec spec;
  if (!file.variant.empty() && ParseVariant(file.variant, &spec, &error)) spec_ = spec;
  have_params_ = true;
  params_id_ = row.id;
  params_ = file.values;
  params_json_ = row.params_json;
  return true;
}

void Service::MaybeStartCalibration() {
  if (child_.running() || Now() < next_calibration_s_) return;
  const double now = Now();
  next_calibration_s_ =
      static_cast<double>(NextLocalTime(static_cast<std::int64_t>(now), at_hour_, at_minute_));
  const std::int64_t end = static_cast<std::int64_t>(std::floor(now / 60.0)) * 60;
  const std::int64_t begin = end - config_.calibration.window_days * kDayS;

  Store::CalibrationRow row;
  row.run_at = static_cast<std::int64_t>(now);
  row.variant = spec_.Name();
  row.window_start = begin;
  row.window_end = end;
  Series window;
  std::string error;
  if (!store_->ReadMinutes(begin, end, &window, &error)) {
    row.status = "failed";
    row.reason = "reading the window failed: " + error;
    RecordCalibration(row);
    return;
  }
  const std::int64_t span = window.size() ? window.time_s.back() - window.time_s.front() : 0;
  if (span < 2 * kDayS - 120) {
    row.status = "skipped";
    row.reason = "window holds " + Format("%.1f", span / 86400.0) +
                 " days of 1-min data; two are needed (training days and a held-out day)";
    RecordCalibration(row);
    if (!have_params_)
      next_calibration_s_ = std::min(next_calibration_s_, now + kUncalibratedRetryS);
    return;
  }
  // Held out: the last days, as many as it takes (up to 3) to hold two hours
  // with the pump running in sunshine; an overcast pump-off day cannot tell
  // two parameter sets apart.
  const cli::HeldOutChoice held_out = cli::ChooseHeldOutDays(window, end);
  const std::int64_t test_start = end - held_out.days * kDayS;
  const Series train = window.Between(begin, test_start);
  job_test_ = window.Between(test_start, end);
  job_held_out_ = held_out;

  // Each run has its own directory, so a child left over from a killed
  // daemon can never write where the next run reads; the newest few are kept
  // for the operator.
  job_dir_ = work_dir_ / ("run-" + std::to_string(row.run_at));
  RemoveOldRunDirectories(work_dir_, kKeptCalibrationRuns);
  if (!StartCalibrateChild(train, "train.csv", &error)) {
    row.status = "failed";
    row.reason = error;
    RecordCalibration(row);
    return;
  }
  job_ = row;
  job_window_ = window;
  job_kind_ = JobKind::kHeldOut;
  status_.calibrating = true;
  LogToStderr(kInfo, "calibration of " + spec_.Name() + " started on " + FormatIsoUtc(begin) +
                         " .. " + FormatIsoUtc(end) + " (" + HeldOutText() + ")");
}

bool Service::StartCalibrateChild(const Series& data, const std::string& csv_name,
                                  std::string* error) {
  std::error_code ec;
  fs::create_directories(job_dir_, ec);
  const fs::path csv = job_dir_ / csv_name;
  const fs::path new_json = job_dir_ / "new-params.json";
  const fs::path log_path = job_dir_ / "calibrate.log";
  std::vector<Channel> channels;
  for (const ChannelInfo& info : kChannels) {
    if (data.Has(info.channel)) channels.push_back(info.channel);
  }
  fs::remove(new_json, ec);
  fs::remove(log_path, ec);
  if (!WriteCsv(csv.string(), data, channels, error)) return false;
  std::vector<std::string> argv = {options_.exe_path.empty() ? SelfExecutable() : options_.exe_path,
                                   "calibrate",
                                   "--config",
                                   options_.config_path,
                                   "--csv",
                                   csv.string(),
                                   "--variant",
                                   spec_.Name(),
                                   "--step",
                                   Format("%.0f", config_.calibration.step_s),
                                   "--ftol",
                                   Format("%g", options_.calibration_ftol),
                                   "--out",
                                   new_json.string(),
                                   "--parent-pid",
                                   std::to_string(::getpid())};
  if (have_params_) {
    const fs::path current = job_dir_ / "current-params.json";
    if (WriteTextFileAtomically(current.string(), params_json_, error)) {
      argv.push_back("--start");
      argv.push_back(current.string());
    }
  }
  if (!child_.Start(argv, log_path.string(), error)) return false;
  child_started_wall_s_ = WallNowS();
  return true;
}

void Service::CheckCalibration() {
  if (!child_.running()) return;
  int exit_code = 0;
  if (child_.Finished(&exit_code)) {
    if (job_kind_ == JobKind::kRefit) {
      FinishRefit(exit_code);
    } else {
      const std::int64_t before = params_id_;
      FinishCalibration(exit_code);  // may start the refit
      accepted_tonight_ = params_id_ != before;
    }
    if (!child_.running()) AfterCalibration();
    return;
  }
  const double ran_s = WallNowS() - child_started_wall_s_;
  if (ran_s > options_.calibration_timeout_s) {
    child_.Kill();
    if (job_kind_ == JobKind::kRefit) {
      LogToStderr(kWarning, "the refit of calibration " + std::to_string(params_id_) +
                                " ran over its time limit; the held-out-checked parameters stay");
    } else {
      Store::CalibrationRow row = job_;
      row.status = "timeout";
      row.runtime_s = ran_s;
      row.reason = "abandoned after " + Format("%.0f", ran_s) + " s (limit " +
                   Format("%.0f", options_.calibration_timeout_s) + " s); parameters kept";
      RecordCalibration(row);
      accepted_tonight_ = false;
    }
    AfterCalibration();
  }
}

void Service::AfterCalibration() {
  status_.calibrating = false;
  DailyChecks(accepted_tonight_);
  MaybeStartDiagnosis();
}

// After the held-out check the fit is repeated on the whole window (the
// held-out days carry the newest information), warm-started from the
// accepted parameters.
void Service::StartRefit() {
  std::string error;
  job_dir_ = job_dir_ / "refit";
  if (!StartCalibrateChild(job_window_, "window.csv", &error)) {
    LogToStderr(kWarning, "the refit on the whole window did not start (" + error +
                              "); the held-out-checked parameters stay");
    return;
  }
  job_kind_ = JobKind::kRefit;
  status_.calibrating = true;
}

void Service::FinishRefit(int exit_code) {
  job_kind_ = JobKind::kHeldOut;
  const fs::path new_json = job_dir_ / "new-params.json";
  std::ifstream in(new_json);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ParamsFile file;
  Diagnostics errors;
  if (exit_code != 0 || !ParseParamsJson(text, new_json.string(), config_.plant, &file, &errors)) {
    LogToStderr(kWarning,
                "the refit of calibration " + std::to_string(params_id_) +
                    " on the whole window failed (" +
                    (exit_code != 0 ? LastOutputLine((job_dir_ / "calibrate.log").string())
                                    : std::string("unreadable parameters")) +
                    "); the held-out-checked parameters stay");
    return;
  }
  const nlohmann::json fit =
      nlohmann::json::parse(text, nullptr, false).value("fit", nlohmann::json::object());
  const std::string note = "; refit on the whole window (held-out days included) in " +
                           Format("%.1f", WallNowS() - child_started_wall_s_) + " s";
  std::string error;
  if (!store_->UpdateCalibrationParams(params_id_, text, ParamRowsOf(fit), note, &error)) {
    LogToStderr(kWarning, "storing the refit failed (" + error +
                              "); the held-out-checked "
                              "parameters stay");
    return;
  }
  params_ = file.values;
  params_json_ = text;
  LogToStderr(kInfo, "calibration " + std::to_string(params_id_) + note.substr(1));
  IssueForecast();
}

void Service::MaybeStartDiagnosis() {
  if (!have_params_ || !diagnosis_) return;
  cli::NightlyDiagnosis::Job job;
  job.exe = options_.exe_path.empty() ? SelfExecutable() : options_.exe_path;
  job.config_path = options_.config_path;
  job.db_path = config_.storage.path;
  job.variant = spec_.Name();
  job.step_s = Format("%.0f", config_.calibration.step_s);
  job.window_start = job_.window_start;
  job.window_end = job_.window_end;
  job.calibration_id = params_id_;
  job.now_s = static_cast<std::int64_t>(Now());
  diagnosis_->MaybeStart(config_.diagnosis, *store_, job, LogToStderr);
}

void Service::DailyChecks(bool accepted_now) {
  cli::DailyCheckInputs in;
  in.config = &config_;
  in.spec = spec_;
  in.now_s = static_cast<std::int64_t>(Now());
  in.accepted_now = accepted_now;
  for (const auto& [priority, line] : cli::RunDailyChecks(*store_, in)) {
    LogToStderr(priority, line);
  }
}

void Service::FinishCalibration(int exit_code) {
  Store::CalibrationRow row = job_;
  row.runtime_s = WallNowS() - child_started_wall_s_;
  const fs::path new_json = job_dir_ / "new-params.json";
  if (exit_code != 0) {
    row.status = exit_code < 0 ? "crashed" : "failed";
    row.reason = (exit_code < 0 ? "calibrate ended by signal " + std::to_string(-exit_code)
                                : "calibrate exited with " + std::to_string(exit_code)) +
                 ": " + LastOutputLine((job_dir_ / "calibrate.log").string());
    RecordCalibration(row);
    return;
  }
  std::ifstream in(new_json);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ParamsFile file;
  Diagnostics errors;
  if (!ParseParamsJson(text, new_json.string(), config_.plant, &file, &errors)) {
    row.status = "failed";
    row.reason = errors.empty() ? "unreadable parameters" : errors.front().ToString();
    RecordCalibration(row);
    return;
  }
  const nlohmann::json fit =
      nlohmann::json::parse(text, nullptr, false).value("fit", nlohmann::json::object());
  row.n_evals = fit.value("simulations", 0L);
  row.params_json = text;
  row.params = ParamRowsOf(fit);
  const std::optional<ErrorMetrics> fresh =
      HeldOutErrors(job_test_, config_.plant, spec_, file.values);
  if (!fresh) {
    row.status = "rejected";
    row.reason =
        "the held-out days have no usable rows to judge the new parameters (" + HeldOutText() + ")";
    RecordCalibration(row);
    return;
  }
  row.mae_p_el_w = fresh->mae_p_el_w;
  row.mae_q_th_w = fresh->mae_q_th_w;
  row.heldout_mae_w = fresh->mae_p_el_w + fresh->mae_q_th_w;
  std::optional<ErrorMetrics> current;
  if (have_params_) current = HeldOutErrors(job_test_, config_.plant, spec_, params_);
  std::vector<std::string> at_bounds;
  for (const auto& name : fit.value("at_bounds", nlohmann::json::array())) {
    if (name.is_string()) at_bounds.push_back(name.get<std::string>());
  }
  const double tolerance_w_m2 =
      current ? cli::HeldOutDifferenceSe(job_test_, config_.plant, spec_, file.values, params_)
              : 0.0;
  const cli::AcceptanceDecision decision = cli::DecideCalibration(
      fresh->objective_w_m2(),
      current ? std::optional<double>(current->objective_w_m2()) : std::nullopt, at_bounds,
      config_.plant.area_m2, tolerance_w_m2);
  row.reason = decision.reason + "; " + HeldOutText();
  if (current) row.reason += " (current: calibration " + std::to_string(params_id_) + ")";
  if (!decision.accept) {
    row.status = "rejected";
    RecordCalibration(row);
    return;
  }
  row.status = "accepted";
  row.accepted = true;
  row.id = RecordCalibration(row);
  if (row.id > 0) {
    have_params_ = true;
    params_id_ = row.id;
    params_ = file.values;
    params_json_ = text;
    IssueForecast();
    if (config_.calibration.refit_full_window) StartRefit();
  }
}

std::int64_t Service::RecordCalibration(Store::CalibrationRow row) {
  std::string error;
  if (!store_->InsertCalibration(&row, &error)) {
    LogToStderr(kErr, "recording the calibration failed: " + error);
    row.id = 0;
  }
  status_.calibrating = false;
  ++status_.calibrations;
  status_.last_calibration = row.status + ": " + row.reason;
  LogToStderr(row.status == "accepted" ? kNotice : kWarning,
              "calibration " + std::to_string(row.id) + " " + row.status + ": " + row.reason);
  return row.id;
}

void Service::IssueForecast() {
  if (!have_params_) return;
  const double now = Now();
  next_forecast_s_ = now + config_.forecast.refresh_min * 60.0;
  ForecastRequest request;
  request.issued_at_s = static_cast<std::int64_t>(std::floor(now / 60.0)) * 60;
  request.horizon_s = config_.forecast.horizon_h * 3600.0;
  const std::int64_t horizon_end =
      request.issued_at_s + static_cast<std::int64_t>(request.horizon_s);
  Series history, weather, plan;
  std::string error;
  const std::int64_t history_from = request.issued_at_s - config_.calibration.window_days * kDayS;
  Store::TextCells weather_text, plan_text;
  if (!store_->ReadMinutes(history_from, request.issued_at_s, &history, &error) ||
      !store_->ReadWeatherForecast(request.issued_at_s, horizon_end, &weather, &error,
                                   &weather_text) ||
      !store_->ReadOperationPlan(request.issued_at_s, horizon_end, &plan, &error, &plan_text)) {
    LogToStderr(kErr, "forecast inputs could not be read: " + error);
    return;
  }
  // Text where a number belongs (an `sqlite3 .import` of empty cells): read
  // as missing, said once for as long as it stays the same.
  const std::string text_warning = weather_text.Warning("weather_forecast") +
                                   (weather_text.Total() && plan_text.Total() ? "; " : "") +
                                   plan_text.Warning("operation_plan");
  if (text_warning != text_cells_warned_ && !text_warning.empty()) {
    LogToStderr(kWarning, "forecast inputs: " + text_warning);
  }
  text_cells_warned_ = text_warning;
  UpdateForecastStats(history, request);
  BandedForecast banded;
  if (!MakeBandedForecast(config_.plant, spec_, params_, history, weather, plan, request,
                          forecast_stats_, &banded, &error)) {
    LogToStderr(kWarning, "no forecast issued: " + error);
    return;
  }
  Forecast& forecast = banded.forecast;
  if (weather.size() > 0 && !store_->ReadWeatherSources(request.issued_at_s, horizon_end,
                                                        &forecast.inputs.weather_sources, &error)) {
    LogToStderr(kWarning, "the weather_forecast sources could not be read: " + error);
  }
  std::vector<Store::ForecastRow> rows(forecast.rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    Store::ForecastRow& r = rows[i];
    r.ts = forecast.rows.time_s[i];
    r.p_el_w = forecast.rows[Channel::kPElW][i];
    r.q_th_w = forecast.rows[Channel::kQThW][i];
    r.t_pv_c = forecast.rows[Channel::kTPvC][i];
    r.t_out_c = forecast.rows[Channel::kTOutC][i];
    r.p_el_w_p10 = banded.bands.p_el_p10[i];
    r.p_el_w_p90 = banded.bands.p_el_p90[i];
    r.q_th_w_p10 = banded.bands.q_th_p10[i];
    r.q_th_w_p90 = banded.bands.q_th_p90[i];
    r.p_el_w_p50 = banded.bands.p_el_p50[i];
    r.q_th_w_p50 = banded.bands.q_th_p50[i];
    r.p_el_w_ref = forecast.reference[Channel::kPElW][i];
    r.q_th_w_ref = forecast.reference[Channel::kQThW][i];
  }
  const std::string inputs = banded.Inputs();
  if (!store_->InsertForecast(request.issued_at_s, params_id_, inputs, rows, &error)) {
    LogToStderr(kErr, "writing the forecast failed: " + error);
    return;
  }
  ++status_.forecasts;
  status_.last_forecast_rows = rows.size();
  LogToStderr(kInfo, "forecast issued at " + FormatIsoUtc(request.issued_at_s) + ": " +
                         std::to_string(rows.size()) + " rows, calibration " +
                         std::to_string(params_id_) + "; " + inputs);
}

void Service::UpdateForecastStats(const Series& history, const ForecastRequest& request) {
  const std::int64_t day = request.issued_at_s - ((request.issued_at_s % kDayS) + kDayS) % kDayS;
  if (request.issued_at_s == forecast_stats_issued_at_ && params_id_ == forecast_stats_params_id_) {
    return;
  }
  forecast_stats_issued_at_ = request.issued_at_s;
  forecast_stats_params_id_ = params_id_;
  Series past_weather;
  std::string error;
  if (!store_->ReadWeatherForecast(history.size() ? history.time_s.front() : day, day + kDayS,
                                   &past_weather, &error) ||
      !ReplayWindow(config_.plant, spec_, params_, history, past_weather, request, &forecast_stats_,
                    &error)) {
    // Forecasts go on without bands and with the typical day until the
    // next day or calibration tries again.
    forecast_stats_ = ForecastWindowStats{};
    LogToStderr(kWarning,
                "the forecast's window could not be replayed (forecasts without bands until the "
                "next day or calibration): " +
                    error);
    return;
  }
  LogToStderr(kInfo, forecast_stats_.operation.Describe());
}

void Service::StartUpload() {
  upload_ = std::make_unique<UploadWorker>(
      UploadSettingsFor(config_), config_.upload.interval_s,
      [](int priority, const std::string& line) { LogToStderr(priority, line); });
  upload_->Start();
}

void Service::UpdateWeatherFetch() {
  WeatherFetchSettings settings;
  settings.store_path = config_.storage.path;
  settings.plant = config_.plant;
  settings.url = config_.forecast.weather_url.empty()
                     ? ""
                     : ExpandWeatherUrl(config_.forecast.weather_url, config_.plant);
  settings.refresh_s = config_.forecast.weather_refresh_min * 60.0;
  settings.timeout_s = config_.forecast.weather_timeout_s;
  if (weather_ && weather_->settings().url == settings.url &&
      weather_->settings().refresh_s == settings.refresh_s &&
      weather_->settings().timeout_s == settings.timeout_s &&
      PlantKeyValues(weather_->settings().plant) == PlantKeyValues(settings.plant)) {
    return;
  }
  weather_.reset();  // stops and joins the old thread
  if (settings.url.empty()) return;
  LogToStderr(kInfo, "weather: fetching " + UrlForLogs(settings.url) + " every " +
                         Format("%.0f", config_.forecast.weather_refresh_min) + " min");
  weather_ = std::make_unique<WeatherWorker>(
      settings, [](int priority, const std::string& line) { LogToStderr(priority, line); });
  weather_->Start();
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

void Service::UpdateDeviceStatus() {
  if (!poller_) return;
  int up = 0;
  const std::vector<DeviceStats> stats = poller_->Stats();
  for (const DeviceStats& d : stats) up += d.connected ? 1 : 0;
  // The poller's state changes (a device down, back, answering with
  // exceptions, frozen) become events here, on the main thread: a busy
  // database must never hold up a poll thread.
  std::vector<std::pair<int, std::string>> changes;
  {
    std::lock_guard lock(device_events_mutex_);
    changes.swap(device_events_);
  }
  for (const auto& [priority, line] : changes) {
    std::string error;
    const char* severity = priority <= kErr ? "error" : priority <= kWarning ? "warning" : "info";
    if (!store_->InsertMonitorEvent(static_cast<std::int64_t>(Now()), "device", severity, line,
                                    &error)) {
      LogToStderr(kWarning, "recording the device event failed: " + error);
    }
  }
  status_.devices = static_cast<int>(stats.size());
  status_.devices_up = up;
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
  if (!LoadAndApplyConfig(true)) return 2;
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
  next_forecast_s_ = have_params_ ? now : INFINITY;
  next_retention_s_ = now;
  const double watchdog_s = WatchdogIntervalS();
  NotifyReady("polling " + std::to_string(config_.modbus.devices.size()) + " devices into " +
              config_.storage.path);
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
    if (options_.reload && options_.reload->exchange(false)) {
      NotifyReloading();
      LogToStderr(kInfo, "SIGHUP: reloading " + options_.config_path);
      if (!LoadAndApplyConfig(false)) {
        LogToStderr(kErr, "reload failed; the old config stays");
      } else {
        RecordPlant();
        UpdateWeatherFetch();
      }
      NotifyReady("reloaded");
    }
    if (!StoreStillAtPath()) return 1;
    StoreSamples();
    Aggregate();
    CheckCalibration();
    diagnosis_->Check(config_.diagnosis, *store_, LogToStderr);
    MaybeStartCalibration();
    // A fresh weather forecast is used at once, not at the next refresh.
    const bool fresh_weather = weather_ && weather_->TakeFresh();
    if (Now() >= next_forecast_s_ || (fresh_weather && have_params_)) IssueForecast();
    if (Now() >= next_retention_s_) {
      next_retention_s_ = Now() + kRetentionPeriodS;
      if (!store_->ApplyRetention(static_cast<std::int64_t>(Now()),
                                  config_.storage.raw_retention_days, &error))
        LogToStderr(kWarning, "retention failed (retried in an hour): " + error);
    }
    if (watchdog_s > 0 && WallNowS() >= next_watchdog_wall_s_) {
      NotifyWatchdog();
      next_watchdog_wall_s_ = WallNowS() + watchdog_s;
    }
    UpdateDeviceStatus();
    status_.now_s = Now();
    status_.calibration_id = params_id_;
    if (options_.on_tick && !options_.on_tick(status_)) break;
  }
  Shutdown();
  return 0;
}

}  // namespace

int RunService(const ServiceOptions& options) {
  Service service(options);
  return service.Run();
}

}  // namespace pvtwin
