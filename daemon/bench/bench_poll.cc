// pvtwin-bench poll: the Modbus poller against a simulator on loopback.
//
// The register map has 2 devices × 40 points (every type and word order,
// input and holding registers, so 2 reads per device). The simulator's server
// (io/sim/modbus_sim_server.h, real libmodbus TCP) runs in a forked child process,
// so getrusage of this process counts the poller alone.
//   * CPU: the poller at the real 5 s period for a while, CPU time over wall
//     time = share of one core (this includes the clock's idle wake-ups).
//   * Latency: many cycles on an accelerated clock (a cycle every 50 ms of
//     wall time); per cycle the longest device poll (connect + reads +
//     decoding), p50 and p99; and CPU time per cycle.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <vector>

#include "core/synth/synthetic_plant.h"
#include "daemon/bench/bench.h"
#include "io/modbus/modbus_poller.h"
#include "io/sim/modbus_sim_server.h"
#include "io/sim/plant_source.h"

namespace pvtwin::cli {

namespace {

constexpr int kDevices = 2;
constexpr int kPointsPerDevice = 40;

constexpr Channel kServedChannels[] = {
    Channel::kTInC,   Channel::kTOutC,          Channel::kMdotKgS, Channel::kGPoaWM2,
    Channel::kGhiWM2, Channel::kDhiWM2,         Channel::kTAmbC,   Channel::kWindMS,
    Channel::kPElW,   Channel::kGPoaDiffuseWM2, Channel::kQThW,    Channel::kLwDownWM2,
    Channel::kTPvC,   Channel::kAoiRad};

ModbusConfig BenchMap() {
  constexpr RegisterType kTypes[] = {RegisterType::kU16, RegisterType::kI16, RegisterType::kU32,
                                     RegisterType::kI32, RegisterType::kF32, RegisterType::kF64};
  constexpr WordOrder kOrders[] = {WordOrder::kABCD, WordOrder::kCDAB, WordOrder::kBADC,
                                   WordOrder::kDCBA};
  ModbusConfig map;
  for (int d = 0; d < kDevices; ++d) {
    ModbusDevice device;
    device.name = d == 0 ? "collector" : "weather";
    device.host = "127.0.0.1";
    device.unit_id = d + 1;
    device.timeout_ms = 500;
    map.devices.push_back(device);
    int address[2] = {0, 0};
    for (int i = 0; i < kPointsPerDevice; ++i) {
      ModbusPoint p;
      p.device = static_cast<std::size_t>(d);
      // Several points per channel (the bench measures reading and decoding,
      // not the map), all of them channels the simulated plant provides.
      p.channel = kServedChannels[static_cast<std::size_t>(i) % std::size(kServedChannels)];
      p.table = i % 2 == 0 ? RegisterTable::kInput : RegisterTable::kHolding;
      p.type = kTypes[i % 6];
      p.word_order = kOrders[(i / 6) % 4];
      if (p.type == RegisterType::kU16 || p.type == RegisterType::kI16 ||
          p.type == RegisterType::kU32 || p.type == RegisterType::kI32) {
        p.scale = 0.01;
      }
      int& next = address[i % 2];
      p.address = next;
      next += p.Count();
      map.points.push_back(p);
    }
  }
  return map;
}

// The simulator in a child process; ports come back through a pipe.
struct ServerChild {
  pid_t pid = -1;
  std::vector<int> ports;

  bool Start(const ModbusConfig& map, std::uint64_t seed) {
    int fds[2];
    if (pipe(fds) != 0) return false;
    pid = fork();
    if (pid == 0) {
      close(fds[0]);
      signal(SIGPIPE, SIG_IGN);
      const ScaledClock clock;  // real time: the values only need to be plausible
      PlantSourceOptions options;
      options.plant = DesignExamplePlant();
      options.seed = seed;
      Diagnostics errors;
      std::unique_ptr<PlantSource> source = PlantSource::Create(options, &errors);
      source->At(clock.NowS());
      SimServerOptions server_options;
      server_options.ephemeral_ports = true;
      ModbusSimServer server(map, source.get(), clock, clock.NowS(), server_options,
                             [](int, const std::string&) {});
      std::string error;
      int ports[kDevices] = {0, 0};
      if (server.Start(&error)) {
        for (int d = 0; d < kDevices; ++d) ports[d] = server.Port(static_cast<std::size_t>(d));
      }
      if (write(fds[1], ports, sizeof ports) != static_cast<ssize_t>(sizeof ports)) _exit(1);
      for (;;) pause();  // until SIGKILL
    }
    close(fds[1]);
    int got[kDevices] = {0, 0};
    const bool ok = read(fds[0], got, sizeof got) == static_cast<ssize_t>(sizeof got) && got[0] > 0;
    close(fds[0]);
    ports.assign(got, got + kDevices);
    return ok;
  }

  ~ServerChild() {
    if (pid > 0) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
};

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t i = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))) - 1;
  return v[std::min(i, v.size() - 1)];
}

struct RunFigures {
  int cycles = 0;
  int complete = 0;  // cycles with every point's channel delivered
  double cpu_s = 0;
  double wall_s = 0;
  std::vector<double> latency_s;
};

// Polls for `cycles` periods of period_s at `speed`.
RunFigures Run(const ModbusConfig& map, double speed, int cycles) {
  const double period_s = 5.0;
  const ScaledClock clock(WallNowS(), 0.0, speed);
  PollerOptions options;
  options.period_s = period_s;
  // The simulator's values change every 5 s of wall time, so accelerated
  // polls see identical registers; the comparison still runs, the verdict
  // "frozen" is switched off.
  options.frozen_after_polls = 0;
  RunFigures f;
  std::mutex mutex;
  std::condition_variable cv;
  ModbusPoller poller(map, options, clock, [](int, const std::string&) {});
  const double cpu0 = SelfCpuSeconds();
  const auto wall0 = std::chrono::steady_clock::now();
  poller.Start([&](const Sample& s) {
    double latency = 0;
    for (const DeviceStats& st : poller.Stats()) latency = std::max(latency, st.last_poll_wall_s);
    bool complete = true;
    for (const ModbusPoint& p : map.points) complete = complete && s.Has(p.channel);
    std::lock_guard<std::mutex> lock(mutex);
    ++f.cycles;
    f.complete += complete;
    f.latency_s.push_back(latency);
    cv.notify_all();
  });
  {
    std::unique_lock<std::mutex> lock(mutex);
    cv.wait_for(lock, std::chrono::duration<double>(cycles * period_s / speed + 30.0),
                [&] { return f.cycles >= cycles; });
  }
  poller.Stop();
  f.cpu_s = SelfCpuSeconds() - cpu0;
  f.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return f;
}

}  // namespace

void BenchPoll(int cycles, std::uint64_t seed) {
  const ModbusConfig map = BenchMap();
  ServerChild server;
  if (!server.Start(map, seed)) {
    std::printf("poll: the simulator could not start\n");
    return;
  }
  ModbusConfig polled = map;
  for (int d = 0; d < kDevices; ++d)
    polled.devices[static_cast<std::size_t>(d)].port = server.ports[static_cast<std::size_t>(d)];
  const std::size_t reads = PlanReads(polled).size();
  std::printf(
      "poll: %d devices x %d points (%zu reads per cycle) against a simulator process on "
      "loopback\n",
      kDevices, kPointsPerDevice, reads);

  const int real_cycles = 4;
  const RunFigures real = Run(polled, 1.0, real_cycles);
  std::printf(
      "  real time, 5 s period, %d cycles (%.1f s): CPU %.4f s = %.3f %% of one core "
      "(target <= 1 %%), %d/%d cycles complete\n",
      real.cycles, real.wall_s, real.cpu_s, 100.0 * real.cpu_s / real.wall_s, real.complete,
      real.cycles);

  const double speed = 100.0;  // a 5 s period every 50 ms of wall time
  const RunFigures fast = Run(polled, speed, cycles);
  const double cpu_per_cycle_s = fast.cpu_s / std::max(fast.cycles, 1);
  std::printf(
      "  accelerated x%.0f, %d cycles (%.1f s): CPU per cycle %.3f ms = %.4f %% of one "
      "core at 5 s; %d/%d cycles complete\n",
      speed, fast.cycles, fast.wall_s, cpu_per_cycle_s * 1e3, 100.0 * cpu_per_cycle_s / 5.0,
      fast.complete, fast.cycles);
  std::printf(
      "  cycle latency (longest device poll): p50 %.2f ms, p99 %.2f ms, max %.2f ms "
      "(target p99 <= 50 ms)\n",
      Percentile(fast.latency_s, 0.5) * 1e3, Percentile(fast.latency_s, 0.99) * 1e3,
      Percentile(fast.latency_s, 1.0) * 1e3);
}

}  // namespace pvtwin::cli
