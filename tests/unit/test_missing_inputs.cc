// A missing input is a missing row, never a crash: every variant and every
// effect, every input channel missing on one row, an hour or a day, at the
// start, middle and end of the data. The rows without inputs are the only
// rows without outputs. Then the real commands on a CSV with the gap that
// once crashed them (g_poa_w_m2 empty while GHI and DHI are logged).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/effects/effects.h"
#include "core/model/thermal_model.h"
#include "core/model/variant.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/effect_named.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using testing::ProcessResult;
using testing::ReadFile;
using testing::RunPvtwin;

// Two days of the synthetic plant at 5 min with every weather channel the
// generator logs (POA, GHI/DHI, wind, long-wave, ...).
Series TwoDays(const Plant& plant) {
  SyntheticOptions o;
  std::string error;
  EXPECT_TRUE(DefaultSyntheticOptions(plant, "2N1CcolwrI", 2, 3, &o, &error)) << error;
  o.weather.step_s = 300.0;
  o.defects = {};
  return MakeSyntheticPlantData(plant, o);
}

// The model inputs of the series (outputs and the valid flag are not inputs).
std::vector<Channel> InputChannels(const Series& s) {
  std::vector<Channel> inputs;
  for (const ChannelInfo& info : kChannels) {
    const Channel c = info.channel;
    if (c == Channel::kPElW || c == Channel::kQThW || c == Channel::kValid || c == Channel::kTPvC ||
        c == Channel::kTOutC || !s.Has(c)) {
      continue;
    }
    inputs.push_back(c);
  }
  return inputs;
}

struct Gap {
  const char* what;
  std::size_t first, count;
};

std::vector<Gap> Gaps(std::size_t rows, double step_s) {
  const auto per = [&](double seconds) { return static_cast<std::size_t>(seconds / step_s); };
  const std::size_t hour = per(3600), day = per(86400);
  return {{"one row at the start", 0, 1},
          {"one row in the middle", rows / 2, 1},
          {"one row at the end", rows - 1, 1},
          {"an hour at the start", 0, hour},
          {"an hour at noon", per(12 * 3600), hour},
          {"an hour at the end", rows - hour, hour},
          {"the first day", 0, day},
          {"the last day", rows - day, day}};
}

// The paper's nine variants, and 1N1Cr with each effect of the library.
std::vector<ModelSpec> VariantsUnderTest() {
  std::vector<ModelSpec> v;
  for (const std::string& name : PaperVariants()) v.push_back(testing::SpecOf(name));
  const ModelSpec base = testing::SpecOf("1N1Cr");
  for (const EffectModule* e : EffectRegistry()) v.push_back(WithEffect(base, *e));
  return v;
}

TEST(MissingInputs, EveryVariantEffectAndChannelSimulatesAroundTheGap) {
  const Plant plant = DesignExamplePlant();
  const Series full = TwoDays(plant);
  ASSERT_TRUE(full.Has(Channel::kGhiWM2) && full.Has(Channel::kDhiWM2) &&
              full.Has(Channel::kGPoaWM2));
  const std::vector<Channel> inputs = InputChannels(full);
  ASSERT_GE(inputs.size(), 7u);
  SimOutputs out;
  int runs = 0;
  for (const ModelSpec& spec : VariantsUnderTest()) {
    const std::string name = spec.Name();
    const ParamVector params = TruthParamsFor(plant, spec);
    for (const Channel c : inputs) {
      for (const Gap& gap : Gaps(full.size(), full.step_s)) {
        Series s = full;
        for (std::size_t i = gap.first; i < gap.first + gap.count; ++i) s[c][i] = std::nan("");
        Drivers d;
        std::string error;
        if (!PrepareDrivers(s, plant, spec, &d, &error)) {
          // Only irradiance_bias may refuse: it needs enough rows where both
          // irradiance sources are high, and the gap may take them away.
          EXPECT_TRUE(HasEffect(spec, testing::EffectNamed("irradiance_bias")))
              << name << ": " << error;
          EXPECT_NE(error.find("irradiance_bias needs"), std::string::npos) << error;
          continue;
        }
        Simulate(d, params, &out);
        ++runs;
        for (std::size_t i = 0; i < s.size(); ++i) {
          const bool in_gap = i >= gap.first && i < gap.first + gap.count;
          const bool has_output = std::isfinite(out.p_el_w[i]) && std::isfinite(out.q_th_w[i]);
          // transport_delay and clock_offset read neighbouring rows: a row
          // next to a gap may lack its delayed or shifted input.
          const bool reads_neighbours = HasEffect(spec, testing::EffectNamed("transport_delay")) ||
                                        HasEffect(spec, testing::EffectNamed("clock_offset"));
          const bool near_gap = i + 3 >= gap.first && i < gap.first + gap.count + 3;
          if (!in_gap && !(reads_neighbours && near_gap)) {
            ASSERT_TRUE(has_output) << name << ", " << ChannelName(c) << " missing on " << gap.what
                                    << ": row " << i << " has no output";
          }
        }
      }
    }
  }
  EXPECT_GT(runs, 500);
}

// A CSV from `pvtwin sim --export`: GHI, DHI and POA logged. Cells of
// g_poa_w_m2 are emptied for a 15-minute sensor outage at noon and one row.
class MissingInputsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::copy_file(fs::path(PVTWIN_SOURCE_DIR) / "config/examples/sim-plant.toml",
                  dir_ / "sim.toml");
    // 2024-06-01 00:00 UTC, three days at 1 min.
    const ProcessResult exported =
        RunPvtwin(dir_.path(),
                  "sim --config sim.toml --export full.csv --days 3 --step 60 --start 1717200000");
    ASSERT_EQ(exported.exit_code, 0) << exported.err;
    std::ifstream in(dir_ / "full.csv");
    std::ofstream out(dir_ / "gap.csv");
    std::string header;
    std::getline(in, header);
    out << header << "\n";
    std::vector<std::string> names;
    std::istringstream h(header);
    for (std::string cell; std::getline(h, cell, ',');) names.push_back(cell);
    const auto poa = std::find(names.begin(), names.end(), "g_poa_w_m2") - names.begin();
    ASSERT_LT(static_cast<std::size_t>(poa), names.size()) << header;
    ASSERT_NE(header.find("ghi_w_m2"), std::string::npos) << header;
    int row = 0;
    for (std::string line; std::getline(in, line); ++row) {
      // Day 2, 12:00-12:14 UTC, and day 3, 09:30.
      const bool blank = (row >= 1440 + 720 && row < 1440 + 735) || row == 2 * 1440 + 570;
      std::vector<std::string> cells;
      std::istringstream r(line);
      for (std::string cell; std::getline(r, cell, ',');) cells.push_back(cell);
      if (blank) cells[static_cast<std::size_t>(poa)].clear();
      for (std::size_t i = 0; i < cells.size(); ++i) out << (i ? "," : "") << cells[i];
      out << "\n";
    }
  }
  testing::ScratchDir dir_{"missing_cli"};
};

TEST_F(MissingInputsCli, SimulateFallsBackToGhiAndDhiOnTheGap) {
  const ProcessResult run = RunPvtwin(
      dir_.path(), "simulate --config sim.toml --csv gap.csv --variant 2N1CcolwrI --out pred.csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream pred(ReadFile(dir_ / "pred.csv"));
  std::string line;
  std::getline(pred, line);
  int rows = 0, empty = 0;
  while (std::getline(pred, line)) {
    ++rows;
    if (line.find(",,") != std::string::npos || line.back() == ',') ++empty;
  }
  EXPECT_EQ(rows, 3 * 1440);
  EXPECT_EQ(empty, 0) << "the rows without g_poa have GHI and DHI: they get outputs";
}

TEST_F(MissingInputsCli, CalibrateBacktestAndDiagnoseFinishOnTheGap) {
  ProcessResult run = RunPvtwin(dir_.path(),
                                "calibrate --config sim.toml --csv gap.csv --variant 2N1CcolwrI "
                                "--out params.json");
  EXPECT_EQ(run.exit_code, 0) << run.err << run.out;
  run = RunPvtwin(dir_.path(),
                  "backtest --config sim.toml --csv gap.csv --variants 1N1Cwr --train-days 2 "
                  "--step 300 --threads 1");
  EXPECT_EQ(run.exit_code, 0) << run.err << run.out;
  run = RunPvtwin(dir_.path(),
                  "diagnose --config sim.toml --csv gap.csv --variant 1N1Cwr --train-days 2 "
                  "--heldout-days 1 --step 300 --effects iam,wind --threads 1");
  EXPECT_EQ(run.exit_code, 0) << run.err << run.out;
}

}  // namespace
}  // namespace pvtwin
