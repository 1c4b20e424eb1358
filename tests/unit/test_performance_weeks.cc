// The performance index's band and alarm (core/monitor/index_band.h) as the
// daemon runs them (daemon/service/monitor.h, night after night on a real
// SQLite file), on synthetic weeks from core/synth: the truth `pvtwin sim`
// serves ("2N2CrI+wind+transport_delay", other structure than the
// calibrated 2N1Ccolwr), drawn clear, broken and overcast days, variable
// flow, realistic sensor noise. The model is fitted on the first
// kTrainDays (accepted, as the daemon's first calibration) and kept; the
// nights after score a day each. Issue 53's targets: on the healthy plant
// the index band holds 1 on at least 80 % of the days (over the
// development seeds, each output) and no alarm; with pv_clipping switched
// on from kSwitchDay (the module's typical inverter limit, 120 W/m²) the
// electricity alarm comes within three clear days.
//
// Seeds: development 1, 2, 3 (the rule was designed on these); final check
// 31, 32, 33, run once: PVTWIN_PI_SEEDS=31,32,33. The regime test (a day
// whose expected energy its reference days do not hold is not judged) was
// designed on development seeds 4, 7, 30, 43, 54, 67, chosen by their
// weather alone (DayTypesFor: 30, 43, 54, 67 open with a mostly overcast
// week, 43 and 54 with 10 or 11 overcast days; 7 opens with 11 clear days;
// 4 mixed; each with clear days after kSwitchDay) and checked once on
// final seeds 23, 29, 37, 61, 65, 71, chosen the same way before the rule
// was changed (doc/validation.md has the figures). The reference's
// composition (an open excursion's days stay in the reference, an alarm's
// leave it) was designed on fresh development seeds 103, 112, 120, 134,
// 148, 164 (with the old ones) and checked once on fresh final seeds 105,
// 123, 137, 143, 173, 188, both sets fixed before the rule changed and
// chosen by DayTypesFor alone: months that mix the regimes (overcast or
// broken stretches between clear ones; 112, 164 and 143 open overcast or
// broken with few clear days), each with clear days after kSwitchDay.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "core/fit/identification.h"
#include "core/synth/synthetic_plant.h"
#include "daemon/service/monitor.h"
#include "io/files/params_json.h"
#include "tests/support/effect_named.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/seeds.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin::cli {
namespace {

using testing::kDayS;
using testing::kJune1_2024UtcS;
constexpr int kWeeksDays = 30;
constexpr int kTrainDays = 10;  // the first calibration's window; scored the first night
constexpr int kSwitchDay = 18;  // pv_clipping from this day on
using testing::kExampleDaemonModel;
using testing::kExamplePlantTruth;

std::vector<std::uint64_t> IndexSeeds() {
  return testing::SeedsFromEnv("PVTWIN_PI_SEEDS", "1,2,3");
}

WeatherOptions WeatherOf(std::uint64_t seed) {
  WeatherOptions w;
  w.start_time_s = kJune1_2024UtcS;
  w.num_days = kWeeksDays;
  w.step_s = 60.0;
  w.seed = seed;
  w.flow_mode = FlowMode::kVariable;
  return w;
}

// What one run of the monitor over the days after training shows.
struct RunFigures {
  int banded_el = 0, hold_el = 0, banded_th = 0, hold_th = 0;
  int alarms = 0;            // performance_low_* events
  int first_alarm_day = -1;  // the day scored the night of the first electricity alarm
  // The change's first day as the daemon dates it each night
  // (NewestChangeOnset; -1: none), by the night's number (day scored + 1).
  std::vector<int> onset_by_night = std::vector<int>(kWeeksDays + 1, -1);
  // … and the outputs whose alarms dated it ("p_el", "q_th", "both", "").
  std::vector<std::string> outputs_by_night = std::vector<std::string>(kWeeksDays + 1);
  int OnsetAtFirstAlarm() const {
    return first_alarm_day < 0 ? -1 : onset_by_night[static_cast<std::size_t>(first_alarm_day + 1)];
  }
  std::string OutputsAtFirstAlarm() const {
    return first_alarm_day < 0 ? ""
                               : outputs_by_night[static_cast<std::size_t>(first_alarm_day + 1)];
  }
};

// Writes `data` to a new store with `params` as the accepted calibration of
// the first kTrainDays, and runs the daily checks every night after.
RunFigures Monitor(const Series& data, const ParamVector& params, const Config& config) {
  testing::ScratchDir dir("performance_weeks");
  std::string error;
  std::unique_ptr<Store> store = Store::Open((dir.path() / "pvtwin.db").string(), &error);
  EXPECT_NE(store, nullptr) << error;
  EXPECT_TRUE(store->WriteMinutes(data, &error)) << error;
  Store::CalibrationRow row;
  row.run_at = kJune1_2024UtcS + kTrainDays * kDayS;
  row.variant = kExampleDaemonModel;
  row.window_start = kJune1_2024UtcS;
  row.window_end = row.run_at;
  row.status = "accepted";
  row.accepted = true;
  row.params_json = FormatParamsJson(kExampleDaemonModel, params, {}, "");
  EXPECT_TRUE(store->InsertCalibration(&row, &error)) << error;
  DailyCheckInputs in;
  in.config = &config;
  in.spec = testing::SpecOf(kExampleDaemonModel);
  RunFigures f;
  for (int night = kTrainDays; night <= kWeeksDays; ++night) {
    in.now_s = kJune1_2024UtcS + night * kDayS + 2 * 3600;
    RunDailyChecks(*store, in);
    std::int64_t onset_s = -1;
    EXPECT_TRUE(NewestChangeOnset(*store, in, &onset_s, &error,
                                  &f.outputs_by_night[static_cast<std::size_t>(night)]))
        << error;
    f.onset_by_night[static_cast<std::size_t>(night)] =
        onset_s < 0 ? -1 : static_cast<int>((onset_s - kJune1_2024UtcS) / kDayS);
  }
  testing::RawDb db(dir.path() / "pvtwin.db");
  const std::string monitored = " FROM performance_daily WHERE day >= " +
                                std::to_string(kJune1_2024UtcS + kTrainDays * kDayS);
  f.banded_el =
      static_cast<int>(db.Number("SELECT count(*)" + monitored + " AND pi_el_low IS NOT NULL"));
  f.hold_el = static_cast<int>(
      db.Number("SELECT count(*)" + monitored + " AND pi_el_low <= 1 AND pi_el_high >= 1"));
  f.banded_th =
      static_cast<int>(db.Number("SELECT count(*)" + monitored + " AND pi_th_low IS NOT NULL"));
  f.hold_th = static_cast<int>(
      db.Number("SELECT count(*)" + monitored + " AND pi_th_low <= 1 AND pi_th_high >= 1"));
  f.alarms = static_cast<int>(
      db.Number("SELECT count(*) FROM monitor_event WHERE kind LIKE 'performance_low%'"));
  if (db.Number("SELECT count(*) FROM monitor_event WHERE kind = 'performance_low_el'") > 0) {
    const double ts =
        db.Number("SELECT min(ts) FROM monitor_event WHERE kind = 'performance_low_el'");
    f.first_alarm_day =
        static_cast<int>((static_cast<std::int64_t>(ts) - kJune1_2024UtcS) / kDayS) - 1;
  }
  return f;
}

// Runs each seed's healthy and switched weeks and checks: no alarm on the
// healthy plant, the clipping alarm within three clear days of the switch;
// with `coverage`, the band holds 1 on 80 % of the healthy days over the
// seeds, each output.
void CheckSeeds(const std::vector<std::uint64_t>& seeds, bool coverage) {
  const Plant plant = DesignExamplePlant();
  Config config;
  config.plant = plant;
  config.calibration.variant = kExampleDaemonModel;
  const ModelSpec truth_spec = testing::SpecOf(kExamplePlantTruth);
  const ModelSpec clipping_spec = testing::SpecOf(std::string(kExamplePlantTruth) + "+pv_clipping");
  const ModelSpec model = testing::SpecOf(kExampleDaemonModel);
  ParamVector clipping_truth = ReferenceTruthParams(plant);
  for (const auto& [param, value] : testing::EffectNamed("pv_clipping").typical_truth) {
    clipping_truth[static_cast<std::size_t>(param)] = value;
  }
  int banded_el = 0, hold_el = 0, banded_th = 0, hold_th = 0;
  for (const std::uint64_t seed : seeds) {
    const WeatherOptions weather = WeatherOf(seed);
    const Series healthy = MakeSyntheticPlantData(
        plant, weather, truth_spec, ReferenceTruthParams(plant), RealisticSensorNoise(seed));
    const Series clipped = MakeSyntheticPlantData(plant, weather, clipping_spec, clipping_truth,
                                                  RealisticSensorNoise(seed));
    ASSERT_EQ(healthy.size(), clipped.size());
    Series switched = healthy;  // pv_clipping from kSwitchDay on
    for (std::size_t c = 0; c < kNumChannels; ++c) {
      for (std::size_t i = 0; i < switched.size() && !switched.columns[c].empty(); ++i) {
        if (switched.time_s[i] >= kJune1_2024UtcS + kSwitchDay * kDayS) {
          switched.columns[c][i] = clipped.columns[c][i];
        }
      }
    }
    // The first calibration: the first kTrainDays, from the start values.
    const Series train = healthy.Between(kJune1_2024UtcS, kJune1_2024UtcS + kTrainDays * kDayS);
    Drivers drivers;
    std::string error;
    ASSERT_TRUE(PrepareDrivers(train, plant, model, &drivers, &error)) << error;
    const IdentSummary fit =
        Identify(drivers, MakeMeasurements(train, drivers), StartParams(plant), IdentOptions{});
    ASSERT_TRUE(fit.ok) << fit.BriefReport();

    const RunFigures h = Monitor(healthy, fit.params, config);
    const RunFigures s = Monitor(switched, fit.params, config);
    const std::vector<DayType> types = DayTypesFor(weather);
    int clear_days = 0;  // from the switch to the alarm's day, both included
    for (int d = kSwitchDay; d <= s.first_alarm_day; ++d) {
      clear_days += types[static_cast<std::size_t>(d)] == DayType::kClear;
    }
    std::printf(
        "seed %llu: healthy band holds 1 on %d/%d days (P_el), %d/%d (Q_u), %d alarm(s); "
        "clipping from day %d: first alarm on day %d, %d clear day(s) after the switch; "
        "change dated day %d the night of that alarm, day %d on the last night\n",
        static_cast<unsigned long long>(seed), h.hold_el, h.banded_el, h.hold_th, h.banded_th,
        h.alarms, kSwitchDay, s.first_alarm_day, clear_days, s.OnsetAtFirstAlarm(),
        s.onset_by_night.back());
    EXPECT_EQ(h.alarms, 0) << "seed " << seed;
    EXPECT_GE(s.first_alarm_day, kSwitchDay) << "seed " << seed;
    EXPECT_LE(clear_days, 3) << "seed " << seed;
    // The night of that alarm the change is dated (NewestChangeOnset, for
    // the diagnosis's window) neither before the switch nor after the alarm.
    EXPECT_GE(s.OnsetAtFirstAlarm(), kSwitchDay) << "seed " << seed;
    EXPECT_LE(s.OnsetAtFirstAlarm(), s.first_alarm_day) << "seed " << seed;
    // The inverter's clipped power stays in the collector as heat: the
    // electricity changed, the heat did not fall, and the diagnosis of the
    // days since judges the candidates on P_el.
    EXPECT_EQ(s.OutputsAtFirstAlarm(), "p_el") << "seed " << seed;
    banded_el += h.banded_el, hold_el += h.hold_el;
    banded_th += h.banded_th, hold_th += h.hold_th;
  }
  std::printf("all seeds: the band holds 1 on %d/%d days (P_el), %d/%d (Q_u)\n", hold_el, banded_el,
              hold_th, banded_th);
  if (!coverage) return;
  EXPECT_GE(hold_el, 0.8 * banded_el);
  EXPECT_GE(hold_th, 0.8 * banded_th);
  EXPECT_GT(banded_el, 0);
  EXPECT_GT(banded_th, 0);
}

TEST(PerformanceWeeks, AHealthyPlantsBandHoldsOneAndClippingAlarmsWithinThreeClearDays) {
  CheckSeeds(IndexSeeds(), true);
}

// Seeds 30, 37 and 61 (37 and 61 the regime test's spent final seeds) had
// 1, 4 and 5 false electricity alarms from a mixed reference: clear days
// 2–4 σ low against broken and overcast ones, left out of the reference
// while their excursion was open; none with its days kept in.
TEST(PerformanceWeeks, AMixedReferenceRaisesNoFalseAlarmOnTheClearDays) {
  CheckSeeds({30, 37, 61}, false);
}

// Development seeds 43 and 54 open with 11 and 10 overcast days: the model,
// fitted on them, is 2 % high on the clear days after (electricity), which
// the nearest days, all overcast, judged many σ low: 5 false alarms each
// before the regime test (index_band.h), none with it.
TEST(PerformanceWeeks, AHistoryThatStartsOvercastRaisesNoFalseAlarmOnTheClearDaysAfter) {
  CheckSeeds({43, 54}, false);
}

}  // namespace
}  // namespace pvtwin::cli
