// pvtwin-bench: speed figures of the model and of identification, printed
// as medians over repeated runs on synthetic data with a recorded seed.
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "core/common/units.h"
#include "core/model/sensitivities.h"
#include "core/model/thermal_model.h"
#include "core/synth/synthetic_plant.h"
#include "daemon/bench/bench.h"
#include "daemon/commands/commands.h"

namespace pvtwin::cli {

double SelfCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

namespace {

struct BenchArgs {
  std::vector<std::string> what = {"sim"};
  int repeats = 21;
  std::uint64_t seed = 1;
  double daemon_seconds = 60.0;
  std::string data_dir;
};

// Median time of `repeats` calls of run(), after one warm-up call.
template <typename Run>
double MedianTime(int repeats, const Run& run) {
  run();
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    run();
    times.push_back(SecondsSince(start));
  }
  return Median(times);
}

// Milliseconds of a fixed workload on the calling thread: a chain of 1e7
// dependent multiply-adds, which neither memory nor the compiler can
// shorten (about 20 ms on the AMD EPYC behind doc/performance.md's figures).
double FixedWorkloadMs() {
  volatile double seed = 1.0;
  double x = seed;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 10'000'000; ++i) x = x * 0.9999999 + 1e-7;
  const double ms = 1e3 * SecondsSince(start);
  seed = x;
  return ms;
}

// Milliseconds of one pass over `memory` reading one double per 64-byte
// line: bound by the memory's bandwidth, which a neighbour on a shared
// machine takes share of without slowing the core's own arithmetic.
double MemoryPassMs(const std::vector<double>& memory) {
  const auto start = std::chrono::steady_clock::now();
  double sum = 0.0;
  for (std::size_t i = 0; i < memory.size(); i += 8) sum += memory[i];
  const double ms = 1e3 * SecondsSince(start);
  volatile double sink = sum;
  (void)sink;
  return ms;
}

// The fixed workloads' median times (of 5) on each core the process may run
// on, one thread pinned to each in turn: on a shared virtual machine whose
// cores are at times of unequal speed, or slower for minutes, the figures
// that follow are read against these. Printed before and after the
// benchmarks.
void PrintCoreSpeeds(const char* when) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return;
  const std::vector<double> memory(std::size_t{8} << 20, 1.0);  // 64 MB, written once
  std::string line;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (!CPU_ISSET(cpu, &allowed)) continue;
    double chain_ms = 0.0;
    double memory_ms = 0.0;
    bool pinned = false;
    std::thread worker([&] {
      cpu_set_t one;
      CPU_ZERO(&one);
      CPU_SET(cpu, &one);
      pinned = pthread_setaffinity_np(pthread_self(), sizeof one, &one) == 0;
      std::vector<double> chain, pass;
      for (int r = 0; r < 5; ++r) {
        chain.push_back(FixedWorkloadMs());
        pass.push_back(MemoryPassMs(memory));
      }
      chain_ms = Median(chain);
      memory_ms = Median(pass);
    });
    worker.join();
    char buf[96];
    std::snprintf(buf, sizeof buf, "%scpu%d %.1f / %.1f ms%s", line.empty() ? "" : ", ", cpu,
                  chain_ms, memory_ms, pinned ? "" : " (not pinned)");
    line += buf;
  }
  std::printf(
      "cores %s: fixed workloads (1e7 dependent multiply-adds / a pass over 64 MB, medians of 5) "
      "took %s\n",
      when, line.c_str());
  std::fflush(stdout);
}

// One 14-day, 1-min simulation (20 160 rows) of each variant, and where the
// variant has them the run with sensitivities to its default free
// parameters (what identification's Jacobian takes), with its cost in plain
// runs.
void BenchSimulation(const BenchArgs& a) {
  const Plant plant = DesignExamplePlant();
  WeatherOptions weather;
  weather.num_days = 14;
  weather.step_s = 60.0;
  weather.seed = a.seed;
  const Series series = GenerateWeather(plant, weather);
  std::printf("simulation: 14 days at 1 min (%zu rows), weather seed %llu, median of %d runs\n",
              series.size(), static_cast<unsigned long long>(a.seed), a.repeats);
  std::printf("  %-24s %12s %14s %18s %9s %12s\n", "variant", "median (ms)", "per row (ns)",
              "sensitivities (ms)", "/plain", "2 threads");
  std::vector<std::string> variants = PaperVariants();
  variants.push_back("1N1Cwr+transport_delay");
  variants.push_back("1N1Cwr+pv_clipping+shading+soiling+clock_offset");
  for (const std::string& name : variants) {
    ModelSpec spec;
    std::string error;
    ParseVariant(name, &spec, &error);
    Drivers drivers;
    if (!PrepareDrivers(series, plant, spec, &drivers, &error)) {
      std::printf("  %-24s %s\n", name.c_str(), error.c_str());
      continue;
    }
    const ParamVector params = ReferenceTruthParams(plant);
    SimOutputs out;
    const double median = MedianTime(a.repeats, [&] { Simulate(drivers, params, &out); });
    std::printf("  %-24s %12.3f %14.1f", name.c_str(), median * 1e3,
                median * 1e9 / static_cast<double>(series.size()));
    // The default free parameters that no effect hook reads: the columns
    // of the run with sensitivities (identification differences the rest).
    std::vector<Param> free_params;
    const auto free = DefaultFreeParams(spec);
    for (std::size_t i = 0; i < kNumParams; ++i) {
      if (free.test(i)) free_params.push_back(static_cast<Param>(i));
    }
    const std::vector<Param> wrt = WithoutHookParams(spec, free_params);
    if (SensitivitiesSupported(spec, wrt, nullptr)) {
      SimSensitivities sens;
      const double sens_s =
          MedianTime(a.repeats, [&] { SimulateSensitivities(drivers, params, wrt, &sens); });
      // The columns split over two threads (SimSensitivities::threads), as
      // `calibrate` runs them.
      sens.threads = 2;
      const double sens2_s =
          MedianTime(a.repeats, [&] { SimulateSensitivities(drivers, params, wrt, &sens); });
      std::printf(" %12.3f (%2zu) %9.2f %12.3f", sens_s * 1e3, wrt.size(), sens_s / median,
                  sens2_s * 1e3);
    }
    std::printf("\n");
  }
}

}  // namespace

void ConfigureBench(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = &app;
  cmd->description(
      "pvtwin-bench: print speed figures (medians over repeated runs, one core unless noted) on synthetic data,\n"
      "before and after each core's time for a fixed workload (cores of a shared machine may\n"
      "differ in speed, and drift):\n"
      "  sim    one 14-day 1-min simulation of each variant\n"
      "  ident  identification of 2N1Ccolwr: 14 days at 1 min and at 5 s, the\n"
      "         algorithm comparison behind the default, and the whole `pvtwin\n"
      "         calibrate` process on the 1-min days\n"
      "  table6 the paper's Table 6 protocol (9 variants x 29 test days) on both cores,\n"
      "         from Table 3 and again with warm starts (backtest --warm-start)\n"
      "  store  the SQLite store: 14 days of 5 s samples ingested, aggregated, read back\n"
      "  daemon CPU and memory of `pvtwin run` polling `pvtwin sim` at 5 s (real time)\n"
      "  poll   the Modbus poller, 2 devices x 40 points, against a simulator on loopback\n"
      "         (CPU at real time; latency over max(400, --repeats) accelerated cycles)\n"
      "  effects each effect of the library: fit time and held-out MAE of base + effect\n"
      "         on 14 + 7 days of synthetic truth data with that effect\n"
      "  diagnose one gap diagnosis, 14 + 7 days at 1 min, every effect, both cores\n"
      "  upload a 30-day backlog of 1-min rows into a PostgreSQL the bench starts itself:\n"
      "         rows/s and the uploader's CPU time (needs Debian's postgresql package)");
  cmd->add_option(
         "what", args->what,
         "what to benchmark: sim, ident, table6, store, daemon, poll, effects, diagnose, upload")
      ->check(CLI::IsMember(
          {"sim", "ident", "table6", "store", "daemon", "poll", "effects", "diagnose", "upload"}));
  cmd->add_option("--repeats", args->repeats, "runs per figure (median)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--seed", args->seed, "seed of the synthetic weather");
  cmd->add_option("--data-dir", args->data_dir,
                  "ident: write its 1-min training and held-out days there (train.csv, "
                  "held_out.csv), its 5-s training days (train_5s.csv) and plant.toml "
                  "(config/examples/plant.toml's plant), and time `pvtwin calibrate` on them "
                  "(default: a temporary directory, removed after)");
  cmd->add_option("--daemon-seconds", args->daemon_seconds, "measuring time of `bench daemon`")
      ->check(CLI::PositiveNumber);
  cmd->callback([args] {
    PrintCoreSpeeds("before");
    for (const std::string& w : args->what) {
      if (w == "sim") BenchSimulation(*args);
      if (w == "ident") BenchIdentification(args->repeats, args->seed, args->data_dir);
      if (w == "table6") BenchTable6(args->seed);
      if (w == "store") BenchStore(args->repeats, args->seed);
      if (w == "daemon") BenchDaemon(args->daemon_seconds);
      if (w == "poll") BenchPoll(std::max(args->repeats, 400), args->seed);
      if (w == "effects") BenchEffects(std::min(args->repeats, 3), args->seed);
      if (w == "diagnose") BenchDiagnosis(args->seed);
      if (w == "upload") BenchUpload(args->seed);
    }
    PrintCoreSpeeds("after");
    SetExitCode(kExitOk);
  });
}

}  // namespace pvtwin::cli
