// pvtwin sim: the plant simulator. Serves every point of the config's Modbus
// register map from a simulated PVT plant (io/sim/modbus_sim_server.h,
// io/sim/plant_source.h), or writes that plant's history as canonical CSV.
#include <poll.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/data/resample.h"
#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "io/files/csv.h"
#include "io/platform/log.h"
#include "io/sim/modbus_sim_server.h"
#include "io/sim/plant_source.h"

namespace pvtwin::cli {

namespace {

volatile std::sig_atomic_t g_stop_signal = 0;
void OnSimStopSignal(int) { g_stop_signal = 1; }

struct SimArgs {
  std::string config;
  bool ephemeral_ports = false;
  int port_offset = 0;
  double speed = 1.0;
  std::string start;
  double wall_anchor_s = 0;
  bool stepped = false;
  std::uint64_t seed = 1;
  std::string truth_variant = kDefaultTruthVariant;
  std::string weather = "generate";
  std::vector<std::string> sky;
  std::string csv;
  std::vector<std::string> faults;
  std::string export_path;
  std::string operation;  // empty: the config's [sim] operation
  std::string run_start;  // empty: --start
  int days = 14;
  double step_s = 5;
};

int RunExport(const SimArgs& a, PlantSource* source, std::int64_t start_s) {
  Series history = source->History(start_s, a.days);
  if (a.step_s != kPlantSourceStepS) {
    Series averaged;
    std::string error;
    if (!Resample(history, a.step_s, &averaged, &error)) {
      std::cerr << "--step = " << a.step_s << ": " << error << "\n";
      return kExitBadInput;
    }
    history = std::move(averaged);
  }
  std::vector<Channel> channels;
  for (const ChannelInfo& info : kChannels) {
    if (history.Has(info.channel)) channels.push_back(info.channel);
  }
  std::string error;
  if (!WriteCsv(a.export_path, history, channels, &error)) {
    std::cerr << error << "\n";
    return kExitRuntime;
  }
  std::cerr << "wrote " << history.size() << " rows (" << a.days << " days at " << a.step_s
            << " s) to " << a.export_path << "\n";
  return kExitOk;
}

// One control line from stdin; the answer goes to stdout.
std::string Control(const std::string& line, SteppedClock* stepped, const Clock& clock,
                    ModbusSimServer* server, bool* quit) {
  std::istringstream in(line);
  std::string verb;
  in >> verb;
  if (verb == "quit") {
    *quit = true;
    return "ok quit";
  }
  if (verb == "time")
    return "ok " + std::to_string(static_cast<std::int64_t>(std::floor(clock.NowS())));
  if (verb == "advance") {
    double dt_s = 0;
    if (stepped == nullptr) return "error advance needs --stepped";
    if (!(in >> dt_s) || !(dt_s >= 0)) return "error usage: advance SECONDS";
    stepped->Advance(dt_s);
    return "ok " + std::to_string(static_cast<std::int64_t>(std::floor(clock.NowS())));
  }
  if (verb == "fault") {
    std::string spec;
    in >> spec;
    Fault fault;
    std::string error;
    if (!ParseFault(spec, &fault, &error) || !server->AddFault(fault, &error)) {
      return "error " + error;
    }
    return "ok fault " + spec;
  }
  return "error unknown command '" + verb + "' (advance S | fault SPEC | time | quit)";
}

int RunSim(const SimArgs& a) {
  Config config;
  if (!LoadConfigOrReport(a.config, &config)) return kExitBadInput;

  PlantSourceOptions source_options;
  source_options.plant = config.plant;
  source_options.truth_variant = a.truth_variant;
  source_options.seed = a.seed;
  const std::string& operation = a.operation.empty() ? config.sim.operation : a.operation;
  source_options.pump_control = *PumpControlFromName(operation);
  source_options.pump_dt_on_k = config.sim.pump_dt_on_k;
  source_options.pump_dt_off_k = config.sim.pump_dt_off_k;
  source_options.brine_below_ambient_k = config.sim.brine_below_ambient_k;
  source_options.brine_min_c = config.sim.brine_min_c;
  source_options.brine_max_c = config.sim.brine_max_c;
  for (const std::string& sky : a.sky) source_options.day_types.push_back(*DayTypeFromName(sky));
  if (a.weather == "replay") {
    if (a.csv.empty()) {
      std::cerr << "--weather replay needs --csv FILE\n";
      return kExitBadInput;
    }
    source_options.replay_csv = a.csv;
  }
  const double now_s = WallNowS();
  std::int64_t start_s = 0;
  if (!a.start.empty()) {
    if (!ParseTimeOrReport("--start", a.start, &start_s)) return kExitBadInput;
  } else if (!a.export_path.empty()) {
    // The last `days` whole UTC days before today: history leading up to now.
    start_s = (static_cast<std::int64_t>(now_s) / 86400 - a.days) * 86400;
  } else {
    start_s = static_cast<std::int64_t>(now_s);
  }
  // The continuous plant (thermostat operations) starts its run here.
  source_options.run_start_s = start_s;
  if (!a.run_start.empty() &&
      !ParseTimeOrReport("--run-start", a.run_start, &source_options.run_start_s)) {
    return kExitBadInput;
  }
  if (source_options.Continuous() && source_options.run_start_s > start_s) {
    std::cerr << "--run-start = " << a.run_start << ": must not be after --start\n";
    return kExitBadInput;
  }
  Diagnostics errors;
  std::unique_ptr<PlantSource> source = PlantSource::Create(source_options, &errors);
  if (source == nullptr) {
    for (const Diagnostic& d : errors) std::cerr << d.ToString() << "\n";
    return kExitBadInput;
  }
  if (!a.export_path.empty()) return RunExport(a, source.get(), start_s);

  if (config.modbus.devices.empty()) {
    std::cerr << a.config << ": no [[modbus.device]]: nothing to serve\n";
    return kExitBadInput;
  }
  std::unique_ptr<SteppedClock> stepped;
  std::unique_ptr<Clock> clock;
  if (a.stepped) {
    stepped = std::make_unique<SteppedClock>(static_cast<double>(start_s));
  } else {
    clock = std::make_unique<ScaledClock>(static_cast<double>(start_s), a.wall_anchor_s, a.speed);
  }
  const Clock& sim_clock = a.stepped ? static_cast<const Clock&>(*stepped) : *clock;

  SimServerOptions server_options;
  server_options.ephemeral_ports = a.ephemeral_ports;
  server_options.port_offset = a.port_offset;
  ModbusSimServer server(config.modbus, source.get(), sim_clock, static_cast<double>(start_s),
                         server_options, LogToStderr);
  for (const std::string& text : a.faults) {
    Fault fault;
    std::string error;
    if (!ParseFault(text, &fault, &error) || !server.AddFault(fault, &error)) {
      std::cerr << "--fault: " << error << "\n";
      return kExitBadInput;
    }
  }
  // Generate the first day now, not on the first request (it takes a moment).
  source->At(static_cast<double>(start_s));
  std::signal(SIGPIPE, SIG_IGN);
  std::signal(SIGTERM, OnSimStopSignal);
  std::signal(SIGINT, OnSimStopSignal);
  std::string error;
  if (!server.Start(&error)) {
    std::cerr << error << "\n";
    return kExitRuntime;
  }
  for (const std::string& endpoint : server.Endpoints()) {
    std::cout << "listening " << endpoint << "\n";
  }
  std::cout << "ready start=" << start_s << " speed=" << (a.stepped ? 0.0 : a.speed) << std::endl;
  LogToStderr(kInfo, "sim: serving " + std::to_string(config.modbus.points.size()) + " points of " +
                         std::to_string(config.modbus.devices.size()) + " device(s), truth " +
                         a.truth_variant + ", seed " + std::to_string(a.seed) + ", operation " +
                         operation);

  // Control lines on stdin until quit, SIGTERM or SIGINT; end of input only
  // stops reading (the simulator may run detached from a terminal).
  bool quit = false;
  bool stdin_open = true;
  std::string pending;
  while (!quit && g_stop_signal == 0) {
    if (!stdin_open) {
      usleep(50000);
      continue;
    }
    pollfd fd{STDIN_FILENO, POLLIN, 0};
    if (poll(&fd, 1, 50) <= 0) continue;
    char buf[512];
    const ssize_t n = read(STDIN_FILENO, buf, sizeof buf);
    if (n <= 0) {
      stdin_open = false;
      continue;
    }
    pending.append(buf, static_cast<std::size_t>(n));
    std::size_t eol = 0;
    while (!quit && (eol = pending.find('\n')) != std::string::npos) {
      const std::string line = pending.substr(0, eol);
      pending.erase(0, eol + 1);
      if (line.empty()) continue;
      std::cout << Control(line, stepped.get(), sim_clock, &server, &quit) << std::endl;
    }
  }
  server.Stop();
  LogToStderr(kInfo, "sim: stopped after " + std::to_string(server.Requests()) + " requests");
  return kExitOk;
}

}  // namespace

void RegisterSim(CLI::App& app) {
  auto args = std::make_shared<SimArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sim",
      "The plant simulator: a simulated PVT plant behind real Modbus servers.\n"
      "Serves every point of the config's register map ([[modbus.device]], [[modbus.point]]):\n"
      "one Modbus TCP server per device host:port (RTU on a device's serial line), values of\n"
      "the plant at the current simulated time, encoded with each point's type, word order,\n"
      "scale and offset. The plant is the config's [plant] with generated weather and\n"
      "operation (seeded, reproducible) run through a truth model, or a replayed CSV.\n"
      "Prints 'listening DEVICE tcp HOST:PORT' per device, then 'ready', on stdout.\n"
      "Control lines on stdin: 'advance S' (with --stepped), 'fault SPEC', 'time', 'quit'.\n"
      "Faults: DEVICE:KIND:from=S:for=S[:ms=N], KIND drop | exception | delay | nan | range |\n"
      "freeze | stray (replies with a wrong transaction or unit id) | wrong_unit (replies\n"
      "as unit id + 6) | glitch (6000 W/m² on the short-wave irradiance points), S\n"
      "simulated seconds after --start (delay: ms of wall time, default 2000).\n"
      "With --export FILE it writes the same plant's history as canonical CSV and exits.");
  cmd->add_option("--config", args->config, "TOML config with [plant] and the register map")
      ->required();
  cmd->add_flag("--ephemeral-ports", args->ephemeral_ports,
                "bind every TCP device to a free port chosen by the kernel (see stdout)");
  cmd->add_option("--port-offset", args->port_offset, "added to every configured TCP port");
  cmd->add_option("--speed", args->speed, "simulated seconds per wall second (default 1)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--start", args->start,
                  "simulated time at --wall-anchor, ISO 8601 or unix s (default: now; with "
                  "--export: 00:00 UTC --days days ago)");
  cmd->add_option("--wall-anchor", args->wall_anchor_s,
                  "wall-clock unix time at which the simulated clock reads --start (default: "
                  "now); give the daemon the same start, anchor and speed")
      ->group("");
  cmd->add_flag("--stepped", args->stepped,
                "simulated time stands still at --start and moves only by 'advance S' on stdin");
  cmd->add_option("--seed", args->seed, "seed of weather, operation and sensor noise");
  cmd->add_option("--truth-variant", args->truth_variant,
                  std::string("model variant of the simulated plant (default ") +
                      kDefaultTruthVariant +
                      "); an effect added to it (e.g. +pv_clipping) acts at its typical magnitude");
  cmd->add_option("--weather", args->weather, "generate (default) or replay --csv")
      ->check(CLI::IsMember({"generate", "replay"}));
  cmd->add_option(
         "--sky", args->sky,
         "sky of each day, cycled: clear, broken_clouds, overcast (default: drawn from the "
         "seed)")
      ->check(CLI::IsMember({"clear", "broken_clouds", "overcast"}));
  cmd->add_option("--csv", args->csv, "canonical CSV to replay (--weather replay)");
  cmd->add_option("--fault", args->faults, "DEVICE:KIND:from=S:for=S[:ms=N] (repeatable)");
  cmd->add_option("--operation", args->operation,
                  "solar loop of the simulated plant, overrides [sim] operation: irradiance "
                  "(pump on irradiance thresholds, tank; per-UTC-day runs), differential (pump "
                  "on collector − tank temperature difference) or heat_pump (brine below "
                  "ambient from a heat pump); the last two are one continuous run")
      ->check(CLI::IsMember({"irradiance", "differential", "heat_pump"}));
  cmd->add_option("--run-start", args->run_start,
                  "differential / heat_pump: when the continuous run begins, ISO 8601 or unix s, "
                  "not after --start (default: --start); give the served plant the start of "
                  "the exported history to make both one run");
  cmd->add_option("--export", args->export_path, "write the plant's history as CSV and exit");
  cmd->add_option("--days", args->days, "days of history for --export (default 14)")
      ->check(CLI::Range(1, 3660));
  cmd->add_option("--step", args->step_s,
                  "row spacing of --export in s, a multiple of 5 (averages of the 5 s rows)")
      ->check(CLI::PositiveNumber);
  cmd->callback([args] { SetExitCode(RunSim(*args)); });
}

}  // namespace pvtwin::cli
