#include "daemon/service/monitor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/monitor/monitoring.h"
#include "daemon/service/window_data.h"
#include "io/platform/log.h"
#include "io/files/params_json.h"
#include "io/platform/time_format.h"

namespace pvtwin::cli {

namespace {

constexpr std::int64_t kDayS = 86400;

using LogLines = std::vector<std::pair<int, std::string>>;

std::string Fixed(double x, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, x);
  return buf;
}

std::string Day(std::int64_t t) { return FormatIsoUtc(t).substr(0, 10); }

// performance_daily for every whole UTC day of the calibration window that
// has no row yet, with the accepted parameters. Returns the newest day it
// scored (-1: none).
std::int64_t ScoreNewDays(Store& store, const DailyCheckInputs& in, const Series& minutes,
                          const Store::CalibrationRow& cal, const ParamVector& params,
                          LogLines* log) {
  std::int64_t newest = -1;
  const std::int64_t today = in.now_s / kDayS * kDayS;
  const std::int64_t first = today - in.config->calibration.window_days * kDayS;
  std::string error;
  std::vector<DayPerformance> done;
  if (!store.ReadPerformanceDays(first, today, &done, &error)) {
    log->push_back({kErr, "daily checks: " + error});
    return newest;
  }
  PerformanceOptions options;
  options.heldout_mae_p_el_w = cal.mae_p_el_w;
  options.heldout_mae_q_th_w = cal.mae_q_th_w;
  std::size_t k = 0;
  for (std::int64_t day = first; day < today; day += kDayS) {
    while (k < done.size() && done[k].day_start_s < day) ++k;
    if (k < done.size() && done[k].day_start_s == day) continue;
    const Series rows = minutes.Between(day, day + kDayS);
    if (rows.size() == 0) continue;
    DayPerformance p;
    if (!ScoreDay(rows, day, in.config->plant, in.spec, params, options, &p, &error)) {
      log->push_back({kWarning, "performance of " + Day(day) + " not scored: " + error});
      continue;
    }
    if (!store.WritePerformanceDay(p, cal.id, &error)) {
      log->push_back({kErr, "daily checks: " + error});
      return newest;
    }
    newest = day;
  }
  return newest;
}

// An alarm when the newest scored days lie below their band alarm_days in a
// row, raised on each night that adds a day to the run (newest_scored: the
// newest day scored this night).
void CheckPerformanceAlarm(Store& store, const DailyCheckInputs& in, std::int64_t newest_scored,
                           LogLines* log) {
  const int alarm_days = in.config->monitor.alarm_days;
  const std::int64_t today = in.now_s / kDayS * kDayS;
  std::vector<DayPerformance> days;
  std::string error;
  if (!store.ReadPerformanceDays(today - 3 * alarm_days * kDayS - 14 * kDayS, today, &days,
                                 &error)) {
    log->push_back({kErr, "daily checks: " + error});
    return;
  }
  for (const bool thermal : {false, true}) {
    const int run = DaysBelowBand(days, thermal);
    if (run < alarm_days) continue;
    const DayPerformance* last = nullptr;
    for (auto it = days.rbegin(); it != days.rend() && last == nullptr; ++it) {
      if (thermal ? it->scored_th : it->scored_el) last = &*it;
    }
    if (last->day_start_s != newest_scored) continue;  // raised on the night it was scored
    const double pi = thermal ? last->pi_th : last->pi_el;
    const double high = thermal ? last->pi_th_high : last->pi_el_high;
    const std::string message = std::string(thermal ? "heat" : "electricity") +
                                " below the calibrated model on " + std::to_string(run) +
                                " days in a row: on " + Day(last->day_start_s) +
                                " pi = " + Fixed(pi, 3) + ", at most " + Fixed(high, 3) +
                                " with the model's held-out error";
    if (!store.InsertMonitorEvent(in.now_s, thermal ? "performance_low_th" : "performance_low_el",
                                  "warning", message, &error)) {
      log->push_back({kErr, "daily checks: " + error});
    }
    log->push_back({kWarning, message});
  }
}

// Sensor faults of the last two days (a fault that goes on is recorded again
// with its later end).
void CheckSensors(Store& store, const DailyCheckInputs& in, const Series& window, LogLines* log) {
  std::string error;
  Series recent = window.Between(in.now_s - 2 * kDayS, in.now_s);
  // A channel without a value in these days is absent, as the store reads it.
  for (std::vector<double>& column : recent.columns) {
    if (std::all_of(column.begin(), column.end(), [](double v) { return std::isnan(v); })) {
      column.clear();
    }
  }
  const std::vector<SensorFault> faults = FindSensorFaults(recent, in.config->plant);
  if (!store.RecordSensorFaults(faults, &error)) {
    log->push_back({kErr, "daily checks: " + error});
    return;
  }
  for (const SensorFault& f : faults) {
    log->push_back({kWarning, "sensor " + f.channel + ": " + f.kind + " from " +
                                  FormatIsoUtc(f.start_s) + " (" + f.detail + ")"});
  }
}

// Drift of each parameter over the accepted calibrations of drift_days.
void CheckDrift(Store& store, const DailyCheckInputs& in, const Store::CalibrationRow& cal,
                LogLines* log) {
  std::map<std::string, std::vector<ParameterPoint>> history;
  std::string error;
  const std::int64_t since = in.now_s - in.config->monitor.drift_days * kDayS;
  if (!store.ReadAcceptedParameters(since, &history, &error)) {
    log->push_back({kErr, "daily checks: " + error});
    return;
  }
  for (const auto& [name, points] : history) {
    const std::optional<ParameterDrift> drift = DetectDrift(points);
    if (!drift) continue;
    const std::string message =
        name + " drifted from " + Fixed(drift->first, 4) + " to " + Fixed(drift->last, 4) + " (" +
        (drift->change > 0 ? "+" : "") + Fixed(drift->change, 4) + ", more than twice its " +
        "standard error " + Fixed(drift->combined_se, 4) + ") over " +
        std::to_string(drift->calibrations) + " accepted calibrations since " + Day(since) +
        " (last: calibration " + std::to_string(cal.id) + ")";
    if (!store.InsertMonitorEvent(in.now_s, "parameter_drift", "warning", message, &error)) {
      log->push_back({kErr, "daily checks: " + error});
    }
    log->push_back({kWarning, message});
  }
}

// The datasheet's power check over the calibration window; an event when
// its outcome differs from the last one recorded (pass: info, fail: warning).
void CheckDatasheetPower(Store& store, const DailyCheckInputs& in, const Series& window,
                         LogLines* log) {
  const MonitorConfig& m = in.config->monitor;
  if (!(m.datasheet_eta0 > 0.0)) return;
  std::string error;
  const Series minutes =
      window.Between(in.now_s - in.config->calibration.window_days * kDayS, in.now_s);
  CollectorDatasheet d;
  d.eta0 = m.datasheet_eta0;
  d.c1_w_m2k = m.datasheet_c1_w_m2k;
  d.c2_w_m2k2 = m.datasheet_c2_w_m2k2;
  d.c3_j_m3k = m.datasheet_c3_j_m3k;
  d.c4 = m.datasheet_c4;
  d.c5_j_m2k = m.datasheet_c5_j_m2k;
  d.c6_s_m = m.datasheet_c6_s_m;
  d.kd = m.datasheet_kd;
  PowerCheckOptions options;
  options.safety_factor = m.power_check_safety_factor;
  const PowerCheckResult r = CheckPowerAgainstDatasheet(minutes, in.config->plant, d, options);
  if (!r.enough) {
    log->push_back({kInfo, "datasheet power check: " + std::to_string(r.intervals) + " of " +
                               std::to_string(options.min_intervals) +
                               " hours needed pass its filters in the window; no verdict"});
    return;
  }
  const std::string message = "datasheet power check over " + std::to_string(r.intervals) +
                              " hours: measured " + Fixed(r.measured_w_m2, 1) +
                              " W/m², datasheet " + Fixed(r.estimated_w_m2, 1) + " W/m², ratio " +
                              Fixed(r.ratio, 3) + (r.pass ? " ≥ " : " < ") +
                              Fixed(options.safety_factor, 2) + (r.pass ? ": passed" : ": failed");
  const std::string severity = r.pass ? "info" : "warning";
  log->push_back({r.pass ? kInfo : kWarning, message});
  std::string last;
  bool found = false;
  if (!store.LatestMonitorEventSeverity("power_check", &last, &found, &error)) {
    log->push_back({kErr, "daily checks: " + error});
    return;
  }
  if (found && last == severity) return;  // no change
  if (!store.InsertMonitorEvent(in.now_s, "power_check", severity, message, &error)) {
    log->push_back({kErr, "daily checks: " + error});
  }
}

}  // namespace

std::vector<std::pair<int, std::string>> RunDailyChecks(Store& store, const DailyCheckInputs& in) {
  LogLines log;
  // One read for every check: from the first day of the calibration window
  // up to now, its 1-min rows or without them its interval rows at their
  // step (window_data.h).
  WindowData data;
  std::string read_error;
  const std::int64_t first = in.now_s / kDayS * kDayS - in.config->calibration.window_days * kDayS;
  if (!ReadWindowData(store, first, in.now_s, &data, &read_error)) {
    log.push_back({kErr, "daily checks: " + read_error});
    return log;
  }
  const Series& window = data.rows;
  CheckSensors(store, in, window, &log);
  CheckDatasheetPower(store, in, window, &log);
  Store::CalibrationRow cal;
  bool found = false;
  std::string error;
  if (!store.LatestAcceptedCalibration(&cal, &found, &error)) {
    log.push_back({kErr, "daily checks: " + error});
    return log;
  }
  if (!found) return log;  // nothing to compare the plant with yet
  ParamsFile file;
  Diagnostics errors;
  if (!ParseParamsJson(cal.params_json, "calibration " + std::to_string(cal.id), in.config->plant,
                       &file, &errors)) {
    log.push_back({kErr, "daily checks: the parameters of calibration " + std::to_string(cal.id) +
                             " are unreadable"});
    return log;
  }
  ModelSpec spec = in.spec;
  std::string variant_error;
  ParseVariant(cal.variant, &spec, &variant_error);  // the calibration's own variant
  DailyCheckInputs with_variant = in;
  with_variant.spec = spec;
  const std::int64_t newest = ScoreNewDays(store, with_variant, window, cal, file.values, &log);
  CheckPerformanceAlarm(store, in, newest, &log);
  if (in.accepted_now) CheckDrift(store, in, cal, &log);
  return log;
}

}  // namespace pvtwin::cli
