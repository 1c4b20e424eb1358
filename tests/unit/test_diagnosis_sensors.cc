// The diagnosis names sensor faults that are plausible on every row, with
// channel, kind, onset and size, and names none on the same plant without
// them: the inlet temperature reading high by a constant from one day on
// (the heat meter then reads ṁ·c_p·ΔT low: offset_step); the logged outlet
// reading low from one day on, seen with the pump on at night (pair_offset);
// the flow meter reading 10 % high from one day on (scale); and no heat
// meter fault where both outputs lose the same light from one day on.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/common/calendar.h"
#include "core/data/qc.h"
#include "core/diagnosis/diagnosis.h"
#include "core/diagnosis/diagnosis_selftest.h"
#include "core/diagnosis/sensor_residuals.h"
#include "core/synth/synthetic_plant.h"
#include "io/platform/time_format.h"
#include "io/store/store.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

// 21 days of 1N1Cwr data with `kind` of `severity` from the third held-out
// day (severity 0: none); with night_pumping the pump runs day and night
// while the absorber is warmer than the brine (a heat pump's source field).
Series Plant21Days(const Plant& plant, DisturbanceKind kind, double severity, std::int64_t* onset_s,
                   bool night_pumping = false) {
  SyntheticOptions synth;
  std::string error;
  EXPECT_TRUE(DefaultSyntheticOptions(plant, "1N1Cwr", 21, 3, &synth, &error)) << error;
  if (night_pumping) {
    synth.weather.pump_control = PumpControl::kHeatPumpSource;
    synth.weather.heat_pump_from_h = 0.0;
    synth.weather.heat_pump_to_h = 24.0;
  }
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  const std::int64_t first = SolarDayStartS(synth.weather.start_time_s, offset_s) + kSecondsPerDay;
  synth.weather.start_time_s = first;
  *onset_s = first + 16 * kSecondsPerDay;  // the third held-out day
  if (severity != 0.0) {
    synth.disturbances.push_back({kind, *onset_s, first + 30 * kSecondsPerDay, severity});
  }
  Series s = MakeSyntheticPlantData(plant, synth);
  ApplyPaperCorrections(&s);
  return s;
}

Series Plant21Days(const Plant& plant, double offset_k, std::int64_t* onset_s) {
  return Plant21Days(plant, DisturbanceKind::kInletSensorOffset, offset_k, onset_s);
}

const SensorFinding* FindKind(const DiagnosisResult& r, const std::string& kind) {
  for (const SensorFinding& f : r.sensors) {
    if (f.kind == kind) return &f;
  }
  return nullptr;
}

void ExpectNoFindingOfKinds(const DiagnosisResult& r, const std::vector<std::string>& kinds) {
  for (const SensorFinding& f : r.sensors) {
    for (const std::string& kind : kinds) {
      EXPECT_NE(f.kind, kind) << f.channel << " " << f.kind << ": " << f.detail;
    }
  }
}

DiagnosisResult DiagnoseSoilingOnly(const Series& s, const Plant& plant) {
  DiagnosisOptions o;
  o.train_days = 14;
  o.heldout_days = 7;
  o.effects = {"soiling"};  // the sensor test does not depend on the candidates
  DiagnosisResult r;
  std::string error;
  EXPECT_TRUE(Diagnose(s, plant, testing::SpecOf("1N1Cwr"), o, &r, &error)) << error;
  return r;
}

TEST(DiagnosisSensors, InletOffsetFromOneDayOnIsNamedWithChannelOnsetAndSize) {
  const Plant plant = DesignExamplePlant();
  std::int64_t onset_s = 0;
  const DiagnosisResult r = DiagnoseSoilingOnly(Plant21Days(plant, 1.5, &onset_s), plant);
  const SensorFinding* step = nullptr;
  for (const SensorFinding& f : r.sensors) {
    if (f.kind == "offset_step") step = &f;
  }
  ASSERT_NE(step, nullptr) << r.verdict_sentence;
  EXPECT_EQ(step->channel, "t_in_c");
  EXPECT_EQ(step->from, SolarDate(onset_s, SolarDayOffsetS(plant)));
  // Sized against the model fitted before the onset, with the model's own
  // response to the high inlet (∂Q_u/∂T_in) in its fault model: the truth's
  // 1.5 K (a model fitted on all days took up a third of it).
  EXPECT_NEAR(step->size, 1.5, 0.15);
  EXPECT_NE(r.verdict_sentence.find("t_in_c offset_step from"), std::string::npos);
  EXPECT_EQ(FindKind(r, "scale"), nullptr) << "an offset is not a flow meter scale";
}

// Both fault models are compared at their least-squares size: Q_u low by
// ṁ·c_p·δ is fitted exactly by the offset model, not by a scale, and a
// Q_u scaled by k the other way round (rows before the onset do not count).
TEST(DiagnosisSensors, EachFaultModelIsComparedAtItsLeastSquaresSize) {
  namespace st = diagnosis_stages;
  st::SensorResiduals r;
  for (std::uint32_t i = 0; i < 40; ++i) {
    r.rows.push_back(i);
    r.day_s.push_back(i < 10 ? 0 : 86400);
    r.capacity_flow_w_k.push_back(i % 4 == 0 ? 0.0 : 100.0 + 10.0 * (i % 7));
    r.q_model_w.push_back(200.0 + 40.0 * (i % 5));
  }
  auto flow = [&r](std::uint32_t i) { return r.capacity_flow_w_k[i]; };
  auto model = [&r](std::uint32_t i) { return r.q_model_w[i]; };
  auto residual = [&r](std::uint32_t i) { return r.q_model_w[i] - r.q_meas_w[i]; };
  auto meas = [&r](std::uint32_t i) { return r.q_meas_w[i]; };
  for (std::uint32_t i = 0; i < 40; ++i) {
    // Before the onset day anything: those rows are not the fault's.
    r.q_meas_w.push_back(i < 10 ? 5000.0 : r.q_model_w[i] - 1.5 * r.capacity_flow_w_k[i]);
  }
  EXPECT_NEAR(st::FitFault(r, 86400, flow, residual).mse, 0.0, 1e-9);
  EXPECT_NEAR(st::FitFault(r, 86400, flow, residual).g, 1.5, 1e-12);
  EXPECT_GT(st::FitFault(r, 86400, model, meas).mse, 1.0);
  for (std::uint32_t i = 0; i < 40; ++i) r.q_meas_w[i] = 0.9 * r.q_model_w[i];
  EXPECT_NEAR(st::FitFault(r, 86400, model, meas).mse, 0.0, 1e-9);
  EXPECT_NEAR(st::FitFault(r, 86400, model, meas).g, 0.9, 1e-12);
  EXPECT_GT(st::FitFault(r, 86400, flow, residual).mse, 1.0);
  // Σ(y − g·x)² / n by hand at g = Σxy/Σx²: x = (1, 2), y = (1, 3): g = 7/5,
  // residuals −0.4 and 0.2, MSE 0.1.
  st::SensorResiduals hand;
  hand.rows = {0, 1};
  hand.day_s = {0, 0};
  hand.capacity_flow_w_k = {1.0, 1.0};
  hand.q_model_w = {1.0, 2.0};
  hand.q_meas_w = {1.0, 3.0};
  const st::FaultFit fit = st::FitFault(
      hand, 0, [&hand](std::uint32_t i) { return hand.q_model_w[i]; },
      [&hand](std::uint32_t i) { return hand.q_meas_w[i]; });
  EXPECT_NEAR(fit.g, 1.4, 1e-12);
  EXPECT_NEAR(fit.mse, 0.1, 1e-12);
}

// The inlet offset of the selftest (1.5 K from the third held-out day) on
// development seeds where the diagnosis went wrong before: on 202 and 205 an
// IAM fitted on the clean training days won the held-out days because the
// faulty days' measured Q_u is low; on 209 a flow scale was named instead of
// the offset. Now the effect must also be chosen on the held-out days before
// the onset (it is not: `unknown`), and the two fault models meet at their
// least-squares sizes (the offset wins).
TEST(DiagnosisSensors, AnInletOffsetOnTheHeldOutDaysNamesNoEffectAndBeatsAFlowScale) {
  const Plant plant = DesignExamplePlant();
  SelftestCase inlet;
  for (const SelftestCase& c : SelftestCases(plant)) {
    if (c.name == "tin_offset") inlet = c;
  }
  ASSERT_EQ(inlet.name, "tin_offset");
  SelftestOptions options;
  for (const std::uint64_t seed : {202, 205, 209}) {
    const SelftestOutcome o = RunSelftestCase(plant, inlet, seed, options);
    EXPECT_TRUE(o.correct) << "seed " << seed << ": " << o.why;
    EXPECT_EQ(o.verdict, "unknown") << "seed " << seed << ": " << o.result.verdict_sentence;
    const SensorFinding* step = FindKind(o.result, "offset_step");
    ASSERT_NE(step, nullptr) << "seed " << seed;
    EXPECT_EQ(step->channel, "t_in_c");
    // 1.3–1.5 K over seeds 201–260 (a model fitted on all days: 0.8–1.3 K).
    EXPECT_GT(step->size, 1.25) << "seed " << seed;
    EXPECT_LT(step->size, 1.65) << "seed " << seed;
    EXPECT_EQ(FindKind(o.result, "scale"), nullptr) << "seed " << seed;
  }
}

TEST(DiagnosisSensors, NoOffsetStepOnTheSamePlantWithoutIt) {
  const Plant plant = DesignExamplePlant();
  std::int64_t onset_s = 0;
  const DiagnosisResult r = DiagnoseSoilingOnly(Plant21Days(plant, 0.0, &onset_s), plant);
  for (const SensorFinding& f : r.sensors) EXPECT_NE(f.kind, "offset_step") << f.detail;
}

TEST(DiagnosisSensors, OutletOffsetWithThePumpOnAtNightIsNamedAsThePair) {
  const Plant plant = DesignExamplePlant();
  std::int64_t onset_s = 0;
  const DiagnosisResult r = DiagnoseSoilingOnly(
      Plant21Days(plant, DisturbanceKind::kOutletSensorOffset, -0.8, &onset_s, true), plant);
  const SensorFinding* pair = FindKind(r, "pair_offset");
  ASSERT_NE(pair, nullptr) << r.verdict_sentence;
  EXPECT_EQ(pair->channel, "t_in_c,t_out_c");
  EXPECT_EQ(pair->from, SolarDate(onset_s, SolarDayOffsetS(plant)));
  EXPECT_NEAR(pair->size, -0.8, 0.2);  // an outlet offset shows in full
  // The heat meter has its own pair: Q_u is right, no other fault is named.
  EXPECT_EQ(FindKind(r, "offset_step"), nullptr);
  EXPECT_EQ(FindKind(r, "scale"), nullptr);
  // As qc_event rows: from the onset to the end given.
  const std::vector<SensorFault> rows = DiagnosedSensorFaults(r, onset_s + 10 * kSecondsPerDay);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].channel, "t_in_c,t_out_c");
  EXPECT_EQ(rows[0].kind, "pair_offset");
  EXPECT_EQ(rows[0].start_s, onset_s);
}

TEST(DiagnosisSensors, FlowMeterScaleFromOneDayOnIsNamedWithItsRatio) {
  const Plant plant = DesignExamplePlant();
  std::int64_t onset_s = 0;
  const DiagnosisResult r = DiagnoseSoilingOnly(
      Plant21Days(plant, DisturbanceKind::kFlowMeterScale, 1.1, &onset_s, true), plant);
  const SensorFinding* scale = FindKind(r, "scale");
  ASSERT_NE(scale, nullptr) << r.verdict_sentence;
  EXPECT_EQ(scale->channel, "flow_kg_s");
  EXPECT_EQ(scale->from, SolarDate(onset_s, SolarDayOffsetS(plant)));
  EXPECT_NEAR(scale->size, 1.1, 0.015);  // the truth's ratio, against the model before it
  EXPECT_EQ(FindKind(r, "offset_step"), nullptr) << "a scale is not an inlet offset";
  EXPECT_NE(r.verdict_sentence.find("flow_kg_s scale from"), std::string::npos);
}

TEST(DiagnosisSensors, NoResidualSensorFaultOnAPlantPumpingAtNightWithoutOne) {
  const Plant plant = DesignExamplePlant();
  std::int64_t onset_s = 0;
  ExpectNoFindingOfKinds(
      DiagnoseSoilingOnly(Plant21Days(plant, DisturbanceKind::kFlowMeterScale, 0.0, &onset_s, true),
                          plant),
      {"offset_step", "pair_offset", "scale"});
}

// A loss of light from one day on (a cover absorbing 90 % of the sun, as
// dirt, partial snow or a new obstacle does) lowers Q_u in proportion from
// that day, as a flow meter reading 10 % low would, but it lowers P_el with
// it: no heat meter fault is named.
TEST(DiagnosisSensors, ALightLossOnBothOutputsFromOneDayOnIsNoHeatMeterFault) {
  const Plant plant = DesignExamplePlant();
  std::int64_t onset_s = 0;
  ExpectNoFindingOfKinds(
      DiagnoseSoilingOnly(Plant21Days(plant, DisturbanceKind::kSnowCover, 0.9, &onset_s, true),
                          plant),
      {"offset_step", "scale"});
}

// The daemon's nightly diagnosis (`pvtwin diagnose --db … --record`) puts a
// fault found in the residuals into qc_event with its onset, as report.json's
// `sensors` names it; without --record nothing is written.
TEST(DiagnosisSensors, RecordPutsTheFlowMeterScaleIntoQcEventFromItsOnset) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("pvtwin_sensors_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Plant plant = DesignExamplePlant();
  std::int64_t onset_s = 0;
  Series s = Plant21Days(plant, DisturbanceKind::kFlowMeterScale, 1.1, &onset_s);
  // The store keeps minute starts: every row later by under a minute, each
  // in the solar day it was in.
  const std::int64_t late_s = (60 - s.time_s.front() % 60) % 60;
  for (std::int64_t& t : s.time_s) t += late_s;
  std::string error;
  {
    std::unique_ptr<Store> store = Store::Open((dir / "t.db").string(), &error);
    ASSERT_TRUE(store) << error;
    ASSERT_TRUE(store->WriteMinutes(s, &error)) << error;
  }
  const std::string config =
      "'" +
      (fs::path(PVTWIN_GOLDEN_DIR) / ".." / ".." / "config" / "examples" / "plant.toml").string() +
      "'";
  const std::string args = "diagnose --config " + config + " --db t.db --variant 1N1Cwr" +
                           " --train-days 14 --heldout-days 7 --effects soiling --from " +
                           FormatIsoUtc(s.time_s.front()) + " --to " +
                           FormatIsoUtc(s.time_s.back() + 60) + " --report out";
  const testing::ProcessResult read_only = testing::RunPvtwin(dir, args);
  ASSERT_EQ(read_only.exit_code, 0) << read_only.err;
  {
    testing::RawDb db(dir / "t.db");
    EXPECT_EQ(db.Number("SELECT COUNT(*) FROM qc_event"), 0.0);
  }
  const testing::ProcessResult run = testing::RunPvtwin(dir, args + " --record");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(testing::ReadFile(dir / "out" / "report.json"));
  bool in_report = false;
  for (const auto& f : j.at("sensors")) {
    in_report = in_report || (f.at("channel") == "flow_kg_s" && f.at("kind") == "scale" &&
                              f.at("from") == SolarDate(onset_s, SolarDayOffsetS(plant)));
  }
  EXPECT_TRUE(in_report) << j.at("sensors").dump();
  testing::RawDb db(dir / "t.db");
  const auto rows =
      db.Rows("SELECT channel, start_ts FROM qc_event WHERE kind = 'scale' ORDER BY start_ts");
  ASSERT_EQ(rows.size(), 1u) << run.err;
  EXPECT_EQ(rows[0][0], "flow_kg_s");
  EXPECT_EQ(rows[0][1], std::to_string(onset_s));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pvtwin
