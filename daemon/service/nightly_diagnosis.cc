#include "daemon/service/nightly_diagnosis.h"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <vector>

#include "core/common/calendar.h"
#include "core/common/clock.h"
#include "io/platform/log.h"
#include "io/platform/time_format.h"

namespace pvtwin::cli {

namespace fs = std::filesystem;

namespace {

// The first line of the child's output that starts with prefix, without it.
std::string LineAfter(const fs::path& path, const std::string& prefix) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(prefix, 0) == 0) return line.substr(prefix.size());
  }
  return "";
}

// Keeps the newest `keep` diagnosis-<date>.html (names sort by date).
void PruneReports(const fs::path& dir, int keep) {
  std::vector<fs::path> reports;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.starts_with("diagnosis-") && name.ends_with(".html")) reports.push_back(e.path());
  }
  std::sort(reports.begin(), reports.end());
  for (std::size_t k = 0; k + static_cast<std::size_t>(keep) < reports.size(); ++k) {
    fs::remove(reports[k], ec);
  }
}

// The local solar midnight nearest t_s (calendar.h).
std::int64_t NearestSolarMidnight(std::int64_t t_s, std::int64_t solar_offset_s) {
  return SolarDayStartS(t_s + kSecondsPerDay / 2, solar_offset_s);
}

// The first minute from t_s on with the sun above the horizon (t_s + a day
// when it stays down: polar night).
std::int64_t FirstSunlight(std::int64_t t_s, SolarPositionInput site) {
  for (std::int64_t t = t_s; t < t_s + kSecondsPerDay; t += 60) {
    site.time_s = static_cast<double>(t);
    if (ComputeSolarPosition(site).elevation_rad > 0.0) return t;
  }
  return t_s + kSecondsPerDay;
}

}  // namespace

NightlyDiagnosis::Plan NightlyDiagnosis::PlanFor(const DiagnosisConfig& config,
                                                 const Store::DiagnosisRow* last, const Job& job) {
  Plan plan;
  plan.window_start = NearestSolarMidnight(job.window_start, job.solar_offset_s);
  plan.window_end = NearestSolarMidnight(job.window_end, job.solar_offset_s);
  const std::int64_t change_from = NearestSolarMidnight(job.change_from, job.solar_offset_s);
  if (job.change_from > 0 && change_from > plan.window_start &&
      plan.window_end - change_from >= 2 * kSecondsPerDay) {
    plan.window_start = change_from;
    plan.why = "the days since the plant changed on " +
               FormatIsoUtc(job.change_from).substr(0, 10) +
               " (the performance alarm's change point)";
    plan.start = true;
    plan.since_change = true;
    return plan;
  }
  // An hour's slack: the nightly runs drift by the calibration's runtime.
  plan.start = last == nullptr || job.now_s - last->run_at >= config.every_days * kSecondsPerDay - 3600;
  return plan;
}

bool NightlyDiagnosis::CalibrationBeforeChange(Store& store, const Plan& plan, const Job& job,
                                               Store::CalibrationRow* row, bool* found,
                                               std::string* error) {
  *found = false;
  if (!plan.since_change) return true;
  return store.LatestAcceptedCalibrationBefore(FirstSunlight(plan.window_start, job.site), row,
                                               found, error);
}

void NightlyDiagnosis::MaybeStart(const DiagnosisConfig& config, Store& store, const Job& job,
                                  const LogFn& log) {
  if (!config.enabled || child_.running() || job.calibration_id <= 0) return;
  Store::DiagnosisRow last;
  bool found = false;
  std::string error;
  if (!store.LatestDiagnosis(&last, &found, &error)) {
    log(kErr, "diagnosis not started: " + error);
    return;
  }
  const Plan plan = PlanFor(config, found ? &last : nullptr, job);
  if (!plan.start) return;
  Store::CalibrationRow before;
  bool have_before = false;
  if (!CalibrationBeforeChange(store, plan, job, &before, &have_before, &error)) {
    log(kErr, "diagnosis not started: " + error);
    return;
  }
  const fs::path work = state_dir_ / "diagnosis";
  std::error_code ec;
  fs::remove_all(work, ec);
  fs::create_directories(work, ec);
  std::vector<std::string> argv = {job.exe,
                                   "diagnose",
                                   "--config",
                                   job.config_path,
                                   "--db",
                                   job.db_path,
                                   "--variant",
                                   job.variant,
                                   "--from",
                                   std::to_string(plan.window_start),
                                   "--to",
                                   std::to_string(plan.window_end),
                                   "--record",
                                   "--calibration-id",
                                   std::to_string(job.calibration_id),
                                   "--run-at",
                                   std::to_string(job.now_s),
                                   "--step",
                                   job.step_s,
                                   "--threads",
                                   "1",
                                   "--report",
                                   (work / "report").string(),
                                   "--parent-pid",
                                   std::to_string(::getpid())};
  std::string against;
  if (have_before) {
    argv.insert(argv.end(), {"--against-calibration", std::to_string(before.id)});
    against = ", against calibration " + std::to_string(before.id) + " (window to " +
              FormatIsoUtc(before.window_end) + "), the plant before it";
  } else if (plan.since_change) {
    against = ", the base re-fitted on them (no accepted calibration ends before the change)";
  }
  if (plan.since_change && (job.change_outputs == "p_el" || job.change_outputs == "q_th")) {
    argv.insert(argv.end(), {"--objective", job.change_outputs});
    against += std::string(", judged on ") + (job.change_outputs == "p_el" ? "P_el" : "Q_u") +
               ", the output whose alarm dated the change";
  }
  if (!child_.Start(argv, (work / "diagnose.log").string(), &error)) {
    Event(store, "diagnosis_failed", "diagnosis not started: " + error, log);
    return;
  }
  started_wall_s_ = WallNowS();
  job_now_s_ = job.now_s;
  log(kInfo, "diagnosis of " + job.variant + " started on " + FormatIsoUtc(plan.window_start) +
                 " .. " + FormatIsoUtc(plan.window_end) +
                 (plan.why.empty() ? std::string() : ": " + plan.why) + against);
}

void NightlyDiagnosis::Check(const DiagnosisConfig& config, Store& store, const LogFn& log) {
  if (!child_.running()) return;
  int exit_code = 0;
  if (child_.Finished(&exit_code)) {
    Finish(exit_code, config, store, log);
    return;
  }
  const double ran_s = WallNowS() - started_wall_s_;
  if (ran_s > config.timeout_s) {
    child_.Kill();
    Event(store, "diagnosis_timeout",
          "diagnosis stopped after " + std::to_string(static_cast<long>(ran_s)) +
              " s ([diagnosis] "
              "timeout_s = " +
              std::to_string(static_cast<long>(config.timeout_s)) + ")",
          log);
  }
}

void NightlyDiagnosis::Finish(int exit_code, const DiagnosisConfig& config, Store& store,
                              const LogFn& log) {
  const fs::path work = state_dir_ / "diagnosis";
  if (exit_code != 0) {
    Event(store, "diagnosis_failed",
          "diagnosis " +
              (exit_code < 0 ? "ended by signal " + std::to_string(-exit_code)
                             : "exited with " + std::to_string(exit_code)) +
              ": " + LastOutputLine((work / "diagnose.log").string()),
          log);
    return;
  }
  const fs::path reports = state_dir_ / "reports";
  std::error_code ec;
  fs::create_directories(reports, ec);
  const fs::path kept = reports / ("diagnosis-" + FormatIsoUtc(job_now_s_).substr(0, 10) + ".html");
  fs::copy_file(work / "report" / "report.html", kept, fs::copy_options::overwrite_existing, ec);
  if (ec) log(kWarning, "diagnosis report not kept: " + kept.string() + ": " + ec.message());
  PruneReports(reports, config.keep);
  const std::string verdict = LineAfter(work / "diagnose.log", "verdict: ");
  log(verdict == "none" ? kInfo : kWarning, "diagnosis: verdict " +
                                                (verdict.empty() ? std::string("?") : verdict) +
                                                "; report " + kept.string());
}

void NightlyDiagnosis::Event(Store& store, const std::string& kind, const std::string& message,
                             const LogFn& log) {
  log(kWarning, message);
  std::string error;
  if (!store.InsertMonitorEvent(job_now_s_, kind, "warning", message, &error)) {
    log(kErr, "recording the event failed: " + error);
  }
}

void NightlyDiagnosis::Stop() {
  if (child_.running()) child_.Kill();
}

}  // namespace pvtwin::cli
