// The plant simulator's parts without a network: fault specs, the plant
// source (reproducible, History = At), and `pvtwin sim` as a process: --export
// and the stdin control protocol of the stepped mode.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/synth/synthetic_plant.h"
#include "io/files/csv.h"
#include "io/sim/modbus_sim_server.h"
#include "io/sim/plant_source.h"
#include "tests/support/child_process.h"
#include "tests/support/files.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;

const std::string kExampleMap =
    std::string(PVTWIN_GOLDEN_DIR) + "/../../config/examples/sim-plant.toml";
constexpr std::int64_t kJune21 = 1718928000;  // 2024-06-21T00:00:00Z

TEST(SimFault, ParsesTheTextForm) {
  Fault f;
  std::string error;
  ASSERT_TRUE(ParseFault("collector:delay:from=60:for=30:ms=750", &f, &error)) << error;
  EXPECT_EQ(f.device, "collector");
  EXPECT_EQ(f.kind, FaultKind::kDelay);
  EXPECT_EQ(f.from_s, 60);
  EXPECT_EQ(f.for_s, 30);
  EXPECT_EQ(f.delay_ms, 750);
  ASSERT_TRUE(ParseFault("weather:freeze:for=5:from=0", &f, &error)) << error;
  EXPECT_EQ(f.kind, FaultKind::kFreeze);
  ASSERT_TRUE(ParseFault("weather:wrong_unit:from=0:for=5", &f, &error)) << error;
  EXPECT_EQ(f.kind, FaultKind::kWrongUnit);
  ASSERT_TRUE(ParseFault("weather:glitch:from=0:for=5", &f, &error)) << error;
  EXPECT_EQ(f.kind, FaultKind::kGlitch);
}

TEST(SimFault, RejectsBadText) {
  Fault f;
  std::string error;
  for (const char* bad : {"collector:drop", "collector:melt:from=0:for=5", "collector:nan:from=0",
                          "collector:nan:from=0:for=0", "collector:nan:from=x:for=5",
                          ":nan:from=0:for=5", "collector:nan:from=0:for=5:depth=3"}) {
    EXPECT_FALSE(ParseFault(bad, &f, &error)) << bad;
    EXPECT_NE(error.find(bad), std::string::npos) << "the message quotes the spec: " << error;
  }
}

std::unique_ptr<PlantSource> MakeSource(std::uint64_t seed) {
  PlantSourceOptions options;
  options.plant = DesignExamplePlant();
  options.seed = seed;
  Diagnostics errors;
  return PlantSource::Create(options, &errors);
}

TEST(PlantSource, IsReproducibleAndAtAgreesWithHistory) {
  auto a = MakeSource(7);
  auto b = MakeSource(7);
  auto c = MakeSource(8);
  ASSERT_TRUE(a && b && c);
  const Series history = a->History(kJune21 + 43200, 1);  // noon to noon: two day chunks
  ASSERT_EQ(history.size(), 17280u);
  EXPECT_EQ(history.time_s.front(), kJune21 + 43200);
  EXPECT_EQ(history.time_s.back(), kJune21 + 43200 + 86400 - 5);
  int differs_from_other_seed = 0;
  for (std::size_t i = 0; i < history.size(); i += 997) {
    const double t = static_cast<double>(history.time_s[i]) + 2.5;  // inside the row
    const Sample sa = a->At(t);
    const Sample sb = b->At(t);
    EXPECT_EQ(sa.ts_s, history.time_s[i]);
    for (const Channel ch : {Channel::kTOutC, Channel::kPElW, Channel::kGPoaWM2, Channel::kTAmbC}) {
      EXPECT_EQ(sa.Get(ch), history.At(ch, i)) << ChannelName(ch) << " row " << i;
      EXPECT_EQ(sa.Get(ch), sb.Get(ch));
    }
    differs_from_other_seed += c->At(t).Get(Channel::kTAmbC) != sa.Get(Channel::kTAmbC);
  }
  EXPECT_GT(differs_from_other_seed, 10);
}

TEST(PlantSource, ReplaysACanonicalCsv) {
  const fs::path path =
      fs::temp_directory_path() / ("pvtwin_replay_" + std::to_string(getpid()) + ".csv");
  std::ofstream(path) << "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n"
                         "2024-06-21T10:00:00Z,30,35,0.03,800,22,120\n"
                         "2024-06-21T10:01:00Z,31,36.5,0.03,810,22.5,121\n"
                         "2024-06-21T10:02:00Z,32,38,0.03,820,23,122\n";
  PlantSourceOptions options;
  options.plant = DesignExamplePlant();
  options.replay_csv = path.string();
  Diagnostics errors;
  auto source = PlantSource::Create(options, &errors);
  ASSERT_NE(source, nullptr) << (errors.empty() ? "" : errors[0].ToString());
  const double t0 = static_cast<double>(kJune21 + 36000);
  EXPECT_FALSE(source->At(t0 - 1).Has(Channel::kTOutC));  // before the file
  EXPECT_EQ(source->At(t0).Get(Channel::kTOutC), 35);
  EXPECT_EQ(source->At(t0 + 59.9).Get(Channel::kTOutC), 35);  // a row lasts one step
  EXPECT_EQ(source->At(t0 + 60).Get(Channel::kTOutC), 36.5);
  EXPECT_EQ(source->At(t0 + 179).Get(Channel::kPElW), 122);
  EXPECT_FALSE(source->At(t0 + 180).Has(Channel::kTOutC));  // after the file
  EXPECT_EQ(source->History(kJune21, 1).size(), 3u);
  fs::remove(path);
}

TEST(PlantSource, RejectsAnUnknownTruthVariant) {
  PlantSourceOptions options;
  options.plant = DesignExamplePlant();
  options.truth_variant = "3N";
  Diagnostics errors;
  EXPECT_EQ(PlantSource::Create(options, &errors), nullptr);
  ASSERT_FALSE(errors.empty());
  EXPECT_EQ(errors[0].field, "--truth-variant");
}

TEST(SimCommand, ExportWritesTheSamePlantAsServed) {
  const fs::path dir =
      fs::temp_directory_path() / ("pvtwin_sim_export_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const auto run = testing::RunPvtwin(
      dir, "sim --config '" + kExampleMap +
               "' --export out.csv --days 2 --step 5 --start 2024-06-21T00:00:00Z --seed 3");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  Series csv;
  Diagnostics errors;
  ASSERT_TRUE(ReadCanonicalCsv((dir / "out.csv").string(), {}, &csv, &errors, nullptr))
      << (errors.empty() ? "" : errors[0].ToString());
  ASSERT_EQ(csv.size(), 2u * 17280u);
  auto source = MakeSource(3);
  for (std::size_t i = 0; i < csv.size(); i += 1234) {
    const Sample s = source->At(static_cast<double>(csv.time_s[i]));
    for (const Channel ch : {Channel::kTInC, Channel::kQThW, Channel::kMdotKgS, Channel::kAoiRad}) {
      EXPECT_NEAR(csv.At(ch, i), s.Get(ch), 1e-9 * (1 + std::fabs(s.Get(ch)))) << ChannelName(ch);
    }
  }
  // 1-min rows are averages of twelve 5 s rows.
  const auto minute = testing::RunPvtwin(
      dir, "sim --config '" + kExampleMap +
               "' --export min.csv --days 1 --step 60 --start 2024-06-21T00:00:00Z --seed 3");
  ASSERT_EQ(minute.exit_code, 0) << minute.err;
  Series min;
  ASSERT_TRUE(ReadCanonicalCsv((dir / "min.csv").string(), {}, &min, &errors, nullptr));
  ASSERT_EQ(min.size(), 1440u);
  double sum = 0;
  for (int k = 0; k < 12; ++k) sum += csv.At(Channel::kTAmbC, 720 * 12 + k);
  EXPECT_NEAR(min.At(Channel::kTAmbC, 720), sum / 12, 1e-9);
  fs::remove_all(dir);
}

TEST(SimCommand, SteppedTimeAndControlProtocol) {
  const fs::path dir = fs::temp_directory_path() / ("pvtwin_sim_ctl_" + std::to_string(getpid()));
  fs::create_directories(dir);
  testing::ChildProcess sim;
  ASSERT_TRUE(sim.Start({PVTWIN_BINARY, "sim", "--config", kExampleMap, "--ephemeral-ports",
                         "--stepped", "--start", std::to_string(kJune21 + 36000)},
                        (dir / "sim.err").string()));
  std::string line;
  int listening = 0;
  while (sim.ReadLine(&line, 30.0) && !line.starts_with("ready")) {
    listening += line.starts_with("listening ");
  }
  ASSERT_TRUE(line.starts_with("ready")) << testing::ReadFile(dir / "sim.err");
  EXPECT_EQ(listening, 2);
  const auto ask = [&](const std::string& command) {
    std::string answer;
    EXPECT_TRUE(sim.WriteLine(command));
    EXPECT_TRUE(sim.ReadLine(&answer, 10.0)) << command;
    return answer;
  };
  EXPECT_EQ(ask("time"), "ok " + std::to_string(kJune21 + 36000));
  EXPECT_EQ(ask("advance 65"), "ok " + std::to_string(kJune21 + 36065));
  EXPECT_EQ(ask("time"), "ok " + std::to_string(kJune21 + 36065));
  EXPECT_EQ(ask("fault collector:nan:from=100:for=10"), "ok fault collector:nan:from=100:for=10");
  EXPECT_TRUE(ask("fault inverter:nan:from=100:for=10").starts_with("error "));
  EXPECT_TRUE(ask("fault collector:nan").starts_with("error "));
  EXPECT_TRUE(ask("advance -5").starts_with("error "));
  EXPECT_TRUE(ask("jump").starts_with("error unknown command"));
  EXPECT_EQ(ask("quit"), "ok quit");
  EXPECT_EQ(sim.Wait(10.0), 0);
  fs::remove_all(dir);
}

TEST(SimCommand, BadInputExitsWithTwo) {
  const fs::path dir = fs::temp_directory_path();
  const auto no_map = testing::RunPvtwin(
      dir, "sim --config '" + std::string(PVTWIN_GOLDEN_DIR) + "/config/ok_minimal/config.toml'");
  EXPECT_EQ(no_map.exit_code, 2);
  EXPECT_NE(no_map.err.find("no [[modbus.device]]"), std::string::npos) << no_map.err;
  const auto bad_fault = testing::RunPvtwin(
      dir, "sim --config '" + kExampleMap + "' --fault collector:melt:from=0:for=5");
  EXPECT_EQ(bad_fault.exit_code, 2);
  EXPECT_NE(bad_fault.err.find("unknown kind 'melt'"), std::string::npos) << bad_fault.err;
  const auto bad_variant = testing::RunPvtwin(
      dir, "sim --config '" + kExampleMap + "' --truth-variant 3N --export x.csv");
  EXPECT_EQ(bad_variant.exit_code, 2);
  EXPECT_NE(bad_variant.err.find("--truth-variant = 3N"), std::string::npos) << bad_variant.err;
}

}  // namespace
}  // namespace pvtwin
