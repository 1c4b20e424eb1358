// The diagnose job of the Service (service_internal.h): once the night's
// calibration is done, the daily checks (monitor.h) and the nightly
// diagnosis child (nightly_diagnosis.h).
#include "core/common/calendar.h"
#include "daemon/service/monitor.h"
#include "daemon/service/service_internal.h"
#include "io/platform/log.h"

namespace pvtwin::service_detail {

void Service::AfterCalibration() {
  status_.calibrating = false;
  DailyChecks(accepted_tonight_);
  MaybeStartDiagnosis();
}

void Service::MaybeStartDiagnosis() {
  // Disabled: not even the alarm's days are read.
  if (!have_params_ || !diagnosis_ || !config_.diagnosis.enabled) return;
  cli::NightlyDiagnosis::Job job;
  job.exe = options_.exe_path.empty() ? SelfExecutable() : options_.exe_path;
  std::string error;
  if (!WriteConfigInUse(&job.config_path, &error)) {
    LogToStderr(kErr, "diagnosis not started: " + error);
    return;
  }
  job.db_path = config_.storage.path;
  job.variant = spec_.Name();
  job.step_s = Format("%.0f", config_.calibration.step_s);
  job.window_start = job_.window_start;
  job.window_end = job_.window_end;
  job.calibration_id = params_id_;
  job.now_s = static_cast<std::int64_t>(Now());
  job.solar_offset_s = SolarDayOffsetS(config_.plant);
  job.site = SiteAtStandardPressure(config_.plant);
  cli::DailyCheckInputs checks;
  checks.config = &config_;
  checks.spec = spec_;
  checks.now_s = job.now_s;
  if (!cli::NewestChangeOnset(*store_, checks, &job.change_from, &error, &job.change_outputs)) {
    LogToStderr(kErr, "diagnosis: the performance alarm's days not read: " + error);
  }
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

}  // namespace pvtwin::service_detail
