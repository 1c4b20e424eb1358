// The parameter_drift warning (core/monitor/monitoring.h DetectDrift) as
// the daemon raises it (daemon/service/monitor.h, night after night on a
// real SQLite file), on nightly fits of synthetic weeks from core/synth: the
// truth `pvtwin sim` serves ("2N2CrI+wind+transport_delay", other structure
// than the calibrated 2N1Ccolwr), drawn clear, broken and overcast days,
// variable flow, realistic sensor noise. Every night the model is fitted on
// the kWindowDays before it (from the start values, as the daemon's
// calibrate), stored as an accepted calibration with its window and its
// parameters' standard errors, and the daily checks run. Issue 53's target:
// on the healthy plant no parameter_drift warning (asserted). With a truth
// parameter rising 30 % over six weeks from kDriftStart (PVTWIN_DRIFT_PARAM:
// u_back_w_m2k, the back loss coefficient, by default; r0_fluid_m2k_w,
// fouling) the run prints the warnings and the rule's last figures; it does
// not assert a detection: on these plants the fitted parameters wobble more
// between independent windows than such a rise moves them
// (doc/validation.md).
//
// Seeds, fixed before the rule was changed: development 1, 2 (the rule was
// designed on these); final check 3, 4, run once per design:
// PVTWIN_DRIFT_SEEDS=3,4. The suite runs development seed 1 over
// kSuiteNights; PVTWIN_DRIFT_NIGHTS sets the nights (doc/validation.md's
// figures: 30).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>

#include "core/fit/identification.h"
#include "core/monitor/monitoring.h"
#include "core/synth/synthetic_plant.h"
#include "daemon/service/monitor.h"
#include "io/files/params_json.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/seeds.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin::cli {
namespace {

using testing::kDayS;
using testing::kJune1_2024UtcS;
constexpr int kWindowDays = 14;  // [calibration] window_days' default
constexpr int kSuiteNights = 16;
constexpr int kDriftStart = kWindowDays;  // the truth's parameter rises from this day on
constexpr double kDriftDays = 42.0;       // ... by 30 % over six weeks
constexpr double kDriftFraction = 0.30;
using testing::kExampleDaemonModel;
using testing::kExamplePlantTruth;

std::vector<std::uint64_t> DriftSeeds() { return testing::SeedsFromEnv("PVTWIN_DRIFT_SEEDS", "1"); }

// The truth's parameter that rises: PVTWIN_DRIFT_PARAM, u_back_w_m2k by
// default (the back loss coefficient; fouling: r0_fluid_m2k_w).
Param Drifting() {
  const char* env = std::getenv("PVTWIN_DRIFT_PARAM");
  const std::optional<Param> p = ParamFromName(env != nullptr ? env : "u_back_w_m2k");
  EXPECT_TRUE(p.has_value()) << env;
  return p.value_or(Param::kUBackWM2K);
}

int Nights() {
  const char* env = std::getenv("PVTWIN_DRIFT_NIGHTS");
  return env != nullptr ? std::atoi(env) : kSuiteNights;
}

WeatherOptions WeatherOf(std::uint64_t seed, int days) {
  WeatherOptions w;
  w.start_time_s = kJune1_2024UtcS;
  w.num_days = days;
  w.step_s = 60.0;
  w.seed = seed;
  w.flow_mode = FlowMode::kVariable;
  return w;
}

// The healthy plant's data, and with `drift` the truth's Drifting() rising
// linearly by kDriftFraction over kDriftDays from kDriftStart: each row's
// outputs interpolated between the healthy truth's and that of a truth
// with the full rise (first order in the change, exact at both ends).
Series PlantData(std::uint64_t seed, int days, bool drift) {
  const Plant plant = DesignExamplePlant();
  const WeatherOptions weather = WeatherOf(seed, days);
  const ParamVector truth = ReferenceTruthParams(plant);
  Series healthy = MakeSyntheticPlantData(plant, weather, testing::SpecOf(kExamplePlantTruth),
                                          truth, RealisticSensorNoise(seed));
  if (!drift) return healthy;
  ParamVector wet = truth;
  wet[static_cast<std::size_t>(Drifting())] *= 1.0 + kDriftFraction;
  const Series risen = MakeSyntheticPlantData(plant, weather, testing::SpecOf(kExamplePlantTruth),
                                              wet, RealisticSensorNoise(seed));
  const double start_s = static_cast<double>(kJune1_2024UtcS + kDriftStart * kDayS);
  for (std::size_t i = 0; i < healthy.size(); ++i) {
    const double f = std::clamp(
        (static_cast<double>(healthy.time_s[i]) - start_s) / (kDriftDays * kDayS), 0.0, 1.0);
    if (f == 0.0) continue;
    for (std::size_t c = 0; c < kNumChannels; ++c) {
      if (healthy.columns[c].empty()) continue;
      double& v = healthy.columns[c][i];
      v += f * (risen.columns[c][i] - v);
    }
  }
  return healthy;
}

// The night's fit on the window before it, as an accepted calibration row.
Store::CalibrationRow FitNight(const Series& data, std::int64_t night_s, const Plant& plant) {
  const ModelSpec model = testing::SpecOf(kExampleDaemonModel);
  const Series window = data.Between(night_s - kWindowDays * kDayS, night_s);
  Drivers drivers;
  std::string error;
  Store::CalibrationRow row;
  EXPECT_TRUE(PrepareDrivers(window, plant, model, &drivers, &error)) << error;
  const IdentSummary fit =
      Identify(drivers, MakeMeasurements(window, drivers), StartParams(plant), IdentOptions{});
  EXPECT_TRUE(fit.ok) << fit.BriefReport();
  row.run_at = night_s;
  row.variant = kExampleDaemonModel;
  row.window_start = night_s - kWindowDays * kDayS;
  row.window_end = night_s;
  row.status = "accepted";
  row.accepted = true;
  row.params_json = FormatParamsJson(kExampleDaemonModel, fit.params, {}, "");
  for (const ParamEstimate& e : fit.estimates) {
    const ParamInfo& info = Info(e.param);
    const std::string status = !e.free ? "fixed" : e.at_bound ? "at bound" : "identified";
    row.params.push_back(
        {std::string(info.name), e.value, StdErrorInUnit(e), std::string(info.unit), status});
  }
  return row;
}

// What the nights show: the parameter_drift messages.
std::vector<std::string> DriftWarnings(const Series& data, int nights) {
  testing::ScratchDir dir("drift_weeks");
  Config config;
  config.plant = DesignExamplePlant();
  config.calibration.variant = kExampleDaemonModel;
  config.calibration.window_days = kWindowDays;
  std::string error;
  std::unique_ptr<Store> store = Store::Open((dir.path() / "pvtwin.db").string(), &error);
  EXPECT_NE(store, nullptr) << error;
  EXPECT_TRUE(store->WriteMinutes(data, &error)) << error;
  DailyCheckInputs in;
  in.config = &config;
  in.spec = testing::SpecOf(kExampleDaemonModel);
  in.accepted_now = true;
  for (int night = kWindowDays; night < kWindowDays + nights; ++night) {
    const std::int64_t night_s = kJune1_2024UtcS + night * kDayS;
    Store::CalibrationRow row = FitNight(data, night_s, config.plant);
    EXPECT_TRUE(store->InsertCalibration(&row, &error)) << error;
    in.now_s = night_s + 2 * 3600;
    RunDailyChecks(*store, in);
  }
  // The last night's figures of the rule for the drifting parameter.
  std::map<std::string, std::vector<ParameterPoint>> history;
  EXPECT_TRUE(
      store->ReadAcceptedParameters(in.now_s - config.monitor.drift_days * kDayS, &history, &error))
      << error;
  const std::string name(Info(Drifting()).name);
  const ParameterDrift u = DetectDrift(history[name]);
  std::printf(
      "  last night, %s: %.3f -> %.3f (%+.3f), fits' error %.3f, wobble %.3f "
      "from %d steps, judged %d, drift %d\n",
      name.c_str(), u.first, u.last, u.change, u.combined_se, u.wobble_sd, u.steps, u.judged,
      u.drift);
  testing::RawDb db(dir.path() / "pvtwin.db");
  std::vector<std::string> messages;
  for (const auto& r : db.Rows("SELECT message FROM monitor_event WHERE kind = 'parameter_drift' "
                               "ORDER BY id")) {
    messages.push_back(r[0]);
  }
  return messages;
}

// Healthy nights raise no parameter_drift; drifted nights (with enough of
// them to see the rise) are run and reported.
TEST(DriftWeeks, AHealthyPlantRaisesNoDriftAndARisingBackLossDoes) {
  const int nights = Nights();
  for (const std::uint64_t seed : DriftSeeds()) {
    const int days = kWindowDays + nights;
    const std::vector<std::string> healthy = DriftWarnings(PlantData(seed, days, false), nights);
    std::printf("seed %llu, %d nights, healthy: %zu parameter_drift warning(s)\n",
                static_cast<unsigned long long>(seed), nights, healthy.size());
    for (const std::string& m : healthy) std::printf("  %s\n", m.c_str());
    EXPECT_TRUE(healthy.empty()) << "seed " << seed;
    if (nights < 2 * kWindowDays) continue;  // too few nights for the drift to show
    const std::vector<std::string> drifted = DriftWarnings(PlantData(seed, days, true), nights);
    const std::string name(Info(Drifting()).name);
    int named = 0;
    for (const std::string& m : drifted) named += m.rfind(name, 0) == 0;
    std::printf(
        "seed %llu, %d nights, %s +30 %% over 6 weeks from day %d: %zu warning(s), "
        "%d on it\n",
        static_cast<unsigned long long>(seed), nights, name.c_str(), kDriftStart, drifted.size(),
        named);
    for (const std::string& m : drifted) std::printf("  %s\n", m.c_str());
  }
}

}  // namespace
}  // namespace pvtwin::cli
