// The simulated plant's operation (core/synth/pump_controller.h,
// core/synth/absorber_sensor.h, PumpControl in core/synth/weather_generator.h,
// io/sim/plant_source.h): the ΔT thermostat on hand-checkable cases, the absorber
// sensor against its analytic steady state and step response, heat from the
// heat-pump source in November and June at the example plant through
// `pvtwin sim --export` with the demo's config, and one continuous run
// across midnight.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "config/plant_config.h"
#include "core/common/units.h"
#include "core/synth/absorber_sensor.h"
#include "core/synth/pump_controller.h"
#include "core/synth/synthetic_plant.h"
#include "core/synth/weather_generator.h"
#include "io/files/csv.h"
#include "io/sim/plant_source.h"
#include "tests/support/fixtures.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;

constexpr std::int64_t kNov19_2024 = 1731974400;  // 00:00 UTC
constexpr std::int64_t kNov20_2024 = 1732060800;
using testing::kJune20_2024UtcS;

DifferentialControlState Step(const DifferentialControlParams& p, DifferentialControlState s,
                              double t_coll_c, double t_ref_c, double dt_s, bool enabled = true) {
  return StepDifferentialControl(p, s, {t_coll_c, t_ref_c, enabled, dt_s});
}

// ---------------------------------------------------------------------------
// The thermostat: ΔT_on 5 K, ΔT_off 2 K, dwell 300 s, steps of 60 s.

TEST(DifferentialControl, SwitchesOnOnlyAboveDtOn) {
  const DifferentialControlParams p;  // 5 / 2 K, 300 s
  DifferentialControlState s;         // off, free to switch
  s = Step(p, s, 30.0, 25.0, 60.0);   // ΔT = 5 K: not above 5
  EXPECT_FALSE(s.pump_on);
  s = Step(p, s, 30.1, 25.0, 60.0);  // 5.1 K
  EXPECT_TRUE(s.pump_on);
  EXPECT_EQ(s.since_switch_s, 0.0);
}

TEST(DifferentialControl, HysteresisKeepsThePumpOnBetweenDtOffAndDtOn) {
  DifferentialControlParams p;
  p.min_dwell_s = 0.0;
  DifferentialControlState s;
  s = Step(p, s, 31.0, 25.0, 60.0);  // 6 K: on
  ASSERT_TRUE(s.pump_on);
  for (const double dt_k : {4.0, 3.0, 2.0}) {  // inside the band, and at ΔT_off itself
    s = Step(p, s, 25.0 + dt_k, 25.0, 60.0);
    EXPECT_TRUE(s.pump_on) << dt_k;
  }
  s = Step(p, s, 26.9, 25.0, 60.0);  // 1.9 K: off
  EXPECT_FALSE(s.pump_on);
  s = Step(p, s, 29.0, 25.0, 60.0);  // 4 K: inside the band, stays off
  EXPECT_FALSE(s.pump_on);
}

TEST(DifferentialControl, DwellDelaysTheNextSwitching) {
  const DifferentialControlParams p;  // dwell 300 s
  DifferentialControlState s;
  s = Step(p, s, 40.0, 25.0, 60.0);  // on at t = 0
  ASSERT_TRUE(s.pump_on);
  // ΔT falls to 0 at once; the pump may stop only 300 s after it started:
  // since_switch 60, 120, 180, 240 → on; 300 → off.
  for (int k = 1; k <= 4; ++k) {
    s = Step(p, s, 25.0, 25.0, 60.0);
    EXPECT_TRUE(s.pump_on) << "step " << k;
  }
  s = Step(p, s, 25.0, 25.0, 60.0);
  EXPECT_FALSE(s.pump_on);
  // And it may not restart before another 300 s.
  s = Step(p, s, 40.0, 25.0, 240.0);
  EXPECT_FALSE(s.pump_on);
  s = Step(p, s, 40.0, 25.0, 60.0);
  EXPECT_TRUE(s.pump_on);
}

TEST(DifferentialControl, DisabledStopsThePumpAfterTheDwell) {
  DifferentialControlParams p;
  p.min_dwell_s = 120.0;
  DifferentialControlState s;
  s = Step(p, s, 40.0, 5.0, 60.0, /*enabled=*/false);
  EXPECT_FALSE(s.pump_on);  // a large ΔT does not start a disabled pump
  s = Step(p, s, 40.0, 5.0, 60.0);
  ASSERT_TRUE(s.pump_on);
  s = Step(p, s, 40.0, 5.0, 60.0, false);  // 60 s < 120 s dwell
  EXPECT_TRUE(s.pump_on);
  s = Step(p, s, 40.0, 5.0, 60.0, false);
  EXPECT_FALSE(s.pump_on);
}

// ---------------------------------------------------------------------------
// The absorber sensor.

AbsorberSensorParams NoRadiationNoWind() {
  AbsorberSensorParams p;
  p.eps_lw = 0.0;
  p.u_wind_w_m2k = 0.0;
  return p;  // absorbed 0.76, U_L = 14 + 1.5 = 15.5 W/m²K, C = 4.7e4 J/m²K
}

TEST(AbsorberSensor, StagnationIsAmbientPlusAbsorbedOverLoss) {
  AbsorberSensorInput in;
  in.g_poa_w_m2 = 1000.0;
  in.t_amb_c = 10.0;
  // T = T_a + 0.76·1000 / 15.5 = 10 + 49.032 °C.
  EXPECT_NEAR(AbsorberSteadyStateC(NoRadiationNoWind(), in), 10.0 + 760.0 / 15.5, 1e-9);
}

TEST(AbsorberSensor, StepResponseIsOneMinusExpOfTau) {
  const AbsorberSensorParams p = NoRadiationNoWind();
  AbsorberSensorInput in;
  in.g_poa_w_m2 = 500.0;
  in.t_amb_c = 0.0;
  in.dt_s = 600.0;
  const double t_steady_c = 380.0 / 15.5;
  const double tau_s = 4.7e4 / 15.5;  // 3032 s
  double t_c = 0.0;
  for (int k = 1; k <= 6; ++k) {
    t_c = StepAbsorberSensor(p, in, t_c).t_abs_c;
    EXPECT_NEAR(t_c, t_steady_c * (1.0 - std::exp(-k * 600.0 / tau_s)), 1e-9) << k;
  }
}

TEST(AbsorberSensor, FlowCouplingIsTheTruthsFluidResistance) {
  AbsorberSensorParams p = NoRadiationNoWind();
  p.r_internal_m2k_w = 0.0;
  p.r0_fluid_m2k_w = 0.01;
  p.r1_fluid = 1.0;
  AbsorberSensorInput in;
  in.g_poa_w_m2 = 800.0;
  in.t_amb_c = 5.0;
  in.t_in_c = 5.0;
  in.area_m2 = 2.0;
  in.fluid_cp_j_kgk = 4000.0;
  in.mdot_kg_s = 0.05;  // w = 0.05·4000/2 = 100 W/m²K; 1/k_f = 1/200 + 0.01 → k_f = 66.67
  const double k_f = 1.0 / (1.0 / 200.0 + 0.01);
  const double t_steady_c = 5.0 + 0.76 * 800.0 / (15.5 + k_f);
  in.dt_s = 1e6;  // long enough to reach the steady state
  const AbsorberSensorOutput out = StepAbsorberSensor(p, in, 5.0);
  EXPECT_NEAR(out.t_abs_c, t_steady_c, 1e-9);
  EXPECT_NEAR(out.q_u_w, k_f * (t_steady_c - 5.0) * 2.0, 1e-6);
}

// ---------------------------------------------------------------------------
// The generator's thermostat modes.

WeatherOptions HeatPumpDays(std::int64_t start_s, int days) {
  WeatherOptions w;
  w.start_time_s = start_s;
  w.num_days = days;
  w.step_s = 60.0;
  w.seed = 3;
  w.day_types = {DayType::kClear};
  w.pump_control = PumpControl::kHeatPumpSource;
  return w;
}

bool BitIdentical(const std::vector<double>& a, const std::vector<double>& b, std::size_t n) {
  return a.size() >= n && b.size() >= n && std::memcmp(a.data(), b.data(), n * sizeof(double)) == 0;
}

TEST(PlantOperation, ALongerRunRepeatsTheShorterOneBitForBit) {
  // What the continuous plant source relies on when it extends its run.
  for (const PumpControl control : {PumpControl::kDifferential, PumpControl::kHeatPumpSource}) {
    WeatherOptions w = HeatPumpDays(kNov19_2024, 1);
    w.pump_control = control;
    w.day_types.clear();
    const Series one = GenerateWeather(DesignExamplePlant(), w);
    w.num_days = 3;
    const Series three = GenerateWeather(DesignExamplePlant(), w);
    for (const Channel c :
         {Channel::kMdotKgS, Channel::kTInC, Channel::kTAmbC, Channel::kGPoaWM2}) {
      EXPECT_TRUE(BitIdentical(one[c], three[c], one.size())) << PumpControlName(control);
    }
  }
}

TEST(PlantOperation, HeatPumpBrineStaysWithinItsBandAndTheHeatPumpsHours) {
  const Series s = GenerateWeather(DesignExamplePlant(), HeatPumpDays(kNov19_2024, 2));
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_GE(s[Channel::kTInC][i], -1.0);  // [0, 10] °C + mixing noise (σ 0.15 K)
    EXPECT_LE(s[Channel::kTInC][i], 11.0);
    // Local solar time ≈ UTC + 1.07 h at 16.1° E (± 16 min equation of time):
    // no flow between 20:30 and 05:30 solar time.
    const double utc_h = static_cast<double>(s.time_s[i] % 86400) / 3600.0;
    const double solar_h = std::fmod(utc_h + 16.128 / 15.0 + 24.0, 24.0);
    if (solar_h > 20.5 || solar_h < 5.5) {
      EXPECT_EQ(s[Channel::kMdotKgS][i], 0.0) << s.time_s[i];
    }
  }
}

TEST(PlantOperation, DefaultOperationIsTheIrradianceThresholds) {
  EXPECT_EQ(WeatherOptions().pump_control, PumpControl::kIrradiance);
  EXPECT_EQ(PlantSourceOptions().pump_control, PumpControl::kIrradiance);
  EXPECT_FALSE(PlantSourceOptions().Continuous());
  for (const PumpControl c :
       {PumpControl::kIrradiance, PumpControl::kDifferential, PumpControl::kHeatPumpSource}) {
    EXPECT_EQ(PumpControlFromName(PumpControlName(c)), c);
  }
  EXPECT_FALSE(PumpControlFromName("brine").has_value());
}

TEST(PlantOperation, InvalidThermostatOptionsNameTheField) {
  WeatherOptions w = HeatPumpDays(kNov19_2024, 1);
  w.pump_dt_off_k = 6.0;
  std::string why;
  EXPECT_FALSE(w.IsValid(&why));
  EXPECT_NE(why.find("pump_dt_off_k = 6"), std::string::npos) << why;
  w = HeatPumpDays(kNov19_2024, 1);
  w.brine_min_c = 12.0;
  EXPECT_FALSE(w.IsValid(&why));
  EXPECT_NE(why.find("brine_min_c = 12"), std::string::npos) << why;
}

// ---------------------------------------------------------------------------
// The example plant through the real binary: `pvtwin sim --export` with the
// demo's config (sim-plant.toml + sim-heat-pump.toml), clear sky, 1-min rows.

const fs::path kExamples = fs::path(PVTWIN_SOURCE_DIR) / "config/examples";

std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(HeatPumpSourceExport, DemoConfigIsThePlantWithTheHeatPumpOperation) {
  // sim-plant.toml alone keeps the irradiance operation (the Modbus
  // scenarios compare with a default plant source); the demo appends
  // sim-heat-pump.toml.
  Config plant_only;
  Config demo;
  Diagnostics errors;
  ASSERT_TRUE(
      ParseConfig(ReadText(kExamples / "sim-plant.toml"), "sim-plant.toml", &plant_only, &errors));
  EXPECT_EQ(plant_only.sim.operation, "irradiance");
  ASSERT_TRUE(ParseConfig(
      ReadText(kExamples / "sim-plant.toml") + "\n" + ReadText(kExamples / "sim-heat-pump.toml"),
      "demo.toml", &demo, &errors))
      << (errors.empty() ? "" : errors[0].ToString());
  EXPECT_EQ(demo.sim.operation, "heat_pump");
  EXPECT_EQ(demo.sim.brine_min_c, 0.0);
  EXPECT_EQ(demo.sim.brine_max_c, 10.0);
  EXPECT_EQ(demo.sim.pump_dt_on_k, 5.0);
  EXPECT_EQ(demo.sim.pump_dt_off_k, 2.0);
  EXPECT_EQ(demo.modbus.points.size(), plant_only.modbus.points.size());
}

Series ExportHeatPumpDay(const std::string& name, std::int64_t start_s) {
  const fs::path dir =
      fs::temp_directory_path() / ("pvtwin_heat_" + name + "_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "sim.toml") << ReadText(kExamples / "sim-plant.toml") << "\n"
                                  << ReadText(kExamples / "sim-heat-pump.toml");
  const testing::ProcessResult run =
      testing::RunPvtwin(dir,
                         "sim --config sim.toml --export day.csv --days 1 --step 60 --sky clear "
                         "--start " +
                             std::to_string(start_s));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  Series s;
  Diagnostics errors;
  CsvReadOptions csv;
  csv.area_m2 = 1.8;
  EXPECT_TRUE(ReadCanonicalCsv((dir / "day.csv").string(), csv, &s, &errors, nullptr));
  fs::remove_all(dir);
  return s;
}

// Mean q_th_w over 09:00–13:00 UTC (≈ 10:05–14:05 solar time at 16.1° E),
// and the share of those rows with flow and q_th_w > 0.
struct SunnyHours {
  double mean_q_th_w = 0.0;
  double positive_share = 0.0;
  double mean_t_in_c = 0.0;
};

SunnyHours Midday(const Series& s) {
  SunnyHours h;
  int rows = 0;
  int positive = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::int64_t second_of_day = s.time_s[i] % 86400;
    if (second_of_day < 9 * 3600 || second_of_day >= 13 * 3600) continue;
    ++rows;
    h.mean_q_th_w += s[Channel::kQThW][i];
    h.mean_t_in_c += s[Channel::kTInC][i];
    if (s[Channel::kMdotKgS][i] > 0.0 && s[Channel::kQThW][i] > 0.0) ++positive;
  }
  h.mean_q_th_w /= rows;
  h.mean_t_in_c /= rows;
  h.positive_share = static_cast<double>(positive) / rows;
  return h;
}

TEST(HeatPumpSourceExport, NovemberAt47NorthMakesHeatOnSunnyHours) {
  const Series s = ExportHeatPumpDay("nov", kNov20_2024);
  ASSERT_EQ(s.size(), 1440u);
  const SunnyHours h = Midday(s);
  EXPECT_EQ(h.positive_share, 1.0);
  EXPECT_GT(h.mean_q_th_w, 300.0);  // 1.8 m², ~450 W/m² in plane at noon
  EXPECT_LT(h.mean_t_in_c, 10.5);   // brine, not a 25 °C tank
  RecordProperty("november_midday_q_th_w", std::to_string(h.mean_q_th_w));
  std::printf("November 20, 09-13 UTC: mean q_th_w %.0f W, t_in %.1f °C\n", h.mean_q_th_w,
              h.mean_t_in_c);
}

TEST(HeatPumpSourceExport, JuneMakesHeatOnSunnyHours) {
  const Series s = ExportHeatPumpDay("jun", kJune20_2024UtcS);
  ASSERT_EQ(s.size(), 1440u);
  const SunnyHours h = Midday(s);
  EXPECT_EQ(h.positive_share, 1.0);
  EXPECT_GT(h.mean_q_th_w, 600.0);
  std::printf("June 20, 09-13 UTC: mean q_th_w %.0f W, t_in %.1f °C\n", h.mean_q_th_w,
              h.mean_t_in_c);
}

// ---------------------------------------------------------------------------
// One continuous run across midnight (io/sim/plant_source.h).

PlantSourceOptions ContinuousSource(PumpControl control) {
  PlantSourceOptions o;
  o.plant = DesignExamplePlant();
  o.seed = 11;
  o.pump_control = control;
  o.run_start_s = kNov19_2024 + 8 * 3600;
  return o;
}

TEST(ContinuousPlant, NoJumpAtMidnightInInletOutletOrTank) {
  for (const PumpControl control : {PumpControl::kHeatPumpSource, PumpControl::kDifferential}) {
    Diagnostics errors;
    auto source = PlantSource::Create(ContinuousSource(control), &errors);
    ASSERT_NE(source, nullptr);
    const Series s = source->History(kNov19_2024 + 8 * 3600, 2);
    // The largest step of t_in_c and t_out_c in the night hours around
    // midnight (22:00–02:00 UTC) bounds what one 5 s step can change; the
    // step across 00:00 must be no larger.
    double night_in_k = 0.0;
    double night_out_k = 0.0;
    double midnight_in_k = -1.0;
    double midnight_out_k = -1.0;
    for (std::size_t i = 1; i < s.size(); ++i) {
      const std::int64_t t = s.time_s[i];
      const double d_in = std::abs(s[Channel::kTInC][i] - s[Channel::kTInC][i - 1]);
      const double d_out = std::abs(s[Channel::kTOutC][i] - s[Channel::kTOutC][i - 1]);
      if (t == kNov20_2024) {
        midnight_in_k = d_in;
        midnight_out_k = d_out;
      } else if (std::llabs(t - kNov20_2024) <= 2 * 3600) {
        night_in_k = std::max(night_in_k, d_in);
        night_out_k = std::max(night_out_k, d_out);
      }
    }
    ASSERT_GE(midnight_in_k, 0.0);
    EXPECT_LE(midnight_in_k, night_in_k) << PumpControlName(control);
    EXPECT_LE(midnight_out_k, night_out_k) << PumpControlName(control);
    EXPECT_LT(midnight_in_k, 0.1) << PumpControlName(control);
    EXPECT_LT(midnight_out_k, 0.5) << PumpControlName(control);
  }
}

TEST(ContinuousPlant, ServedValuesAreTheExportedRunsRows) {
  Diagnostics errors;
  auto exporter = PlantSource::Create(ContinuousSource(PumpControl::kHeatPumpSource), &errors);
  auto server = PlantSource::Create(ContinuousSource(PumpControl::kHeatPumpSource), &errors);
  ASSERT_NE(exporter, nullptr);
  ASSERT_NE(server, nullptr);
  const Series history = exporter->History(kNov19_2024 + 8 * 3600, 1);
  // The server is asked for a time two days on first (it generates a longer
  // run), then for times inside the exported day and across midnight.
  EXPECT_FALSE(
      std::isnan(server->At(static_cast<double>(kNov19_2024 + 3 * 86400)).Get(Channel::kTInC)));
  for (const std::size_t i : {std::size_t{0}, std::size_t{4000}, history.size() - 1}) {
    const Sample served = server->At(static_cast<double>(history.time_s[i]) + 2.0);
    EXPECT_EQ(served.ts_s, history.time_s[i]);
    for (const Channel c : {Channel::kTInC, Channel::kTOutC, Channel::kQThW, Channel::kMdotKgS}) {
      EXPECT_EQ(served.Get(c), history[c][i]) << i;
    }
  }
  EXPECT_TRUE(std::isnan(
      server->At(static_cast<double>(kNov19_2024)).Get(Channel::kTInC)));  // before the run
}

// An effect added to the simulator's truth acts at its module's typical
// magnitude: with +pv_clipping (120 W/m² on 1.8 m²: 216 W) a clear June
// day's electricity stops at the limit (sensor noise aside), where the
// default truth's runs well above it; the default truth's other rows are
// unchanged.
TEST(PlantSourceTruth, AnAddedEffectActsAtItsTypicalMagnitude) {
  constexpr std::int64_t kJune1_2024 = 1717200000;
  auto max_p_el = [](const std::string& truth, double* max_w, Series* s) {
    PlantSourceOptions o;
    o.plant = DesignExamplePlant();
    o.truth_variant = truth;
    o.day_types = {DayType::kClear};
    Diagnostics errors;
    auto source = PlantSource::Create(o, &errors);
    ASSERT_NE(source, nullptr) << (errors.empty() ? "" : errors[0].ToString());
    *s = source->History(kJune1_2024, 1);
    *max_w = 0.0;
    for (const double p : (*s)[Channel::kPElW]) {
      if (std::isfinite(p)) *max_w = std::max(*max_w, p);
    }
  };
  double reference_w = 0.0, clipped_w = 0.0;
  Series reference, clipped;
  max_p_el(kDefaultTruthVariant, &reference_w, &reference);
  max_p_el(std::string(kDefaultTruthVariant) + "+pv_clipping", &clipped_w, &clipped);
  const double limit_w = 120.0 * 1.8;
  EXPECT_GT(reference_w, 1.2 * limit_w);
  EXPECT_LT(clipped_w, 1.03 * limit_w);
  EXPECT_GT(clipped_w, 0.97 * limit_w);
  // Before sunrise both truths read the same.
  EXPECT_EQ(reference[Channel::kTAmbC][0], clipped[Channel::kTAmbC][0]);
}

}  // namespace
}  // namespace pvtwin
