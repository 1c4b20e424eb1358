// The long-running job (`pvtwin run`, and `pvtwin demo` in-process):
//
//   config ─► store ─► poller ─► loop { store samples, aggregate minutes,
//                                       nightly calibration (child process),
//                                       forecasts, retention, watchdog }
//
// Modules start in that order and stop in reverse. One loop on one thread
// runs every timed job; the poller delivers samples from its own threads
// through a queue; the calibration runs as a `pvtwin calibrate` child
// process with a time limit. Runtime faults (a device down, SQLITE_BUSY, a
// failed fit) are logged once per change of state and re-armed; the daemon
// keeps the last accepted parameters.
//
// Calibration (doc/contracts.md "The job"): at [calibration] at, local time in
// [calibration] timezone (io/platform/local_time.h), the last window_days of 1-min
// rows are split into training days and the most recent day, held out. The
// variant is fitted on the training days (warm-started from the current
// parameters); the new parameters replace the current ones only if their
// held-out error (MAE P_el + MAE Q_u, the paper's objective) is at most the
// current parameters' on the same day. Every attempt is a `calibration` row.
// A daemon without accepted parameters calibrates as soon as it has two days
// of data instead of waiting for the night; until then it forecasts from the
// start values (core/forecast/start_value_forecast.h, basis 'start_values')
// and the wait is a state ("waiting for history: 3.2 h of 48 h"), logged once.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

namespace pvtwin {

// What the loop has done so far, for progress displays (`pvtwin demo`).
struct ServiceStatus {
  double now_s = 0.0;  // service clock (simulated under --speed)
  std::uint64_t samples_stored = 0;
  std::uint64_t minutes_aggregated = 0;
  int calibrations = 0;             // attempts finished
  bool calibrating = false;         // a calibration child is running
  std::int64_t calibration_id = 0;  // accepted parameters in use (0: none)
  std::string last_calibration;     // status line of the last attempt
  int forecasts = 0;
  std::size_t last_forecast_rows = 0;
  int devices_up = 0;
  int devices = 0;
  // The daemon's state as the systemd status line shows it (sd_notify
  // STATUS=): "waiting for history: 3.2 h of 48 h" before the first
  // calibration, then "calibration 7 in use".
  std::string state;
};

struct ServiceOptions {
  std::string config_path;
  std::string db_path;  // overrides [storage] path when not empty
  // Clock (core/clock.h): simulated start, wall anchor (0 = now) and speed.
  // sim_start_s = 0 means real time.
  double sim_start_s = 0.0;
  double wall_anchor_s = 0.0;
  double speed = 1.0;
  // Wall-clock limit of one calibration child.
  double calibration_timeout_s = 1800.0;
  // Stop criterion of the optimiser for the nightly fit (calibrate --ftol):
  // the daemon has the night, so it fits to the noise floor (doc/performance.md).
  double calibration_ftol = 1e-4;
  // Calibrate at once when no accepted parameters exist and two days of data do.
  bool calibrate_when_uncalibrated = true;
  // Take over a store whose plant_config records another plant (site or
  // area, config/plant_config.h PlantMismatch); without it the daemon
  // refuses to start on it (exit 2).
  bool adopt_store = false;
  // pvtwin binary for the calibration child; empty = this executable.
  std::string exe_path;
  // Set by the signal handlers: stop (SIGTERM, SIGINT), reload (SIGHUP).
  const std::atomic<bool>* stop = nullptr;
  std::atomic<bool>* reload = nullptr;
  // Called after every loop pass; return false to stop (the demo's end).
  std::function<bool(const ServiceStatus&)> on_tick;
};

// Runs until stopped. Returns the exit code: 0 after a clean stop, 2 when
// the config is invalid or belongs to another plant than the store (before
// READY), 1 when the store cannot be opened.
int RunService(const ServiceOptions& options);

}  // namespace pvtwin
