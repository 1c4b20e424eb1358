// The calibration job of the Service (service_internal.h): the nightly
// `pvtwin calibrate` child on the training days, the held-out check
// (calibration_acceptance.h), the refit on the whole window, and the
// calibration rows.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>

#include "core/fit/identification.h"
#include "core/model/thermal_model.h"
#include "daemon/service/calibration_fit.h"
#include "daemon/service/notify.h"
#include "daemon/service/service_internal.h"
#include "daemon/service/window_data.h"
#include "io/files/csv.h"
#include "io/files/params_json.h"
#include "io/platform/local_time.h"
#include "io/platform/log.h"
#include "io/platform/time_format.h"

namespace pvtwin::service_detail {

namespace {

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

// The parameters of calibrate's fit as calibration_param rows.
std::vector<Store::CalibrationParamRow> ParamRowsOf(const CalibrationFit& fit) {
  std::vector<Store::CalibrationParamRow> rows;
  for (const FitParameter& p : fit.parameters) {
    Store::CalibrationParamRow row;
    row.name = p.name;
    row.value = p.value;
    row.std_error = p.std_error;
    row.unit = p.unit;
    row.status = p.status;
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace

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
  last_calibration_ = {row.id, "accepted", static_cast<double>(row.run_at)};
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
  // Its 1-min rows, or without them its interval rows at their own step.
  cli::WindowData data;
  std::string error;
  if (!cli::ReadWindowData(*store_, begin, end, &data, &error)) {
    row.status = "failed";
    row.reason = "reading the window failed: " + error;
    RecordCalibration(row);
    return;
  }
  const Series& window = data.rows;
  const std::int64_t span = window.size() ? window.time_s.back() - window.time_s.front() : 0;
  const std::int64_t min_span_s = 2 * kDayS - static_cast<std::int64_t>(2 * window.step_s);
  if (span < min_span_s && !have_params_) {
    RecordWaitForHistory(row, span);
    return;
  }
  if (span < min_span_s) {
    row.status = "skipped";
    row.reason = "window holds " + Format("%.1f", span / 86400.0) + " days of " +
                 (data.source == cli::WindowSource::kIntervals ? data.Describe()
                                                               : std::string("1-min data")) +
                 "; two are needed (training days and a held-out day)";
    RecordCalibration(row);
    return;
  }
  // Held out: the last days, as many as it takes (up to 3) to hold two hours
  // with the pump running in sunshine; an overcast pump-off day cannot tell
  // two parameter sets apart.
  const auto two_hours_rows = static_cast<std::size_t>(std::lround(7200.0 / window.step_s));
  const cli::HeldOutChoice held_out = cli::ChooseHeldOutDays(window, end, 3, two_hours_rows);
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
                         " .. " + FormatIsoUtc(end) + " (" + data.Describe() + ", " +
                         HeldOutText() + ")");
}

bool Service::WriteConfigInUse(std::string* path, std::string* error) {
  const fs::path file = fs::path(config_.storage.path).parent_path() / "config-in-use.toml";
  if (!WriteTextFileAtomically(file.string(), config_text_, error)) return false;
  *path = file.string();
  return true;
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
  std::string config_path;
  if (!WriteConfigInUse(&config_path, error)) return false;
  std::vector<std::string> argv = {
      options_.exe_path.empty() ? SelfExecutable() : options_.exe_path,
      "calibrate",
      "--config",
      config_path,
      "--csv",
      csv.string(),
      "--variant",
      spec_.Name(),
      "--step",
      Format("%.0f", cli::StepForData(config_.calibration.step_s, data.step_s)),
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
  CalibrationFit fit;
  CalibrationFit::FromParamsJson(text, &fit);  // parsed above: an object
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
  CalibrationFit fit;
  CalibrationFit::FromParamsJson(text, &fit);  // parsed above: an object
  row.n_evals = fit.simulations;
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
  const double tolerance_w_m2 =
      current ? cli::HeldOutDifferenceSe(job_test_, config_.plant, spec_, file.values, params_)
              : 0.0;
  const cli::AcceptanceDecision decision = cli::DecideCalibration(
      fresh->objective_w_m2(),
      current ? std::optional<double>(current->objective_w_m2()) : std::nullopt, fit.at_bounds,
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

std::int64_t Service::RecordCalibration(Store::CalibrationRow row, int priority) {
  std::string error;
  if (!store_->InsertCalibration(&row, &error)) {
    LogToStderr(kErr, "recording the calibration failed: " + error);
    row.id = 0;
  }
  status_.calibrating = false;
  ++status_.calibrations;
  status_.last_calibration = row.status + ": " + row.reason;
  last_calibration_ = {row.id, row.status, static_cast<double>(row.run_at)};
  if (priority < 0) priority = row.status == "accepted" ? kNotice : kWarning;
  LogToStderr(priority,
              "calibration " + std::to_string(row.id) + " " + row.status + ": " + row.reason);
  if (row.accepted && row.id > 0) SetState("calibration " + std::to_string(row.id) + " in use");
  return row.id;
}

void Service::RecordWaitForHistory(Store::CalibrationRow row, std::int64_t span_s) {
  const double now = Now();
  const std::string state =
      "waiting for history: " + Format("%.1f", static_cast<double>(span_s) / 3600.0) + " h of 48 h";
  row.status = "skipped";
  row.reason = state + " (two days of 1-min data are needed: training days and a held-out day)";
  RecordCalibration(row, kDebug);
  next_calibration_s_ = std::min(next_calibration_s_, now + kUncalibratedRetryS);
  SetState(state);
  if (waiting_announced_) return;
  waiting_announced_ = true;
  const std::string line =
      state +
      "; forecasts from the start values (basis = 'start_values') until the first "
      "calibration";
  LogToStderr(kInfo, line);
  std::string error;
  if (!store_->InsertMonitorEvent(static_cast<std::int64_t>(now), "calibration_waiting", "info",
                                  line, &error)) {
    LogToStderr(kWarning, "recording the wait for history failed: " + error);
  }
}

void Service::SetState(const std::string& state) {
  if (state == status_.state) return;
  status_.state = state;
  NotifyStatus(state);
}

}  // namespace pvtwin::service_detail
