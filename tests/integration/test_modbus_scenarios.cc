// Integration through real Modbus: `pvtwin sim` as a separate process serving
// on loopback (RTU: through a socat pseudo-terminal pair), the poller of
// io/modbus/modbus_poller.h in this process, both on one accelerated clock.
//
// Each folder scenarios/NN-name/ holds scenario.toml: the config (plant and
// register map), the simulated start, the sky, the faults given to the
// simulator, and what to check. The checks follow from the faults:
//   * a device without an active fault delivers every channel in every
//     period (values, not NaN, not rejected);
//   * inside a fault window, drop / exception / delay / stray / wrong_unit
//     leave the device's channels missing (NaN, QC bit clear), nan / range /
//     freeze (after frozen_after_polls identical polls) leave them rejected
//     (QC bit set), glitch leaves them present with the short-wave
//     irradiance at the served glitch (the paper's night glitch passes the
//     edge), and the 1-min aggregation of the samples sets it to 0;
//   * from two periods after the window's end the device is back;
//   * the period in which a window begins or ends may go either way (the
//     request is sent a little after the period start);
//   * expect_bad_replies = DEVICE: that device's faulted replies count as
//     bad replies, not timeouts; every other device has none.
// Replies the simulator (built on libmodbus) cannot send, such as protocol id
// 7 or a wrong MBAP length, come from the raw server of
// test_modbus_hostile_server.cc.
// check_values: every value equals what the simulator served, computed here
// from the same deterministic plant (io/sim/plant_source.h) through the point's
// encoding and decoding: the value of the period's row, or of the next row
// when the request landed after it began (it must not be older: never stale).
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <toml++/toml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <mutex>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "config/plant_config.h"
#include "core/common/clock.h"
#include "core/data/aggregate.h"
#include "core/data/qc.h"
#include "io/modbus/modbus_poller.h"
#include "io/modbus/register_codec.h"
#include "io/platform/time_format.h"
#include "io/sim/modbus_sim_server.h"
#include "io/sim/plant_source.h"
#include "tests/support/child_process.h"
#include "tests/support/files.h"
#include "tests/support/ports.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using pvtwin::testing::ChildProcess;
using pvtwin::testing::ReadFile;

const fs::path kScenarioDir = PVTWIN_SCENARIO_DIR;
constexpr double kPeriodS = 5.0;
constexpr double kSpeed = 20.0;  // simulated seconds per wall second: a period is 250 ms

struct Scenario {
  std::string name;
  std::string description;
  fs::path config_path;
  std::int64_t start_s = 0;
  std::string start_at;
  double start_before_s = 0;
  std::vector<std::string> sky;
  int periods = 16;
  std::uint64_t seed = 1;
  int timeout_ms = 150;
  int frozen_after_polls = 0;
  std::vector<std::string> faults;
  bool check_values = false;
  double expect_step_w_m2 = 0;
  bool expect_pump_stop = false;
  std::string dead_device;
  std::string bad_replies_device;  // a device whose faulted replies count as bad replies
  bool rtu = false;
};

Scenario LoadScenario(const std::string& name) {
  const fs::path dir = kScenarioDir / name;
  const toml::table t = toml::parse_file((dir / "scenario.toml").string());
  Scenario s;
  s.name = name;
  s.description = t["description"].value_or(std::string());
  s.config_path = dir / t["config"].value_or(std::string("config.toml"));
  std::string error;
  EXPECT_TRUE(ParseTime(t["start"].value_or(std::string()), &s.start_s, &error)) << error;
  s.start_at = t["start_at"].value_or(std::string());
  s.start_before_s = t["start_before_s"].value_or(0.0);
  if (const auto* sky = t["sky"].as_array()) {
    for (const auto& v : *sky) s.sky.push_back(v.value_or(std::string()));
  }
  s.periods = t["periods"].value_or(16);
  s.seed = static_cast<std::uint64_t>(t["seed"].value_or(1));
  s.timeout_ms = t["timeout_ms"].value_or(150);
  s.frozen_after_polls = t["frozen_after_polls"].value_or(0);
  if (const auto* faults = t["faults"].as_array()) {
    for (const auto& v : *faults) s.faults.push_back(v.value_or(std::string()));
  }
  s.check_values = t["check_values"].value_or(false);
  s.expect_step_w_m2 = t["expect_step_w_m2"].value_or(0.0);
  s.expect_pump_stop = t["expect_pump_stop"].value_or(false);
  s.dead_device = t["dead_device"].value_or(std::string());
  s.bad_replies_device = t["expect_bad_replies"].value_or(std::string());
  s.rtu = t["rtu"].value_or(false);
  return s;
}

std::vector<std::string> ScenarioNames() { return pvtwin::testing::SubfolderNames(kScenarioDir); }

using testing::ClosedPort;

// socat's pseudo-terminal pair; both paths, or a failure message.
struct PtyPair {
  ChildProcess socat;
  std::string a;
  std::string b;
};

bool StartPtyPair(const fs::path& work, PtyPair* pair, std::string* why) {
  const char* candidates[] = {"/usr/bin/socat", "/bin/socat", "/usr/local/bin/socat"};
  std::string socat;
  for (const char* c : candidates) {
    if (fs::exists(c)) socat = c;
  }
  if (socat.empty()) {
    *why = "socat is not installed (apt-get install socat): the RTU scenario needs a pty pair";
    return false;
  }
  const fs::path log = work / "socat.err";
  if (!pair->socat.Start({socat, "-d", "-d", "pty,raw,echo=0", "pty,raw,echo=0"}, log.string())) {
    *why = "cannot start socat";
    return false;
  }
  const std::regex pty_line(R"(PTY is (/dev/\S+))");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  std::vector<std::string> ptys;
  while (ptys.size() < 2 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::string text = ReadFile(log);
    ptys.clear();
    for (std::sregex_iterator it(text.begin(), text.end(), pty_line), end; it != end; ++it) {
      ptys.push_back((*it)[1]);
    }
  }
  if (ptys.size() < 2) {
    *why = "socat did not report two ptys within 10 s: " + ReadFile(log);
    return false;
  }
  pair->a = ptys[0];
  pair->b = ptys[1];
  return true;
}

// The plant's value as the poller should see it: through the point's
// encoding and decoding (quantisation of scaled integers, f32 rounding).
double ThroughRegisters(const ModbusPoint& p, double channel_value) {
  std::vector<std::uint16_t> words(static_cast<std::size_t>(p.Count()));
  EncodePoint(p, ChannelToWireUnit(p.channel, channel_value), words);
  const DecodedValue v = DecodePoint(p, words);
  return WireToChannelUnit(p.channel, v.value);
}

enum class DeviceStatus { kPresent, kMissing, kRejected, kMixed };

const char* StatusName(DeviceStatus s) {
  switch (s) {
    case DeviceStatus::kPresent:
      return "present";
    case DeviceStatus::kMissing:
      return "missing";
    case DeviceStatus::kRejected:
      return "rejected";
    case DeviceStatus::kMixed:
      return "mixed";
  }
  return "?";
}

DeviceStatus StatusOf(const Sample& s, const ModbusConfig& map, std::size_t device) {
  int present = 0, missing = 0, rejected = 0, total = 0;
  for (const ModbusPoint& p : map.points) {
    if (p.device != device) continue;
    ++total;
    if (s.Rejected(p.channel)) {
      ++rejected;
    } else if (s.Has(p.channel)) {
      ++present;
    } else {
      ++missing;
    }
  }
  if (present == total) return DeviceStatus::kPresent;
  if (missing == total) return DeviceStatus::kMissing;
  if (rejected == total) return DeviceStatus::kRejected;
  return DeviceStatus::kMixed;
}

// The first time after noon (UTC) of the start's day at which the served
// flow goes from positive to 0.
std::int64_t FindPumpStop(PlantSource* source, std::int64_t day_start_s) {
  const Series day = source->History(day_start_s, 1);
  const auto& flow = day[Channel::kMdotKgS];
  for (std::size_t i = 1; i < day.size(); ++i) {
    if (day.time_s[i] >= day_start_s + 43200 && flow[i - 1] > 0 && flow[i] == 0) {
      return day.time_s[i];
    }
  }
  return -1;
}

// The first time after 09:00 UTC of the start's day at which the served
// in-plane irradiance jumps by more than step_w_m2 from one row to the next.
std::int64_t FindCloudEdge(PlantSource* source, std::int64_t day_start_s, double step_w_m2) {
  const Series day = source->History(day_start_s, 1);
  const auto& g = day[Channel::kGPoaWM2];
  for (std::size_t i = 1; i < day.size(); ++i) {
    if (day.time_s[i] >= day_start_s + 32400 && std::fabs(g[i] - g[i - 1]) > step_w_m2) {
      return day.time_s[i];
    }
  }
  return -1;
}

class ModbusScenarioTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ModbusScenarioTest, Run) {
  const Scenario sc = LoadScenario(GetParam());
  SCOPED_TRACE(sc.name + ": " + sc.description);
  const fs::path work =
      fs::temp_directory_path() / ("pvtwin_scenario_" + std::to_string(getpid()) + "_" + sc.name);
  fs::create_directories(work);

  // Configs: the simulator's and the poller's (RTU: the two pty ends).
  std::string config_text = ReadFile(sc.config_path);
  ASSERT_FALSE(config_text.empty()) << sc.config_path;
  PtyPair ptys;
  std::string poller_text = config_text;
  if (sc.rtu) {
    std::string why;
    ASSERT_TRUE(StartPtyPair(work, &ptys, &why)) << why;
    const auto put = [](std::string text, const std::string& path) {
      return std::regex_replace(text, std::regex("/dev/@SERIAL@"), path);
    };
    poller_text = put(config_text, ptys.a);
    config_text = put(config_text, ptys.b);
  }
  const fs::path sim_config = work / "sim.toml";
  std::ofstream(sim_config) << config_text;
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(ParseConfig(poller_text, sc.config_path.string(), &config, &errors))
      << (errors.empty() ? "" : errors[0].ToString());

  // The same plant as the simulator's, to know what it serves.
  PlantSourceOptions source_options;
  source_options.plant = config.plant;
  source_options.seed = sc.seed;
  for (const std::string& sky : sc.sky) {
    const std::optional<DayType> type = DayTypeFromName(sky);
    ASSERT_TRUE(type.has_value()) << "sky = " << sky;
    source_options.day_types.push_back(*type);
  }
  std::unique_ptr<PlantSource> truth = PlantSource::Create(source_options, &errors);
  ASSERT_NE(truth, nullptr);
  std::int64_t start_s = sc.start_s;
  std::int64_t pump_stop_s = -1;
  if (sc.start_at == "pump_stop") {
    pump_stop_s = FindPumpStop(truth.get(), sc.start_s);
    ASSERT_GT(pump_stop_s, 0) << "no pump stop in the served day";
    start_s = pump_stop_s - static_cast<std::int64_t>(sc.start_before_s);
    start_s -= start_s % 5;
  } else if (sc.start_at == "cloud_edge") {
    const std::int64_t edge_s = FindCloudEdge(truth.get(), sc.start_s, sc.expect_step_w_m2);
    ASSERT_GT(edge_s, 0) << "no cloud edge in the served day";
    start_s = edge_s - static_cast<std::int64_t>(sc.start_before_s);
    start_s -= start_s % 5;
  }

  // The simulator, on the test's clock.
  const double anchor_s = WallNowS();
  char anchor_text[64];
  std::snprintf(anchor_text, sizeof anchor_text, "%.6f", anchor_s);
  std::vector<std::string> argv = {PVTWIN_BINARY,
                                   "sim",
                                   "--config",
                                   sim_config.string(),
                                   "--ephemeral-ports",
                                   "--start",
                                   std::to_string(start_s),
                                   "--wall-anchor",
                                   anchor_text,
                                   "--speed",
                                   std::to_string(kSpeed),
                                   "--seed",
                                   std::to_string(sc.seed)};
  for (const std::string& sky : sc.sky) argv.insert(argv.end(), {"--sky", sky});
  for (const std::string& fault : sc.faults) argv.insert(argv.end(), {"--fault", fault});
  ChildProcess sim;
  ASSERT_TRUE(sim.Start(argv, (work / "sim.err").string()));
  std::string line;
  const std::regex listening(R"(listening (\S+) tcp [0-9.]+:([0-9]+))");
  while (sim.ReadLine(&line, 30.0) && !line.starts_with("ready")) {
    std::smatch m;
    if (!std::regex_match(line, m, listening)) continue;
    for (ModbusDevice& d : config.modbus.devices) {
      if (d.name == m[1]) d.port = std::stoi(m[2]);
    }
  }
  ASSERT_TRUE(line.starts_with("ready")) << "simulator not ready: " << ReadFile(work / "sim.err");
  for (ModbusDevice& d : config.modbus.devices) {
    d.timeout_ms = sc.timeout_ms;
    if (d.name == sc.dead_device) d.port = ClosedPort();
  }

  // The poller.
  const ScaledClock clock(static_cast<double>(start_s), anchor_s, kSpeed);
  PollerOptions options;
  options.period_s = kPeriodS;
  options.frozen_after_polls = sc.frozen_after_polls;
  std::vector<std::string> log;
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<Sample> samples;
  ModbusPoller poller(config.modbus, options, clock, [&](int priority, const std::string& text) {
    std::lock_guard<std::mutex> lock(mutex);
    log.push_back("<" + std::to_string(priority) + ">" + text);
  });
  poller.Start([&](const Sample& s) {
    std::lock_guard<std::mutex> lock(mutex);
    samples.push_back(s);
    cv.notify_all();
  });
  {
    std::unique_lock<std::mutex> lock(mutex);
    const double wall_s = sc.periods * kPeriodS / kSpeed + 10.0;
    cv.wait_for(lock, std::chrono::duration<double>(wall_s),
                [&] { return samples.size() >= static_cast<std::size_t>(sc.periods); });
  }
  const auto stop_begin = std::chrono::steady_clock::now();
  poller.Stop();
  const double stop_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - stop_begin).count();
  EXPECT_LT(stop_s, sc.timeout_ms / 1000.0 + 0.5) << "Stop() must be bounded by the timeout";
  EXPECT_TRUE(sim.WriteLine("quit"));
  EXPECT_EQ(sim.Wait(10.0), 0) << "the simulator must exit cleanly on quit";

  std::string log_text;
  for (const std::string& l : log) log_text += l + "\n";
  if (std::getenv("PVTWIN_SHOW_LOG") != nullptr) std::cerr << log_text;
  SCOPED_TRACE("poller log:\n" + log_text + "simulator stderr:\n" + ReadFile(work / "sim.err"));
  ASSERT_GE(samples.size(), static_cast<std::size_t>(sc.periods));

  // One sample per period, consecutive, aligned.
  for (std::size_t i = 1; i < samples.size(); ++i) {
    EXPECT_EQ(samples[i].ts_s - samples[i - 1].ts_s, 5) << "sample " << i;
  }
  EXPECT_EQ(samples[0].ts_s % 5, 0);

  // Device status per period against the fault windows.
  std::vector<Fault> faults;
  for (const std::string& text : sc.faults) {
    Fault f;
    std::string error;
    ASSERT_TRUE(ParseFault(text, &f, &error)) << error;
    faults.push_back(f);
  }
  int checked_in_fault = 0;
  for (const Sample& s : samples) {
    const double rel_s = static_cast<double>(s.ts_s - start_s);
    for (std::size_t d = 0; d < config.modbus.devices.size(); ++d) {
      const std::string& name = config.modbus.devices[d].name;
      const DeviceStatus status = StatusOf(s, config.modbus, d);
      std::string where =
          name + " at +" + std::to_string(static_cast<int>(rel_s)) + " s: " + StatusName(status);
      if (name == sc.dead_device) {
        EXPECT_EQ(status, DeviceStatus::kMissing) << where;
        continue;
      }
      bool ambiguous = false;
      bool inside = false;
      DeviceStatus expected_inside = DeviceStatus::kMissing;
      for (const Fault& f : faults) {
        if (f.device != name) continue;
        double begin_s = f.from_s;
        const double end_s = f.from_s + f.for_s;
        if (f.kind == FaultKind::kGlitch) {
          expected_inside = DeviceStatus::kPresent;
        } else if (f.kind == FaultKind::kNan || f.kind == FaultKind::kRange) {
          expected_inside = DeviceStatus::kRejected;
        } else if (f.kind == FaultKind::kFreeze) {
          expected_inside = DeviceStatus::kRejected;
          begin_s += sc.frozen_after_polls * kPeriodS;
        }
        if (rel_s >= begin_s - kPeriodS && rel_s < begin_s + kPeriodS) ambiguous = true;
        if (rel_s >= end_s - kPeriodS && rel_s < end_s + 2 * kPeriodS) ambiguous = true;
        if (rel_s >= begin_s && rel_s < end_s) inside = true;
      }
      if (ambiguous) continue;
      if (inside) {
        ++checked_in_fault;
        EXPECT_EQ(status, expected_inside) << where;
        for (const ModbusPoint& p : config.modbus.points) {
          if (expected_inside != DeviceStatus::kPresent || p.device != d ||
              !IsShortWave(p.channel)) {
            continue;
          }
          EXPECT_EQ(s.Get(p.channel), ThroughRegisters(p, kGlitchWM2))
              << where << ", " << ChannelName(p.channel);
        }
      } else {
        EXPECT_EQ(status, DeviceStatus::kPresent) << where;
      }
    }
  }
  if (!faults.empty()) {
    EXPECT_GT(checked_in_fault, 0) << "no period fell inside a fault window";
  }
  // The glitch becomes 0 W/m² in the 1-min rows, as in a CSV import: no
  // minute loses its irradiance and none is flagged for rejected readings.
  if (std::any_of(faults.begin(), faults.end(),
                  [](const Fault& f) { return f.kind == FaultKind::kGlitch; })) {
    MinuteRows minutes;
    std::string error;
    AggregateOptions aggregate;
    aggregate.area_m2 = config.plant.area_m2;
    ASSERT_TRUE(AggregateSamples(samples, aggregate, &minutes, &error)) << error;
    int corrected = 0;
    for (std::size_t m = 0; m < minutes.rows.size(); ++m) {
      EXPECT_EQ(minutes.qc_flags[m] & kQcRejectedValues, 0u) << "minute " << m;
      corrected += (minutes.qc_flags[m] & kQcIrradianceCorrected) != 0;
      for (const Channel c : kShortWaveChannels) {
        if (!minutes.rows.Has(c)) continue;
        EXPECT_TRUE(std::isfinite(minutes.rows[c][m])) << ChannelName(c) << " minute " << m;
        EXPECT_LT(minutes.rows[c][m], kIrradianceGlitchWM2) << ChannelName(c) << " minute " << m;
      }
    }
    EXPECT_GT(corrected, 0) << "no minute held a corrected glitch";
  }

  // Values equal to the served ones, never older than the period.
  if (sc.check_values) {
    int exact_row = 0;
    int next_row = 0;
    for (const Sample& s : samples) {
      const Sample row = truth->At(static_cast<double>(s.ts_s));
      const Sample next = truth->At(static_cast<double>(s.ts_s) + 5);
      bool all_exact = true;
      for (const ModbusPoint& p : config.modbus.points) {
        ASSERT_TRUE(s.Has(p.channel)) << ChannelName(p.channel) << " at " << s.ts_s;
        const double got = s.Get(p.channel);
        const double want = ThroughRegisters(p, row.Get(p.channel));
        const double want_next = ThroughRegisters(p, next.Get(p.channel));
        EXPECT_TRUE(got == want || got == want_next)
            << ChannelName(p.channel) << " " << TypeName(p.type) << " "
            << WordOrderName(p.word_order) << " at " << s.ts_s << ": got " << got << ", served "
            << want << " (next row " << want_next << ")";
        all_exact = all_exact && got == want;
      }
      (all_exact ? exact_row : next_row)++;
    }
    // Requests land just after the period start: nearly always its own row.
    EXPECT_GE(exact_row, static_cast<int>(samples.size()) * 3 / 4)
        << next_row << " samples had the next row's values";
  }

  if (sc.expect_step_w_m2 > 0) {
    double max_step = 0;
    for (std::size_t i = 1; i < samples.size(); ++i) {
      max_step = std::max(max_step, std::fabs(samples[i].Get(Channel::kGPoaWM2) -
                                              samples[i - 1].Get(Channel::kGPoaWM2)));
    }
    EXPECT_GT(max_step, sc.expect_step_w_m2) << "no cloud transient seen";
  }
  if (sc.expect_pump_stop) {
    int running = 0;
    int stopped = 0;
    for (const Sample& s : samples) {
      ASSERT_TRUE(s.Has(Channel::kMdotKgS)) << "flow must be a value at " << s.ts_s;
      if (s.ts_s >= pump_stop_s + 5) {
        EXPECT_EQ(s.Get(Channel::kMdotKgS), 0.0) << s.ts_s;
        ++stopped;
      } else if (s.ts_s < pump_stop_s - 5 && s.Get(Channel::kMdotKgS) > 0) {
        ++running;
      }
    }
    EXPECT_GT(running, 0);
    EXPECT_GT(stopped, 0);
  }

  // Counters: requests went out; one log line per state change, not per poll.
  const std::vector<DeviceStats> stats = poller.Stats();
  for (const DeviceStats& st : stats) {
    if (st.name != sc.dead_device) {
      EXPECT_GT(st.requests, static_cast<std::uint64_t>(sc.periods / 2)) << st.name;
    }
    // Replies that are not the request's are told apart from timeouts.
    if (st.name == sc.bad_replies_device) {
      EXPECT_GT(st.bad_replies, 0u) << st.name;
      EXPECT_EQ(st.timeouts, 0u) << st.name;
    } else {
      EXPECT_EQ(st.bad_replies, 0u) << st.name;
    }
  }
  EXPECT_LE(log.size(), 4 + 3 * faults.size() + (sc.dead_device.empty() ? 0 : 2)) << log_text;
  fs::remove_all(work);
}

INSTANTIATE_TEST_SUITE_P(Scenarios, ModbusScenarioTest, ::testing::ValuesIn(ScenarioNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return "s" + name;
                         });

// Time stepped by the test: the simulator (--stepped, "advance 5" on stdin)
// and the poller (a SteppedClock here) move together one period at a time,
// and the test waits for each period's reads before the next step. Every
// value must then be exactly the one of its own period's row.
TEST(ModbusStepped, EveryPeriodHoldsExactlyItsOwnRow) {
  const fs::path work = fs::temp_directory_path() / ("pvtwin_stepped_" + std::to_string(getpid()));
  fs::create_directories(work);
  const fs::path config_path = kScenarioDir / "../../../config/examples/sim-plant.toml";
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(ParseConfig(ReadFile(config_path), config_path.string(), &config, &errors));
  const std::int64_t start_s = 1718964000;  // 2024-06-21T10:00:00Z
  ChildProcess sim;
  ASSERT_TRUE(
      sim.Start({PVTWIN_BINARY, "sim", "--config", config_path.string(), "--ephemeral-ports",
                 "--stepped", "--start", std::to_string(start_s), "--seed", "5"},
                (work / "sim.err").string()));
  std::string line;
  const std::regex listening(R"(listening (\S+) tcp [0-9.]+:([0-9]+))");
  while (sim.ReadLine(&line, 30.0) && !line.starts_with("ready")) {
    std::smatch m;
    if (!std::regex_match(line, m, listening)) continue;
    for (ModbusDevice& d : config.modbus.devices) {
      if (d.name == m[1]) d.port = std::stoi(m[2]);
    }
  }
  ASSERT_TRUE(line.starts_with("ready")) << ReadFile(work / "sim.err");

  PlantSourceOptions source_options;
  source_options.plant = config.plant;
  source_options.seed = 5;
  std::unique_ptr<PlantSource> truth = PlantSource::Create(source_options, &errors);
  ASSERT_NE(truth, nullptr);

  SteppedClock clock(static_cast<double>(start_s));
  PollerOptions options;
  options.period_s = kPeriodS;
  std::mutex mutex;
  std::vector<Sample> samples;
  ModbusPoller poller(config.modbus, options, clock, [](int, const std::string&) {});
  const auto polls = [&] {
    std::uint64_t n = 0;
    for (const DeviceStats& st : poller.Stats()) n += st.polls;
    return n;
  };
  poller.Start([&](const Sample& s) {
    std::lock_guard<std::mutex> lock(mutex);
    samples.push_back(s);
  });
  const auto wait_for = [](const std::function<bool()>& done) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!done() && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return done();
  };
  constexpr int kSteps = 12;
  for (int step = 1; step <= kSteps; ++step) {
    const std::uint64_t before = polls();
    ASSERT_TRUE(sim.WriteLine("advance 5"));
    ASSERT_TRUE(sim.ReadLine(&line, 10.0));
    ASSERT_EQ(line, "ok " + std::to_string(start_s + 5 * step));
    clock.Advance(kPeriodS);
    ASSERT_TRUE(wait_for([&] { return polls() >= before + config.modbus.devices.size(); }))
        << "step " << step << ": the reads of the period did not happen";
  }
  ASSERT_TRUE(wait_for([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return samples.size() >= kSteps - 1;
  }));
  poller.Stop();
  EXPECT_TRUE(sim.WriteLine("quit"));
  EXPECT_EQ(sim.Wait(10.0), 0);

  std::lock_guard<std::mutex> lock(mutex);
  for (const Sample& s : samples) {
    EXPECT_EQ(s.rejected_mask, 0u);
    const Sample row = truth->At(static_cast<double>(s.ts_s));
    for (const ModbusPoint& p : config.modbus.points) {
      EXPECT_EQ(s.Get(p.channel), ThroughRegisters(p, row.Get(p.channel)))
          << ChannelName(p.channel) << " at " << s.ts_s;
    }
  }
  EXPECT_EQ(samples.front().ts_s, start_s + 5);
  fs::remove_all(work);
}

TEST(ModbusScenarios, HasTheNumberedCatalogue) {
  const std::vector<std::string> names = ScenarioNames();
  for (const char* required : {"01-clear-day", "02-cloud-transient", "03-pump-off",
                               "04-device-dropout", "05-garbage-registers"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
}

}  // namespace
}  // namespace pvtwin
