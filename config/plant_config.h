// The pvtwin configuration file (TOML): schema, parser and validator.
//
// Sections (doc/contracts.md, "Plant section" and "Daemon sections"):
//   [plant]        required; the collector field (core/plant.h). Required keys:
//                  latitude_deg, longitude_deg, tilt_deg, azimuth_deg, area_m2;
//                  the others default to the values of core/plant.h.
//                  Extensions: elevation_m (default 0), collector_height_m
//                  (default 10, the height a forecast's wind is brought to), sky =
//                  "auto" | "measured" | "estimated" (where the sky temperature
//                  comes from, default auto: the long-wave channel unless it is
//                  implausible).
//   [storage]      path, raw_retention_days
//   [poll]         period_s
//   [calibration]  variant, window_days, step_s, at, timezone, refit_full_window
//   [forecast]     horizon_h, refresh_min, weather_url, weather_refresh_min,
//                  weather_timeout_s
//   [diagnosis]    enabled, every_days, timeout_s, keep (the nightly diagnosis)
//   [log]          status_min (the daemon's health line)
//   [monitor]      drift_days, alarm_days, datasheet_eta0, datasheet_c1_w_m2k …
//                  datasheet_c6_s_m, datasheet_kd, power_check_safety_factor
//                  (the daily checks)
//   [sim]          optional; how `pvtwin sim` operates the simulated plant:
//                  operation, pump_dt_on_k, pump_dt_off_k, brine_below_ambient_k,
//                  brine_min_c, brine_max_c (SimConfig). Ignored by the daemon.
//   [upload]       optional; replication of the store into a central
//                  PostgreSQL (io/fleet/upload.h): url, password_file, plant_id
//                  (required with [upload]), interval_s, batch_rows,
//                  forecast_days. The url must not hold a password.
//   [[modbus.*]]   the Modbus register map (config/modbus_config.h).
//
// Every problem is reported as one Diagnostic "file:line: key = value: rule",
// all of them in one pass and in file order. Unknown keys and sections are
// errors. Degrees in the file become radians in Plant.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

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
  // After a fit passes the held-out check, fit again on the whole window
  // (held-out days included) and forecast with that.
  bool refit_full_window = true;
};

struct ForecastConfig {
  double horizon_h = 24;    // forecast length, (0, 168]
  double refresh_min = 60;  // re-issue period, [1, 1440]
  // Weather forecast fetched by the daemon (issue 15): a URL template of an
  // Open-Meteo-compatible server (ExpandWeatherUrl); empty = no fetch.
  std::string weather_url;
  double weather_refresh_min = 60;  // fetch period, [5, 1440]
  double weather_timeout_s = 30;    // connect + transfer limit of one fetch, [1, 600]
};

// [diagnosis]: the daemon's diagnosis of the sim-to-real gap, run after a
// calibration on its window (core/diagnosis.h), in a child process.
struct DiagnosisConfig {
  bool enabled = true;
  int every_days = 7;       // [1, 365]: at most one diagnosis per this many days
                            // (after a performance alarm: nightly on the days since)
  double timeout_s = 1800;  // [1, 86400]: the child is stopped after this
  int keep = 10;            // [1, 1000] HTML reports kept in <state dir>/reports
};

// [log]: what the daemon says about itself while it runs.
struct LogConfig {
  // Minutes of the daemon's clock between two health lines (samples per
  // device, devices up, last calibration and forecast; also systemd's
  // STATUS=), [0, 1440]; 0 = none.
  int status_min = 15;
};

// [monitor]: what the daemon checks day by day (core/monitoring.h).
struct MonitorConfig {
  int drift_days = 28;  // [2, 365]: accepted calibrations of this many days for the drift check
  int alarm_days = 3;   // [1, 60]: fewest scored days of a CUSUM alarm (core/monitor/index_band.h)
  // The collector's datasheet (ISO 9806) for the nightly power check
  // (core/monitoring.h); datasheet_eta0 = 0 (default): no check.
  double datasheet_eta0 = 0.0;             // [0, 1]
  double datasheet_c1_w_m2k = 0.0;         // [0, 100]
  double datasheet_c2_w_m2k2 = 0.0;        // [0, 1]
  double datasheet_c3_j_m3k = 0.0;         // [0, 100]
  double datasheet_c4 = 0.0;               // [0, 1]
  double datasheet_c5_j_m2k = 0.0;         // [0, 1e6]
  double datasheet_c6_s_m = 0.0;           // [0, 1]
  double datasheet_kd = 1.0;               // [0, 1.5]
  double power_check_safety_factor = 0.9;  // (0, 1]
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

// [upload]: the fleet database (doc/contracts.md "Fleet contract"). The password
// never sits in the config: it comes from password_file, from the systemd
// credential $CREDENTIALS_DIRECTORY/pgpassword, or from libpq's own
// PGPASSFILE / ~/.pgpass, in that order.
struct UploadConfig {
  bool enabled = false;       // the config has an [upload] section
  std::string url;            // postgresql:// URI or libpq key=value string, no password
  std::string password_file;  // file whose first line is the password (optional)
  std::string plant_id;       // this plant's key in every central table
  double interval_s = 60;     // seconds between upload rounds, [1, 86400]
  int batch_rows = 5000;      // rows per PostgreSQL transaction, [1, 100000]
  int forecast_days = 7;      // forecast rows kept centrally, days back from now, [1, 3650]
};

// The whole configuration. Plain values only: a loaded Config does not refer
// back to the file and is meant to be held as const.
struct Config {
  Plant plant;
  StorageConfig storage;
  PollConfig poll;
  CalibrationConfig calibration;
  ForecastConfig forecast;
  DiagnosisConfig diagnosis;
  LogConfig log;
  MonitorConfig monitor;
  SimConfig sim;
  UploadConfig upload;
  ModbusConfig modbus;
  std::string source_path;  // the file it was read from
};

// The [plant] keys with their values in the config's units (degrees), in
// the order of the config's key table (the store's plant_config), and back:
// false with *error naming the key when a required key is missing or a
// value is out of its range.
std::vector<std::pair<std::string, double>> PlantKeyValues(const Plant& plant);
bool PlantFromKeyValues(const std::vector<std::pair<std::string, double>>& values, Plant* plant,
                        std::string* error);

// Whether `configured` is another plant than the one a store recorded
// (`stored`, its plant_config; empty: a new store, no plant yet): "" when
// it is the same, else what differs, naming both values. Another site is
// more than kSameSiteM apart (over 1 km the sun's position changes by less
// than 0.01°, so within it a corrected coordinate is the same site);
// another field an area that differs by more than kSameAreaShare (the
// rounding of a nameplate area).
inline constexpr double kSameSiteM = 1000.0;
inline constexpr double kSameAreaShare = 0.01;
std::string PlantMismatch(const Plant& configured,
                          const std::vector<std::pair<std::string, double>>& stored);

// [forecast] weather_url: an http:// or https:// URL whose placeholders are
// {lat}, {lon} (degrees, north and east positive), {tilt} (degrees from
// horizontal), {azimuth} (degrees from north, clockwise: pvtwin's),
// {om_azimuth} (Open-Meteo's: degrees from south, west positive, = azimuth
// − 180) and {elevation} (m). False with *error for another scheme, an
// unknown or unclosed placeholder.
bool CheckWeatherUrlTemplate(const std::string& url, std::string* error);
// The URL with the plant's values in place of the placeholders.
std::string ExpandWeatherUrl(const std::string& url, const Plant& plant);

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
