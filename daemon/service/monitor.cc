#include "daemon/service/monitor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>

#include "core/monitor/index_band.h"
#include "core/monitor/monitoring.h"
#include "daemon/service/window_data.h"
#include "io/files/params_json.h"
#include "io/platform/log.h"
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

// The band and alarm rules with [monitor]'s settings (index_band.h).
IndexCusumOptions CusumOptionsOf(const Config& config) {
  IndexCusumOptions options;
  options.min_days = config.monitor.alarm_days;
  return options;
}

// The performance_daily rows a night's scoring and alarm look back on: the
// reference days of the oldest day it may score, and the CUSUM's days
// before them that decide which of them are suspect.
std::int64_t LookBackStart(const DailyCheckInputs& in, const IndexBandOptions& bands) {
  const std::int64_t today = in.now_s / kDayS * kDayS;
  return today - (in.config->calibration.window_days + 2 * bands.reference_days) * kDayS;
}

// performance_daily for every whole UTC day of the calibration window that
// has no row yet, with the accepted parameters, each day's band from the
// days before it (index_band.h). Returns the first day it scored (-1: none).
std::int64_t ScoreNewDays(Store& store, const DailyCheckInputs& in, const Series& minutes,
                          const Store::CalibrationRow& cal, const ParamVector& params,
                          LogLines* log) {
  std::int64_t first_scored = -1;
  const IndexBandOptions bands;
  const IndexCusumOptions cusum = CusumOptionsOf(*in.config);
  const std::int64_t today = in.now_s / kDayS * kDayS;
  const std::int64_t first = today - in.config->calibration.window_days * kDayS;
  std::string error;
  std::vector<DayPerformance> known;  // stored rows and the new ones, in time order
  if (!store.ReadPerformanceDays(LookBackStart(in, bands), today, &known, &error)) {
    log->push_back({kErr, "daily checks: " + error});
    return first_scored;
  }
  for (std::int64_t day = first; day < today; day += kDayS) {
    const auto at =
        std::lower_bound(known.begin(), known.end(), day,
                         [](const DayPerformance& d, std::int64_t t) { return d.day_start_s < t; });
    if (at != known.end() && at->day_start_s == day) continue;
    const Series rows = minutes.Between(day, day + kDayS);
    if (rows.size() == 0) continue;
    DayPerformance p;
    if (!ScoreDay(rows, day, in.config->plant, in.spec, params, PerformanceOptions{}, &p, &error)) {
      log->push_back({kWarning, "performance of " + Day(day) + " not scored: " + error});
      continue;
    }
    const auto earlier = static_cast<std::size_t>(at - known.begin());
    SetIndexBands(std::span<const DayPerformance>(known.data(), earlier), bands, cusum, &p);
    if (!store.WritePerformanceDay(p, cal.id, &error)) {
      log->push_back({kErr, "daily checks: " + error});
      return first_scored;
    }
    known.insert(known.begin() + static_cast<std::ptrdiff_t>(earlier), p);
    if (first_scored < 0) first_scored = day;
  }
  return first_scored;
}

// The performance alarm (index_band.h: a one-sided CUSUM of the days'
// standardised errors), raised for each day scored this night (from
// first_scored on) on which the CUSUM of an output reaches its decision
// interval.
void CheckPerformanceAlarm(Store& store, const DailyCheckInputs& in, std::int64_t first_scored,
                           LogLines* log) {
  if (first_scored < 0) return;
  const IndexCusumOptions cusum = CusumOptionsOf(*in.config);
  const std::int64_t today = in.now_s / kDayS * kDayS;
  std::vector<DayPerformance> days;
  std::string error;
  if (!store.ReadPerformanceDays(LookBackStart(in, IndexBandOptions{}), today, &days, &error)) {
    log->push_back({kErr, "daily checks: " + error});
    return;
  }
  for (const bool thermal : {false, true}) {
    for (const IndexDay& c : FollowIndex(days, thermal, IndexBandOptions{}, cusum)) {
      if (c.withheld && c.day_start_s >= first_scored) {
        log->push_back({kInfo, std::string(thermal ? "heat" : "electricity") + " of " +
                                   Day(c.day_start_s) + " not judged: its expected energy (" +
                                   Fixed(c.e_model_wh / 1000.0, 2) +
                                   " kWh) lies in a regime its reference days do not hold "
                                   "(no band, no part in the alarm)"});
      }
      if (!c.alarm || c.day_start_s < first_scored) continue;
      const std::string message =
          std::string(thermal ? "heat" : "electricity") +
          " below the calibrated model: the evidence of " + std::to_string(c.run_days) +
          " days together (CUSUM " + Fixed(c.s, 2) + " σ ≥ " + Fixed(cusum.h_sigma, 1) +
          " σ); on " + Day(c.day_start_s) + " pi = " + Fixed(c.pi, 3) + ", band " +
          Fixed(c.low, 3) + "–" + Fixed(c.high, 3) + " from the model's daily errors";
      if (!store.InsertMonitorEvent(in.now_s, thermal ? "performance_low_th" : "performance_low_el",
                                    "warning", message, &error)) {
        log->push_back({kErr, "daily checks: " + error});
      }
      log->push_back({kWarning, message});
    }
  }
}

}  // namespace

bool NewestChangeOnset(Store& store, const DailyCheckInputs& in, std::int64_t* onset_s,
                       std::string* error, std::string* outputs) {
  *onset_s = -1;
  if (outputs != nullptr) outputs->clear();
  std::vector<DayPerformance> days;
  if (!store.ReadPerformanceDays(LookBackStart(in, IndexBandOptions{}), in.now_s / kDayS * kDayS,
                                 &days, error)) {
    return false;
  }
  std::int64_t onset_el_s = -1, onset_th_s = -1;
  for (const bool thermal : {false, true}) {
    const std::vector<IndexDay> followed =
        FollowIndex(days, thermal, IndexBandOptions{}, CusumOptionsOf(*in.config));
    (thermal ? onset_th_s : onset_el_s) = ChangeOnsetS(followed);
  }
  *onset_s = std::max(onset_el_s, onset_th_s);
  if (outputs != nullptr && *onset_s >= 0) {
    // An output whose own change began earlier did not change on the days since.
    *outputs = onset_el_s == onset_th_s ? "both" : onset_el_s > onset_th_s ? "p_el" : "q_th";
  }
  return true;
}

namespace {

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

// Drift of each parameter over the accepted calibrations of drift_days
// (DetectDrift: the newest fit against the oldest a window apart, on the
// scale of the plant's own wobble). The log says each night what it finds;
// monitor_event gets a parameter's drift once, when it begins (warning), and
// once when a judged night no longer finds it (info), as the power check's
// outcome. When no parameter can be judged the log says why: a daemon
// younger than a window and two nights, or drift_days too short to hold
// fits a window apart (a warning: it never will).
void CheckDrift(Store& store, const DailyCheckInputs& in, const Store::CalibrationRow& cal,
                LogLines* log) {
  std::map<std::string, std::vector<ParameterPoint>> history;
  std::string error;
  const int drift_days = in.config->monitor.drift_days;
  const int window_days = in.config->calibration.window_days;
  const std::int64_t since = in.now_s - drift_days * kDayS;
  if (!store.ReadAcceptedParameters(since, &history, &error)) {
    log->push_back({kErr, "daily checks: " + error});
    return;
  }
  int judged = 0;
  for (const auto& [name, points] : history) {
    const ParameterDrift drift = DetectDrift(points);
    judged += drift.judged;
    if (!drift.judged) continue;
    std::string last;
    bool found = false;
    if (!store.LatestMonitorEventSeverity("parameter_drift", name + " ", &last, &found, &error)) {
      log->push_back({kErr, "daily checks: " + error});
      continue;
    }
    const bool open = found && last == "warning";
    if (!drift.drift) {
      if (!open) continue;
      const std::string message =
          name + " no longer drifts: " + Fixed(drift.last, 4) + " against " +
          Fixed(drift.first, 4) + " a window before, within " + Fixed(kDriftSigmas, 0) + " times " +
          Fixed(drift.scale, 4) + " (calibration " + std::to_string(cal.id) + ")";
      if (!store.InsertMonitorEvent(in.now_s, "parameter_drift", "info", message, &error)) {
        log->push_back({kErr, "daily checks: " + error});
      }
      log->push_back({kInfo, message});
      continue;
    }
    const std::string head = name + " drifted from " + Fixed(drift.first, 4) + " to " +
                             Fixed(drift.last, 4) + " (" + (drift.change > 0 ? "+" : "") +
                             Fixed(drift.change, 4) + ", more than " + Fixed(kDriftSigmas, 0) +
                             " times its standard error " + Fixed(drift.scale, 4);
    const std::string tail = ") over " + std::to_string(drift.calibrations) +
                             " accepted calibrations since " + Day(since) + " (last: calibration " +
                             std::to_string(cal.id) + ")";
    const std::string message = head + ": the larger of the fits' " + Fixed(drift.combined_se, 4) +
                                " and the wobble of fits a window apart " +
                                Fixed(drift.wobble_sd, 4) + " from " + std::to_string(drift.steps) +
                                " nightly steps; windows ending " + Day(drift.first_window_end_s) +
                                " and from " + Day(drift.last_window_start_s) + tail;
    if (!open &&
        !store.InsertMonitorEvent(in.now_s, "parameter_drift", "warning", message, &error)) {
      log->push_back({kErr, "daily checks: " + error});
    }
    // The event has the scale's parts; the log says it again each night.
    log->push_back({kWarning, head + tail + (open ? "; raised before, still open" : "")});
  }
  if (judged > 0 || history.empty()) return;
  const bool too_short = drift_days < window_days + 2;
  log->push_back({too_short ? kWarning : kInfo,
                  "parameter drift not judged: no two accepted fits of drift_days = " +
                      std::to_string(drift_days) + " lie a window apart (needs window_days + 2 = " +
                      std::to_string(window_days + 2) + " days of nightly fits" +
                      (too_short ? ": set drift_days >= 2 x window_days = " +
                                       std::to_string(2 * window_days) + ")"
                                 : "; the daemon's history is shorter)")});
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
  if (!store.LatestMonitorEventSeverity("power_check", "", &last, &found, &error)) {
    log->push_back({kErr, "daily checks: " + error});
    return;
  }
  if (found && last == severity) return;  // no change
  if (!store.InsertMonitorEvent(in.now_s, "power_check", severity, message, &error)) {
    log->push_back({kErr, "daily checks: " + error});
  }
}

// forecast_skill materialised for the days that ended since the last run
// and those whose measurements or scored forecasts changed (an import, a
// late forecast), so that a dashboard's reads compute only today.
void RefreshSkill(Store& store, const DailyCheckInputs& in, LogLines* log) {
  int days = 0;
  std::string error;
  if (!store.RefreshForecastSkill(in.now_s, &days, &error)) {
    log->push_back({kErr, "daily checks: " + error});
  } else if (days > 0) {
    log->push_back({kInfo, "forecast_skill materialised for " + std::to_string(days) +
                               (days == 1 ? " day" : " days")});
  }
}

}  // namespace

std::vector<std::pair<int, std::string>> RunDailyChecks(Store& store, const DailyCheckInputs& in) {
  LogLines log;
  RefreshSkill(store, in, &log);
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
  const std::int64_t first_scored =
      ScoreNewDays(store, with_variant, window, cal, file.values, &log);
  CheckPerformanceAlarm(store, in, first_scored, &log);
  if (in.accepted_now) CheckDrift(store, in, cal, &log);
  return log;
}

}  // namespace pvtwin::cli
