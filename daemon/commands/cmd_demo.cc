// pvtwin demo: the whole job on the embedded default, with nothing configured.
//
//   1. a scratch directory with the example plant and register map
//      (config/examples/sim-plant.toml, compiled in) and a SQLite file;
//   2. 14 days of history from the simulator's truth model (`pvtwin sim
//      --export`), imported as 1-min rows, up to 08:00 UTC on the latest day
//      on which the live part ends before the wall clock;
//   3. `pvtwin sim` serving the plant over Modbus TCP on loopback, and the
//      daemon loop (daemon/service/service.h) polling it, both on one accelerated
//      clock;
//   4. the daemon calibrates (it has no parameters yet), accepts the fit and
//      writes a 24 h forecast while polling goes on;
//   5. a summary and the SQL to look at the forecast.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

#include "config/config_edit.h"
#include "core/common/clock.h"
#include "core/common/units.h"
#include "core/forecast/forecast_backtest.h"
#include "core/model/variant.h"
#include "daemon/commands/commands.h"
#include "daemon/demo_config.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/service.h"
#include "io/platform/child_process.h"
#include "io/files/csv.h"
#include "io/platform/local_time.h"
#include "io/files/params_json.h"
#include "io/platform/quantity_text.h"
#include "io/store/store.h"
#include "io/platform/time_format.h"

namespace pvtwin::cli {

namespace {

// "1 forecast written", "19 forecasts written".
std::string ForecastsWritten(int n) {
  return std::to_string(n) + (n == 1 ? " forecast written" : " forecasts written");
}

namespace fs = std::filesystem;

struct DemoArgs {
  std::string db;
  std::string dir;
  double speed = 60.0;
  int live_minutes = 30;
  double max_wall_s = 110.0;
  std::string date;  // UTC day of the live part, YYYY-MM-DD; empty: the latest that fits
};

// The live part starts at 08:00 UTC: morning in Europe, sun up at the example
// plant.
constexpr std::int64_t kLiveStartOfDayS = 8 * 3600;

// The simulated seconds the live part can span at most: the daemon's clock
// runs `speed` times the wall clock for at most --max-wall seconds from the
// demo's start, then one last loop pass and the shutdown store what the
// poller still holds (allowed kLiveSlackWallS of wall time).
std::int64_t LiveSpanS(const DemoArgs& a) {
  constexpr double kLiveSlackWallS = 10.0;
  return static_cast<std::int64_t>(std::ceil((a.max_wall_s + kLiveSlackWallS) * a.speed));
}

std::string Q(const std::string& s) { return "'" + s + "'"; }

// One line on how the example plant runs its solar loop ([sim] operation).
std::string OperationSummary(const SimConfig& sim) {
  char buf[200];
  if (sim.operation == "heat_pump") {
    std::snprintf(
        buf, sizeof buf,
        "heat-pump source: brine %.0f-%.0f °C (%.0f K below ambient), pump on a %.0f/%.0f K "
        "collector-brine difference: heat gains from sun and ambient",
        sim.brine_min_c, sim.brine_max_c, sim.brine_below_ambient_k, sim.pump_dt_on_k,
        sim.pump_dt_off_k);
  } else if (sim.operation == "differential") {
    std::snprintf(buf, sizeof buf, "solar tank: pump on a %.0f/%.0f K collector-tank difference",
                  sim.pump_dt_on_k, sim.pump_dt_off_k);
  } else {
    std::snprintf(buf, sizeof buf, "pump on in-plane irradiance thresholds, crude tank at 25 °C");
  }
  return buf;
}

// The forecast at the plant's first solar noon after from_ts and the day's
// highest Q_u, from forecast_latest.
void PrintNoonForecast(Store* store, const Plant& plant, std::int64_t from_ts) {
  std::vector<Store::ForecastRow> rows;
  std::string error;
  if (!store->ReadLatestForecast(from_ts, from_ts + 2 * 86400, &rows, &error) || rows.empty())
    return;
  const double noon_utc_s = (12.0 - RadToDeg(plant.longitude_rad) / 15.0) * 3600.0;
  std::int64_t noon = from_ts / 86400 * 86400 + static_cast<std::int64_t>(noon_utc_s) / 60 * 60;
  if (noon < rows.front().ts) noon += 86400;
  const Store::ForecastRow* at_noon = nullptr;
  const Store::ForecastRow* best = nullptr;
  for (const Store::ForecastRow& r : rows) {
    if (at_noon == nullptr && r.ts >= noon) at_noon = &r;
    if (r.ts >= noon - 43200 && r.ts < noon + 43200 &&
        (best == nullptr || r.q_th_w > best->q_th_w)) {
      best = &r;
    }
  }
  if (at_noon == nullptr || best == nullptr) return;
  std::printf(
      "      forecast at solar noon (%s): P_el %.0f W (10-90 %%: %.0f-%.0f W), Q_u %.0f W "
      "(%.0f-%.0f W); that day's highest Q_u %.0f W at %s\n",
      FormatIsoUtc(at_noon->ts).c_str(), at_noon->p_el_w, at_noon->p_el_w_p10, at_noon->p_el_w_p90,
      at_noon->q_th_w, at_noon->q_th_w_p10, at_noon->q_th_w_p90, best->q_th_w,
      FormatIsoUtc(best->ts).c_str());
}

// The skill of the day-ahead forecasts: forecast_skill's days where the live
// run scored one; else the forecast as the daemon issues it (its accepted
// calibration, issued at local midnight) replayed over the last days of the
// imported history and scored like forecast_skill (core/forecast/
// forecast_backtest.h).
void PrintForecastSkill(Store* store, const Config& config, const Store::CalibrationRow& cal,
                        const Series& history) {
  std::vector<Store::SkillRow> days;
  std::string error;
  if (store->ReadForecastSkill(0, std::numeric_limits<std::int64_t>::max(), &days, &error)) {
    bool printed = false;
    for (const Store::SkillRow& d : days) {
      if (std::isnan(d.skill_p_el)) continue;
      std::printf(
          "      forecast_skill %s: skill P_el %.3f, Q_u %.3f, band coverage %.2f over %lld "
          "minutes\n",
          FormatIsoUtc(d.day).c_str(), d.skill_p_el, d.skill_q_th, d.coverage_p10_p90,
          static_cast<long long>(d.minutes));
      printed = true;
    }
    if (printed) return;
  }
  ForecastBacktestOptions options;
  ParamsFile params;
  Diagnostics errors;
  if (!ParseVariant(cal.variant, &options.spec, &error) ||
      !ParseParamsJson(cal.params_json, "calibration " + std::to_string(cal.id), config.plant,
                       &params, &errors) ||
      !UseTimeZone(config.calibration.timezone, &error) || history.size() == 0) {
    return;
  }
  options.fixed_params = true;
  options.params = params.values;
  constexpr int kDays = 3;
  // The daemon's window, as far as the history before the first test day
  // holds it: the bands learn from the window's days.
  const int history_days =
      static_cast<int>((history.time_s.back() - history.time_s.front()) / 86400) - kDays;
  options.window_days = std::clamp(config.calibration.window_days, 2, std::max(2, history_days));
  for (std::int64_t t = history.time_s.back() - (kDays + 1) * 86400;
       options.issue_times_s.size() < kDays;) {
    t = NextLocalTime(t, 0, 0);
    if (t + 86400 <= history.time_s.back() + 60) options.issue_times_s.push_back(t);
  }
  ForecastBacktestResult result;
  if (!RunForecastBacktest(history, Series{}, config.plant, options, &result, &error) ||
      result.days_ok == 0) {
    return;
  }
  std::printf(
      "      day-ahead forecasts of calibration %lld replayed over the last %d imported days "
      "(persisted weather; skill against smart persistence):\n",
      static_cast<long long>(cal.id), kDays);
  for (const ForecastBacktestDay& d : result.days) {
    if (!d.ok) continue;
    std::printf("        issued %s (%s operation): skill P_el %.3f, Q_u %.3f\n",
                FormatIsoUtc(d.issued_at_s).c_str(), d.operation.c_str(), d.p_el.skill,
                d.q_th.skill);
  }
  std::printf(
      "        all %d days: skill P_el %.3f, Q_u %.3f; the 10-90 %% band covers %.0f %% (P_el) "
      "and %.0f %% (Q_u) of the measured minutes\n",
      result.days_ok, result.total_p_el.skill, result.total_q_th.skill,
      100.0 * result.total_p_el.coverage, 100.0 * result.total_q_th.coverage);
  std::printf(
      "        (the band: where a minute's measurement falls 8 times in 10, judged by the "
      "model's own errors on the %d-day window's held-out days; it always holds the "
      "forecast, p50 is the median)\n",
      options.window_days);
}

// What the daily checks and the diagnosis left in the store.
void PrintMonitoring(Store* store, const fs::path& state_dir) {
  std::vector<DayPerformance> days;
  std::string error;
  if (!store->ReadPerformanceDays(0, std::numeric_limits<std::int64_t>::max(), &days, &error)) {
    return;
  }
  double lo_el = INFINITY, hi_el = -INFINITY, lo_th = INFINITY, hi_th = -INFINITY;
  int scored = 0;
  for (const DayPerformance& d : days) {
    if (!d.scored_el) continue;
    ++scored;
    lo_el = std::min(lo_el, d.pi_el);
    hi_el = std::max(hi_el, d.pi_el);
    if (d.scored_th) {
      lo_th = std::min(lo_th, d.pi_th);
      hi_th = std::max(hi_th, d.pi_th);
    }
  }
  if (scored > 0) {
    std::printf(
        "      performance index (measured / model): %d days scored, electrical %.3f-%.3f, "
        "thermal %.3f-%.3f\n",
        scored, lo_el, hi_el, lo_th, hi_th);
  }
  Store::DiagnosisRow diagnosis;
  bool found = false;
  if (store->LatestDiagnosis(&diagnosis, &found, &error) && found) {
    std::printf("      diagnosis of %s: verdict %s; report in %s\n", diagnosis.base_variant.c_str(),
                diagnosis.verdict.c_str(), (state_dir / "reports").c_str());
  } else {
    std::printf(
        "      diagnosis: still running when the demo stopped (it runs after the "
        "calibration, in the background)\n");
  }
}

// What the stages of the demo share: where it works and on which timeline.
struct DemoRun {
  double wall_start = 0.0;  // wall clock when the demo began
  fs::path dir;             // scratch directory
  std::string db;           // SQLite file
  std::string exe;          // this executable, for `pvtwin sim`
  fs::path sim_config;      // the example plant (kDemoPlantConfig)
  fs::path history_csv;     // the exported history
  Config plant;             // sim_config loaded
  std::int64_t t0 = 0;      // start of the live part; history covers the 14 days before
};

// The scratch directory, the database path and the example plant; false
// (with the exit code in *code) when the demo cannot start.
bool PrepareDemo(const DemoArgs& a, DemoRun* run, int* code) {
  run->wall_start = WallNowS();
  fs::path dir = a.dir;
  if (dir.empty()) {
    std::string tmpl = (fs::temp_directory_path() / "pvtwin-demo-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) {
      std::perror("mkdtemp");
      *code = kExitRuntime;
      return false;
    }
    dir = tmpl;
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  run->dir = dir;
  run->db = a.db.empty() ? (dir / "pvtwin.db").string() : fs::absolute(a.db).string();
  if (fs::exists(run->db)) {
    std::cerr << "--db = " << run->db << ": exists; the demo starts from an empty database\n";
    *code = kExitBadInput;
    return false;
  }
  run->exe = SelfExecutable();
  run->sim_config = dir / "sim.toml";
  run->history_csv = dir / "history.csv";
  std::ofstream(run->sim_config) << kDemoPlantConfig;

  // The live part starts at 08:00 UTC on --date, else on the latest day on
  // which it ends before the wall clock: the daemon stamps its 5 s samples
  // and 1-min rows with a simulated clock `speed` times faster than the wall
  // clock, and none may lie after the wall clock when it is written (issue
  // 54). The history covers the 14 days before.
  const std::int64_t now_s = static_cast<std::int64_t>(WallNowS());
  const std::int64_t latest_t0 = now_s - LiveSpanS(a);
  const std::int64_t latest_day_t0 =
      (latest_t0 - kLiveStartOfDayS) / 86400 * 86400 + kLiveStartOfDayS;
  run->t0 = latest_day_t0;
  if (!a.date.empty()) {
    std::int64_t day_s = 0;
    if (!ParseTimeOrReport("--date", a.date + "T00:00:00Z", &day_s)) {
      *code = kExitBadInput;
      return false;
    }
    run->t0 = day_s / 86400 * 86400 + kLiveStartOfDayS;
    if (run->t0 > latest_t0) {
      std::fprintf(stderr,
                   "--date = %s: the live part, from %s for up to %.1f h of simulated time "
                   "(--max-wall %.0f s at --speed %.0f), would end after the wall clock (%s); "
                   "the latest day it fits is %s\n",
                   a.date.c_str(), FormatIsoUtc(run->t0).c_str(), LiveSpanS(a) / 3600.0,
                   a.max_wall_s, a.speed, FormatIsoUtc(now_s).c_str(),
                   FormatIsoUtc(latest_day_t0).substr(0, 10).c_str());
      *code = kExitBadInput;
      return false;
    }
  }
  if (!LoadConfigOrReport(run->sim_config.string(), &run->plant)) {
    *code = kExitRuntime;
    return false;
  }
  return true;
}

// [1/4] 14 days of history from the simulator's truth model (`pvtwin sim
// --export`), imported into the database as 1-min rows.
bool SeedHistory(const DemoRun& run) {
  std::printf("[1/4] 14 days of plant history from the simulator's truth model ...\n");
  std::fflush(stdout);
  ChildProcess exporter;
  std::string error;
  const std::vector<std::string> export_argv = {run.exe,    "sim",
                                                "--config", run.sim_config.string(),
                                                "--export", run.history_csv.string(),
                                                "--days",   "14",
                                                "--step",   "60",
                                                "--start",  std::to_string(run.t0 - 14 * 86400)};
  int code = -1;
  if (!exporter.Start(export_argv, (run.dir / "sim-export.log").string(), &error)) {
    std::cerr << error << "\n";
    return false;
  }
  while (!exporter.Finished(&code)) ::usleep(50000);
  if (code != 0) {
    std::cerr << "pvtwin sim --export failed; see " << (run.dir / "sim-export.log").string()
              << "\n";
    return false;
  }
  Series history;
  if (!LoadCsvOrReport(run.history_csv.string(), run.plant, &history)) return false;
  std::unique_ptr<Store> store = Store::Open(run.db, &error);
  if (!store || !store->WriteMinutes(history, &error)) {
    std::cerr << run.db << ": " << error << "\n";
    return false;
  }
  std::printf("      %zu 1-min rows imported into %s\n", history.size(), run.db.c_str());
  return true;
}

// [2/4] `pvtwin sim` serving the plant over Modbus TCP on loopback from t0,
// on the clock anchored at wall_anchor_s, and the daemon's config pointing at
// its ports (written to *daemon_config).
bool StartSimulator(const DemoRun& run, const DemoArgs& a, double wall_anchor_s, ChildProcess* sim,
                    fs::path* daemon_config) {
  std::printf("[2/4] starting the plant simulator (Modbus TCP on loopback, clock x%.0f) ...\n",
              a.speed);
  std::fflush(stdout);
  std::string error;
  std::vector<std::string> lines;
  const fs::path sim_log = run.dir / "sim.log";
  if (!sim->StartPiped(
          {run.exe, "sim", "--config", run.sim_config.string(), "--ephemeral-ports", "--speed",
           std::to_string(a.speed), "--start", std::to_string(run.t0), "--run-start",
           std::to_string(run.t0 - 14 * 86400), "--wall-anchor", std::to_string(wall_anchor_s)},
          sim_log.string(), &error)) {
    std::cerr << error << "\n";
    return false;
  }
  if (!sim->ReadUntil("ready", 20.0, &lines)) {
    std::cerr << "the simulator did not get ready within 20 s; see " << sim_log.string() << "\n";
    return false;
  }
  for (const std::string& l : lines) {
    if (l.rfind("listening", 0) == 0) std::printf("      %s\n", l.c_str());
  }
  *daemon_config = run.dir / "pvtwin.toml";
  DaemonSettings settings;
  settings.db_path = run.db;
  std::string config_text;
  if (!EditConfig(kDemoPlantConfig, ParseListeningLines(lines), settings, &config_text, &error)) {
    std::cerr << "demo config: " << error << "\n";
    return false;
  }
  std::ofstream(*daemon_config) << "# Written by `pvtwin demo`: the example plant and register "
                                   "map at the simulator's\n# loopback ports, and the daemon "
                                   "sections.\n"
                                << config_text;
  return true;
}

// How the live part ended.
struct LiveResult {
  int rc = 0;              // RunService's exit code
  ServiceStatus last;      // the last status the loop reported
  bool timed_out = false;  // cut short by --max-wall
};

// [3/4] The daemon loop polling the simulator on the same accelerated clock,
// with a status line every 2 s of wall time, until forecasts are written and
// live_minutes aggregated, or --max-wall.
LiveResult RunLive(const DemoRun& run, const DemoArgs& a, double wall_anchor_s,
                   const fs::path& daemon_config) {
  std::printf(
      "[3/4] daemon: polling every 5 s (simulated), 1-min aggregation, calibration, "
      "forecast ...\n");
  std::fflush(stdout);
  ServiceOptions options;
  options.config_path = daemon_config.string();
  options.sim_start_s = static_cast<double>(run.t0);
  options.wall_anchor_s = wall_anchor_s;
  options.speed = a.speed;
  options.exe_path = run.exe;
  double next_print = 0.0;
  LiveResult live;
  options.on_tick = [&](const ServiceStatus& s) {
    live.last = s;
    const bool done =
        s.forecasts > 0 && s.minutes_aggregated >= static_cast<std::uint64_t>(a.live_minutes);
    if (WallNowS() >= next_print || done) {
      next_print = WallNowS() + 2.0;
      std::printf("      %s | devices %d/%d up | 5 s samples %llu | 1-min rows %llu | %s\n",
                  FormatIsoUtc(static_cast<std::int64_t>(s.now_s)).c_str(), s.devices_up, s.devices,
                  static_cast<unsigned long long>(s.samples_stored),
                  static_cast<unsigned long long>(s.minutes_aggregated),
                  s.calibrating        ? "calibrating ..."
                  : s.forecasts > 0    ? ForecastsWritten(s.forecasts).c_str()
                  : s.calibrations > 0 ? s.last_calibration.c_str()
                                       : "waiting for calibration");
      std::fflush(stdout);
    }
    if (WallNowS() - run.wall_start > a.max_wall_s) {
      live.timed_out = true;
      return false;
    }
    return !done;
  };
  live.rc = RunService(options);
  return live;
}

// [4/4] The accepted calibration, the forecast, the monitoring, the forecast
// skill, and the SQL to look at them.
void PrintSummary(const DemoRun& run, const ServiceStatus& last) {
  std::printf("[4/4] summary\n");
  std::string error;
  std::unique_ptr<Store> store = Store::Open(run.db, &error);
  Store::CalibrationRow cal;
  bool found = false;
  if (store) store->LatestAcceptedCalibration(&cal, &found, &error);
  if (found) {
    const double area_m2 = run.plant.plant.area_m2;
    std::printf(
        "      calibration %lld: %s, held-out day MAE P_el %s, MAE Q_u %s, "
        "fit %.1f s, %ld simulations\n",
        static_cast<long long>(cal.id), cal.variant.c_str(),
        WattsAndPerM2(cal.mae_p_el_w, area_m2).c_str(),
        WattsAndPerM2(cal.mae_q_th_w, area_m2).c_str(), cal.runtime_s, cal.n_evals);
  } else {
    std::printf("      no accepted calibration (%s)\n", last.last_calibration.c_str());
  }
  std::printf("      forecast rows written: %zu (24 h at 1 min)\n", last.last_forecast_rows);
  if (store) PrintNoonForecast(store.get(), run.plant.plant, run.t0);
  if (store) PrintMonitoring(store.get(), fs::path(run.db).parent_path());
  if (store && found) {
    Series history;
    if (LoadCsvOrReport(run.history_csv.string(), run.plant, &history)) {
      PrintForecastSkill(store.get(), run.plant, cal, history);
    }
  }
  std::printf("      plant: %s\n", OperationSummary(run.plant.sim).c_str());
  std::printf("      live polling: %llu samples, %llu 1-min rows; runtime %.0f s\n",
              static_cast<unsigned long long>(last.samples_stored),
              static_cast<unsigned long long>(last.minutes_aggregated),
              WallNowS() - run.wall_start);
  const std::string db = Q(run.db);
  std::printf(
      "\nThe database stays for you to explore:\n"
      "  sqlite3 %s \"SELECT datetime(ts, 'unixepoch') AS time_utc, round(p_el_w, 1) AS p_el_w,\n"
      "    round(q_th_w, 1) AS q_th_w, round(t_out_c, 1) AS t_out_c FROM forecast_latest\n"
      "    WHERE ts %% 3600 = 0 ORDER BY ts;\"\n"
      "  sqlite3 %s \"SELECT id, status, reason FROM calibration;\"\n"
      "  sqlite3 %s \"SELECT * FROM forecast_skill;\"\n"
      "  sqlite3 %s \"SELECT datetime(ts, 'unixepoch'), kind, severity, message FROM event;\"\n"
      "  sqlite3 %s \"SELECT date(day, 'unixepoch') AS day, round(pi_el, 3) AS pi_el,\n"
      "    round(pi_th, 3) AS pi_th, valid_minutes FROM performance_daily;\"\n"
      "  sqlite3 %s \"SELECT name, value, std_error, unit, status FROM parameter_history;\"\n",
      db.c_str(), db.c_str(), db.c_str(), db.c_str(), db.c_str(), db.c_str());
}

int RunDemo(const DemoArgs& a) {
  DemoRun run;
  int code = kExitOk;
  if (!PrepareDemo(a, &run, &code)) return code;
  std::printf("pvtwin demo: working in %s\n", run.dir.string().c_str());
  std::printf("      plant: %s\n", OperationSummary(run.plant.sim).c_str());
  if (!SeedHistory(run)) return kExitRuntime;

  // The simulator and the daemon share one clock: t0 at this wall time.
  const double anchor = WallNowS();
  ChildProcess sim;
  fs::path daemon_config;
  if (!StartSimulator(run, a, anchor, &sim, &daemon_config)) return kExitRuntime;
  const LiveResult live = RunLive(run, a, anchor, daemon_config);
  sim.SendLine("quit");
  sim.Stop(0, 5.0);
  if (live.rc != 0) return live.rc;

  PrintSummary(run, live.last);
  if (live.last.forecasts == 0) {
    std::cerr << "demo: stopped after " << static_cast<long>(WallNowS() - run.wall_start)
              << " s without a forecast; see the log above\n";
    return kExitRuntime;
  }
  if (live.timed_out) {
    // Forecasts were written: the demo did its job, only the live part was
    // cut short by --max-wall.
    std::printf(
        "\nStopped at the wall-time limit (--max-wall %.0f s) after %llu of %d live minutes, "
        "with %s.\n",
        a.max_wall_s, static_cast<unsigned long long>(live.last.minutes_aggregated), a.live_minutes,
        ForecastsWritten(live.last.forecasts).c_str());
  }
  return kExitOk;
}

}  // namespace

void RegisterDemo(CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "demo",
      "Run the whole job on the built-in example, with nothing configured: seed 14 days of\n"
      "history from the plant simulator's truth model, start `pvtwin sim` on loopback and the\n"
      "daemon against it on an accelerated clock, poll and aggregate live, calibrate, write a\n"
      "24 h forecast, and print a summary with the SQL to query `forecast_latest`. Takes\n"
      "about a minute; leaves the SQLite file for you to explore.");
  cmd->add_option("--db", args->db, "SQLite file to create (default: in the demo directory)");
  cmd->add_option("--dir", args->dir, "working directory (default: a new one under /tmp)");
  cmd->add_option("--speed", args->speed, "simulated seconds per wall second")
      ->check(CLI::Range(1.0, 600.0));
  cmd->add_option("--live-minutes", args->live_minutes,
                  "simulated minutes of live polling to aggregate before stopping")
      ->check(CLI::Range(1, 1440));
  cmd->add_option("--max-wall", args->max_wall_s,
                  "stop the live part after this many wall seconds (default 110)")
      ->check(CLI::Range(10.0, 86400.0));
  cmd->add_option("--date", args->date,
                  "UTC day of the live part, YYYY-MM-DD, from 08:00 UTC (default: the latest "
                  "day on which it ends before now), e.g. a past June day to see the plant in "
                  "summer");
  cmd->callback([args] { SetExitCode(RunDemo(*args)); });
}

}  // namespace pvtwin::cli
