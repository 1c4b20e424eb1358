// `pvtwin poll --once` against the real `pvtwin sim` on loopback: every
// point of the register map is printed with its value, unit and raw
// registers; a value the daemon would reject carries the reason; a device
// that fails is named with its endpoint, unit id, the read and libmodbus's
// error, and the exit code says so.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "tests/support/child_process.h"
#include "tests/support/files.h"
#include "tests/support/ports.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using testing::ChildProcess;
using testing::ReadFile;

const fs::path kSimPlant =
    fs::path(PVTWIN_SCENARIO_DIR) / "../../../config/examples/sim-plant.toml";
constexpr std::int64_t kNoonS = 1718971200;  // 2024-06-21T12:00:00Z

using testing::ClosedPort;

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The example plant with its flow meter mapped as a volume flow in L/h.
std::string PlantWithVolumeFlow() {
  std::string text = ReadFile(kSimPlant);
  text = Replace(text, "channel = \"flow_kg_s\"", "channel = \"flow_l_h\"");
  text = Replace(text, "scale = 1e-5\nvalid_min = 0\nvalid_max = 0.6",
                 "scale = 0.1\nvalid_min = 0\nvalid_max = 2000");
  return text;
}

class PollOnce : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("pvtwin_poll_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Starts `pvtwin sim` on the config, time standing at noon, with the
  // faults; the device names and their ports.
  std::map<std::string, int> StartSim(const fs::path& config,
                                      const std::vector<std::string>& faults) {
    std::vector<std::string> argv = {PVTWIN_BINARY,
                                     "sim",
                                     "--config",
                                     config.string(),
                                     "--ephemeral-ports",
                                     "--stepped",
                                     "--start",
                                     std::to_string(kNoonS),
                                     "--seed",
                                     "3",
                                     "--sky",
                                     "clear"};
    for (const std::string& f : faults) {
      argv.push_back("--fault");
      argv.push_back(f);
    }
    std::map<std::string, int> ports;
    if (!sim_.Start(argv, (dir_ / "sim.err").string())) return ports;
    std::string line;
    const std::regex listening(R"(listening (\S+) tcp [0-9.]+:([0-9]+))");
    while (sim_.ReadLine(&line, 30.0) && !line.starts_with("ready")) {
      std::smatch m;
      if (std::regex_match(line, m, listening)) ports[m[1]] = std::stoi(m[2]);
    }
    return ports;
  }

  // The config text with the example's ports replaced.
  fs::path WriteConfig(std::string text, int collector_port, int weather_port) {
    text = Replace(text, "port = 5020", "port = " + std::to_string(collector_port));
    text = Replace(text, "port = 5021", "port = " + std::to_string(weather_port));
    const fs::path path = dir_ / "poll.toml";
    std::ofstream(path) << text;
    return path;
  }

  fs::path dir_;
  ChildProcess sim_;
};

TEST_F(PollOnce, PrintsEveryPointWithValueUnitAndRawRegisters) {
  const fs::path sim_config = dir_ / "sim.toml";
  std::ofstream(sim_config) << PlantWithVolumeFlow();
  const std::map<std::string, int> ports = StartSim(sim_config, {});
  ASSERT_EQ(ports.size(), 2u) << ReadFile(dir_ / "sim.err");
  const fs::path config =
      WriteConfig(PlantWithVolumeFlow(), ports.at("collector"), ports.at("weather"));
  const testing::ProcessResult r =
      testing::RunPvtwin(dir_, "poll --once --config '" + config.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("2 of 2 device(s) read"), std::string::npos) << r.out;
  // t_in_c: i16 at input 0, 0.01 °C steps.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      r.out, m,
      std::regex(R"(collector t_in_c \(input 0 i16\): (-?[0-9.]+) °C; raw 0x([0-9a-f]{4})\n)")))
      << r.out;
  EXPECT_NEAR(std::stod(m[1]), static_cast<std::int16_t>(std::stoi(m[2], nullptr, 16)) * 0.01,
              1e-9);
  // The volume flow in L/h, and in kg/s through the example's 1040 kg/m³.
  ASSERT_TRUE(std::regex_search(
      r.out, m,
      std::regex(R"(collector flow_l_h \(input 3 u16\): ([0-9.e+-]+) L/h = ([0-9.e+-]+) kg/s; )"
                 R"(raw 0x[0-9a-f]{4}\n)")))
      << r.out;
  const double l_h = std::stod(m[1]);
  EXPECT_GT(l_h, 0.0) << "the pump runs at noon in June";
  EXPECT_NEAR(std::stod(m[2]), l_h * 1040.0 / 3.6e6, 1e-5 * std::stod(m[2]));
  // Every point of the map has its line: one "; raw 0x" per point.
  const std::string map = ReadFile(kSimPlant);
  std::size_t points = 0;
  for (std::size_t at = map.find("[[modbus.point]]"); at != std::string::npos;
       at = map.find("[[modbus.point]]", at + 1)) {
    ++points;
  }
  std::size_t lines = 0;
  for (std::size_t at = r.out.find("; raw 0x"); at != std::string::npos;
       at = r.out.find("; raw 0x", at + 1)) {
    ++lines;
  }
  EXPECT_EQ(lines, points) << r.out;
}

TEST_F(PollOnce, RejectedValuesCarryTheirReason) {
  const std::map<std::string, int> ports = StartSim(kSimPlant, {"collector:nan:from=0:for=86400"});
  ASSERT_EQ(ports.size(), 2u) << ReadFile(dir_ / "sim.err");
  const fs::path config =
      WriteConfig(ReadFile(kSimPlant), ports.at("collector"), ports.at("weather"));
  const testing::ProcessResult r =
      testing::RunPvtwin(dir_, "poll --once --config '" + config.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  // t_in_c sends its sentinel -32768 (raw 0x8000).
  EXPECT_NE(r.out.find("collector t_in_c (input 0 i16): rejected: raw -32768 is the nan_value "
                       "sentinel; raw 0x8000\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("collector t_out_c (input 1 f32): rejected: not a number"),
            std::string::npos)
      << r.out;
}

// The paper's night glitch (6000 W/m²) is no rejection: the daemon keeps it
// and its 1-min row carries 0 W/m² (paper Table 2), as a CSV import does.
// The register map without valid ranges: only the physical limits judge.
TEST_F(PollOnce, TheNightGlitchIsKeptAndSaysItBecomesZero) {
  const fs::path map = fs::path(PVTWIN_SCENARIO_DIR) / "13-physical-limits/config.toml";
  const std::map<std::string, int> ports = StartSim(map, {"weather:glitch:from=0:for=86400"});
  ASSERT_EQ(ports.size(), 2u) << ReadFile(dir_ / "sim.err");
  const fs::path config = WriteConfig(ReadFile(map), ports.at("collector"), ports.at("weather"));
  const testing::ProcessResult r =
      testing::RunPvtwin(dir_, "poll --once --config '" + config.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("weather ghi_w_m2 (input 0 f32): 6000 W/m² (the paper's night glitch "
                       "(above 5000 W/m²): stored as read, 0 W/m² in the 1-min row); raw "),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("rejected"), std::string::npos) << r.out;
}

TEST_F(PollOnce, AFailingDeviceIsNamedWithItsReadAndTheExitCodeIsOne) {
  const std::map<std::string, int> ports =
      StartSim(kSimPlant, {"weather:exception:from=0:for=86400"});
  ASSERT_EQ(ports.size(), 2u) << ReadFile(dir_ / "sim.err");
  const int closed = ClosedPort();
  // The weather station answers with an exception.
  fs::path config = WriteConfig(ReadFile(kSimPlant), ports.at("collector"), ports.at("weather"));
  testing::ProcessResult r =
      testing::RunPvtwin(dir_, "poll --once --config '" + config.string() + "'");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("collector t_in_c"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 of 2 device(s) read"), std::string::npos) << r.out;
  EXPECT_TRUE(std::regex_search(
      r.err, std::regex("device weather \\(127\\.0\\.0\\.1:" + std::to_string(ports.at("weather")) +
                        " unit 2: read input address [0-9]+ count [0-9]+: .+\\)")))
      << r.err;
  // Nothing listens on the collector's port.
  config = WriteConfig(ReadFile(kSimPlant), closed, ports.at("weather"));
  r = testing::RunPvtwin(dir_, "poll --once --config '" + config.string() + "'");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("device collector (127.0.0.1:" + std::to_string(closed) +
                       " unit 1: connect failed: Connection refused)"),
            std::string::npos)
      << r.err;
}

TEST_F(PollOnce, ABadConfigIsExitCodeTwo) {
  const fs::path config = dir_ / "bad.toml";
  std::ofstream(config) << ReadFile(kSimPlant) << "\n[poll]\nperiod_s = -1\n";
  const testing::ProcessResult r =
      testing::RunPvtwin(dir_, "poll --once --config '" + config.string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_EQ(r.out, "");
}

}  // namespace
}  // namespace pvtwin
