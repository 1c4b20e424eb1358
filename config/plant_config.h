// The pvtwin configuration file (TOML): schema, parser and validator.
//
// Sections (DESIGN.md, "Plant section" and "Daemon sections"):
//   [plant]        required; the collector field (core/plant.h). Required keys:
//                  latitude_deg, longitude_deg, tilt_deg, azimuth_deg, area_m2;
//                  the others default to the values of core/plant.h.
//                  Extension: elevation_m (default 0).
//   [storage]      path, raw_retention_days
//   [poll]         period_s
//   [calibration]  variant, window_days, step_s, at, timezone
//   [forecast]     horizon_h, refresh_min
//   [sim]          optional; how `pvtwin sim` operates the simulated plant:
//                  operation, pump_dt_on_k, pump_dt_off_k, brine_below_ambient_k,
//                  brine_min_c, brine_max_c (SimConfig). Ignored by the daemon.
//   [[modbus.*]]   the Modbus register map (config/modbus_config.h).
//
// Every problem is reported as one Diagnostic "file:line: key = value: rule",
// all of them in one pass and in file order. Unknown keys and sections are
// errors. Degrees in the file become radians in Plant.
#pragma once

#include <string>
#include <string_view>

#include "config/modbus_config.h"
#include "core/common/diagnostic.h"
#include "core/common/plant.h"

namespace pvtwin {

struct StorageConfig {
  std::string path = "/var/lib/pvtwin/pvtwin.db";  // SQLite file
  int raw_retention_days = 30;                     // days of sample_5s kept, [1, 3650]
};

struct PollConfig {
  double period_s = 5;  // Modbus poll period: whole seconds in [1, 60] dividing 60
};

struct CalibrationConfig {
  std::string variant = "2N1Ccolwr";       // model variant (grammar checked by the model layer)
  int window_days = 14;                    // identification window, 1..60 days
  double step_s = 60;                      // model step: whole seconds in [5, 900] dividing 86400
  std::string at = "02:00";                // local time of the nightly run, HH:MM
  std::string timezone = "Europe/Vienna";  // IANA zone that `at` refers to
};

struct ForecastConfig {
  double horizon_h = 24;    // forecast length, (0, 168]
  double refresh_min = 60;  // re-issue period, [1, 1440]
};

// [sim]: the simulated plant's solar loop (core/weather_generator.h,
// PumpControl). Defaults are WeatherOptions' defaults.
struct SimConfig {
  std::string operation = "irradiance";  // irradiance | differential | heat_pump
  double pump_dt_on_k = 5.0;             // (0, 30], > pump_dt_off_k
  double pump_dt_off_k = 2.0;            // [0, 30]
  double brine_below_ambient_k = 5.0;    // [0, 30]
  double brine_min_c = 0.0;              // [-20, 30], ≤ brine_max_c
  double brine_max_c = 10.0;             // [-20, 30]
};

// The whole configuration. Plain values only: a loaded Config does not refer
// back to the file and is meant to be held as const.
struct Config {
  Plant plant;
  StorageConfig storage;
  PollConfig poll;
  CalibrationConfig calibration;
  ForecastConfig forecast;
  SimConfig sim;
  ModbusConfig modbus;
  std::string source_path;  // the file it was read from
};

// "HH:MM" (00:00 … 23:59) → hour, minute; false otherwise.
bool ParseClockTime(std::string_view text, int* hour, int* minute);

// True if `iana` names a zone of the system's tz database (TZDIR or
// /usr/share/zoneinfo), e.g. "Europe/Vienna" or "UTC".
bool TimeZoneExists(const std::string& iana);

// Reads and validates the whole file. Returns true when there is no error;
// every problem found is appended to *errors (all at once, in file order).
// *out is written only on success. errors must not be null.
bool LoadConfig(const std::string& path, Config* out, Diagnostics* errors);

// As LoadConfig, for text already in memory; diagnostics and
// Config::source_path use path_for_messages.
bool ParseConfig(std::string_view toml_text, const std::string& path_for_messages, Config* out,
                 Diagnostics* errors);

}  // namespace pvtwin
