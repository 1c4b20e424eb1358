// pvtwin run: the daemon (daemon/service/service.h) under systemd or in a terminal.
#include <signal.h>

#include <atomic>
#include <cstring>
#include <iostream>

#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/service.h"

namespace pvtwin::cli {

namespace {

std::atomic<bool> g_stop(false);
std::atomic<bool> g_reload(false);

// Signal handlers only set a flag; the loop acts on it.
extern "C" void OnRunStopSignal(int) { g_stop.store(true); }
extern "C" void OnHangup(int) { g_reload.store(true); }

void InstallSignalHandlers() {
  struct sigaction sa {};
  sigemptyset(&sa.sa_mask);
  sa.sa_handler = OnRunStopSignal;
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  sa.sa_handler = OnHangup;
  sigaction(SIGHUP, &sa, nullptr);
  sa.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &sa, nullptr);
}

struct RunArgs {
  ServiceOptions service;
  std::string sim_start;
};

int Run(RunArgs& a) {
  if (!a.sim_start.empty()) {
    std::int64_t t = 0;
    if (!ParseTimeOrReport("--sim-start", a.sim_start, &t)) return kExitBadInput;
    a.service.sim_start_s = static_cast<double>(t);
  }
  if (!(a.service.speed > 0)) {
    std::cerr << "--speed = " << a.service.speed << ": must be > 0\n";
    return kExitBadInput;
  }
  InstallSignalHandlers();
  a.service.stop = &g_stop;
  a.service.reload = &g_reload;
  return RunService(a.service);
}

}  // namespace

void RegisterRun(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run",
      "Run the daemon: poll the Modbus devices of the config every [poll] period_s into the\n"
      "SQLite store, aggregate 1-min rows, calibrate the model nightly at [calibration] at\n"
      "(local time) over the last window_days, and write 24 h forecasts to the `forecast`\n"
      "table. Tells systemd READY=1 once the config is valid and the store open; SIGTERM or\n"
      "SIGINT store the last samples and exit 0; SIGHUP reloads [calibration], [forecast]\n"
      "and [plant] ([storage], [poll] and the register map need a restart).");
  cmd->add_option("--config", args->service.config_path, "the daemon's TOML config")->required();
  cmd->add_option("--db", args->service.db_path, "SQLite file (overrides [storage] path)");
  cmd->add_option("--speed", args->service.speed,
                  "run the clock this many times faster than real time (tests, demos)")
      ->group("");
  cmd->add_option("--sim-start", args->sim_start,
                  "simulated time at --wall-anchor (ISO 8601 or unix s); default: real time")
      ->group("");
  cmd->add_option("--wall-anchor", args->service.wall_anchor_s,
                  "wall-clock unix time at which the simulated clock reads --sim-start "
                  "(default: now); give the simulator the same value to share its clock")
      ->group("");
  cmd->add_option("--calibration-timeout", args->service.calibration_timeout_s,
                  "wall seconds after which a calibration is abandoned");
  cmd->add_flag("--adopt-store", args->service.adopt_store,
                "use a store whose plant_config records another site or area (the plant "
                "changed); without it the daemon refuses such a store");
  cmd->callback([args] { SetExitCode(Run(*args)); });
}

}  // namespace pvtwin::cli
