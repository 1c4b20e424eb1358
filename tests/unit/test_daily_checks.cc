// daemon/service/monitor.h on a real SQLite file: two weeks of synthetic 1-min data
// from a known truth, of which the last four days lost 15 % of P_el and one
// night's air temperature froze, and the truth's parameters as the accepted
// calibration. The daily checks score every day, band each from the days
// before, raise the performance alarm for electricity only (on the third
// low day: the evidence of three days together), record the frozen sensor,
// and find a drift across accepted calibrations whose windows lie apart; the event view lists it
// all, newest first.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/synth/synthetic_plant.h"
#include "daemon/service/monitor.h"
#include "io/files/params_json.h"
#include "io/platform/log.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin::cli {
namespace {

using testing::kDayS;
using testing::kJune1_2024UtcS;
constexpr int kHistoryDays = 14;
constexpr int kLossDay = 10;  // P_el at 85 % from this day on

class DailyChecks : public ::testing::Test {
 protected:
  void SetUp() override {
    config_.plant = DesignExamplePlant();
    config_.calibration.window_days = kHistoryDays;
    config_.monitor.alarm_days = 3;
    WeatherOptions weather;
    weather.start_time_s = kJune1_2024UtcS;
    weather.num_days = kHistoryDays;
    weather.step_s = 60.0;
    weather.seed = 11;
    weather.day_types = {DayType::kClear};
    const ParamVector truth = ReferenceTruthParams(config_.plant);
    Series s = MakeSyntheticPlantData(config_.plant, weather, testing::SpecOf("2N1Ccolwr"), truth,
                                      RealisticSensorNoise(5));
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.time_s[i] >= kJune1_2024UtcS + kLossDay * kDayS) s[Channel::kPElW][i] *= 0.85;
      // t_amb frozen 01:00–03:00 of the last day.
      const std::int64_t t = s.time_s[i] - (kJune1_2024UtcS + (kHistoryDays - 1) * kDayS);
      if (t >= 3600 && t < 3 * 3600) s[Channel::kTAmbC][i] = 11.5;
    }
    std::string error;
    store_ = Store::Open((dir_ / "pvtwin.db").string(), &error);
    ASSERT_NE(store_, nullptr) << error;
    ASSERT_TRUE(store_->WriteMinutes(s, &error)) << error;
    Accept(kJune1_2024UtcS, truth, 0.0);
  }

  // An accepted calibration of truth with u_front_w_m2k shifted by du.
  void Accept(std::int64_t run_at, ParamVector params, double du) {
    double& u_front = params[static_cast<std::size_t>(Param::kUFrontWM2K)];
    u_front += du;
    Store::CalibrationRow row;
    row.run_at = run_at;
    row.window_start = run_at - kHistoryDays * kDayS;  // the 14 days before it
    row.window_end = run_at;
    row.variant = "2N1Ccolwr";
    row.status = "accepted";
    row.accepted = true;
    row.mae_p_el_w = 2.0;
    row.mae_q_th_w = 15.0;
    row.params_json = FormatParamsJson("2N1Ccolwr", params, {}, "");
    row.params.push_back({"u_front_w_m2k", u_front, 0.1, "W/(m²·K)", "identified"});
    std::string error;
    ASSERT_TRUE(store_->InsertCalibration(&row, &error)) << error;
  }

  DailyCheckInputs Inputs(bool accepted_now) const {
    DailyCheckInputs in;
    in.config = &config_;
    in.spec = testing::SpecOf("2N1Ccolwr");
    in.now_s = kJune1_2024UtcS + kHistoryDays * kDayS + 2 * 3600;  // 02:00 after the last day
    in.accepted_now = accepted_now;
    return in;
  }

  testing::ScratchDir dir_{"daily_checks"};
  Config config_;
  std::unique_ptr<Store> store_;
};

// The daily checks materialise forecast_skill for the days that ended
// (store schema 11): the view's rows of the scored days, now in
// forecast_skill_day, and the view computes nothing before today.
TEST_F(DailyChecks, ForecastSkillIsMaterialisedForTheDaysThatEnded) {
  std::vector<Store::ForecastRow> rows;
  for (std::int64_t t = kJune1_2024UtcS; t < kJune1_2024UtcS + 2 * kDayS; t += 60)
    rows.push_back({t, 50.0, 300.0});
  std::string error;
  ASSERT_TRUE(store_->InsertForecast(kJune1_2024UtcS - 3600, 0, "test", rows, &error)) << error;
  testing::RawDb db(dir_ / "pvtwin.db");
  EXPECT_EQ(db.Number("SELECT COUNT(*) FROM forecast_skill_day"), 0.0);
  const auto skill = db.Rows("SELECT * FROM forecast_skill ORDER BY day");
  ASSERT_EQ(skill.size(), 2u) << "the issue before day 1 is the newest before day 2 too";
  const auto log = RunDailyChecks(*store_, Inputs(false));
  EXPECT_EQ(db.Number("SELECT done_before FROM forecast_skill_state"),
            static_cast<double>(kJune1_2024UtcS + kHistoryDays * kDayS));
  EXPECT_EQ(db.Rows("SELECT * FROM forecast_skill_day ORDER BY day"), skill);
  EXPECT_EQ(db.Rows("SELECT * FROM forecast_skill ORDER BY day"), skill);
  const auto line = std::find_if(log.begin(), log.end(), [](const auto& l) {
    return l.second == "forecast_skill materialised for 2 days";
  });
  EXPECT_NE(line, log.end());
}

TEST_F(DailyChecks, ScoreEveryDayAlarmOnTheLossAndRecordTheFrozenSensor) {
  const auto log = RunDailyChecks(*store_, Inputs(false));
  testing::RawDb db(dir_ / "pvtwin.db");
  EXPECT_EQ(db.Number("SELECT count(*) FROM performance_daily"), kHistoryDays);
  // Days before kLossDay as the truth, the rest at 85 % of P_el, heat unchanged.
  for (int d = 0; d < kHistoryDays; ++d) {
    const std::string day = std::to_string(kJune1_2024UtcS + d * kDayS);
    const double pi_el = db.Number("SELECT pi_el FROM performance_daily WHERE day = " + day);
    const double pi_th = db.Number("SELECT pi_th FROM performance_daily WHERE day = " + day);
    EXPECT_NEAR(pi_el, d < kLossDay ? 1.0 : 0.85, 0.005) << d;
    EXPECT_NEAR(pi_th, 1.0, 0.01) << d;
  }
  // A band from the ninth day on (nine days before it). The first loss
  // day's band lies below 1; the second's holds it: an open excursion's
  // days stay in the reference (index_band.h), and the first loss day is
  // its rank 1 of 11; the third's lies at 1 within the noise (not
  // asserted); after the alarm its days leave the reference and the fourth
  // loss day's band lies below 1 again.
  const std::string loss = std::to_string(kJune1_2024UtcS + kLossDay * kDayS);
  EXPECT_EQ(db.Number("SELECT count(*) FROM performance_daily WHERE pi_el_low IS NOT NULL"),
            kHistoryDays - 9);
  for (const int d : {kLossDay, kLossDay + 1, kLossDay + 3}) {
    const std::string day = std::to_string(kJune1_2024UtcS + d * kDayS);
    EXPECT_EQ(db.Number("SELECT pi_el_high < 1 FROM performance_daily WHERE day = " + day),
              d == kLossDay + 1 ? 0 : 1)
        << d;
  }
  // One alarm, for electricity, on the third loss day (the alarm's days
  // leave the reference, and the CUSUM starts again), and its log line.
  EXPECT_EQ(db.Rows("SELECT kind, severity FROM monitor_event"),
            (std::vector<std::vector<std::string>>{{"performance_low_el", "warning"}}));
  bool logged = false;
  for (const auto& [priority, line] : log) {
    logged |= priority == kWarning &&
              line.find(
                  "electricity below the calibrated model: the evidence of 3 days "
                  "together") != std::string::npos &&
              line.find("on 2024-06-13") != std::string::npos;
  }
  EXPECT_TRUE(logged);
  // The frozen air temperature: an interval from the second frozen minute.
  const std::int64_t last_day = kJune1_2024UtcS + (kHistoryDays - 1) * kDayS;
  EXPECT_EQ(db.Rows("SELECT channel, kind, start_ts - " + std::to_string(last_day) + ", end_ts - " +
                    std::to_string(last_day) + " FROM qc_event"),
            (std::vector<std::vector<std::string>>{{"t_amb_c", "frozen", "3660", "10800"}}));
  // The next night scores nothing again and raises no new alarm.
  RunDailyChecks(*store_, Inputs(false));
  EXPECT_EQ(db.Number("SELECT count(*) FROM performance_daily"), kHistoryDays);
  EXPECT_EQ(db.Number("SELECT count(*) FROM monitor_event"), 1);
  EXPECT_EQ(db.Number("SELECT count(*) FROM qc_event"), 1);
  // The operator's list: newest first, the calibration included.
  const auto events = db.Rows("SELECT kind FROM event");
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0][0], "performance_low_el");
  EXPECT_EQ(events[1][0], "qc_frozen");
  EXPECT_EQ(events[2][0], "calibration_accepted");
}

// Fits a week apart rising 0.3 each (a steady rise: no wobble, the fits'
// errors 0.1 the scale): the newest against the first, whose window ended
// where the newest's began, moved 0.6 > 3·0.141.
TEST_F(DailyChecks, ADriftAcrossAcceptedCalibrationsIsAnEvent) {
  const ParamVector truth = ReferenceTruthParams(config_.plant);
  Accept(kJune1_2024UtcS + 7 * kDayS, truth, 0.3);
  Accept(kJune1_2024UtcS + 14 * kDayS, truth, 0.6);
  const auto log = RunDailyChecks(*store_, Inputs(true));
  testing::RawDb db(dir_ / "pvtwin.db");
  // The log's line is the event's without the scale's parts (log lines stay
  // within 200 characters).
  const auto line = std::find_if(log.begin(), log.end(), [](const auto& l) {
    return l.first == kWarning && l.second.find("u_front_w_m2k drifted from") == 0;
  });
  ASSERT_NE(line, log.end());
  EXPECT_LE(line->second.size(), 200u) << line->second;
  const auto drift = db.Rows("SELECT message FROM monitor_event WHERE kind = 'parameter_drift'");
  ASSERT_EQ(drift.size(), 1u);
  EXPECT_NE(drift[0][0].find("u_front_w_m2k drifted"), std::string::npos) << drift[0][0];
  EXPECT_NE(drift[0][0].find("(+0.6000, more than 3 times its standard error 0.1414"),
            std::string::npos)
      << drift[0][0];
  EXPECT_NE(drift[0][0].find("windows ending 2024-06-01 and from 2024-06-01"), std::string::npos)
      << drift[0][0];
  EXPECT_NE(drift[0][0].find("over 3 accepted calibrations"), std::string::npos) << drift[0][0];
  EXPECT_NE(drift[0][0].find("the wobble of fits a window apart 0.0000 from 2 nightly steps"),
            std::string::npos)
      << drift[0][0];
  EXPECT_EQ(line->second.find("wobble"), std::string::npos) << line->second;
  // Without a new calibration the drift is not raised again.
  RunDailyChecks(*store_, Inputs(false));
  EXPECT_EQ(db.Number("SELECT count(*) FROM monitor_event WHERE kind = 'parameter_drift'"), 1);
}

// A drift is one warning while it lasts and one info when a judged night
// no longer finds it; the log says it each night.
TEST_F(DailyChecks, ADriftIsOneEventUntilItEnds) {
  const ParamVector truth = ReferenceTruthParams(config_.plant);
  Accept(kJune1_2024UtcS + 7 * kDayS, truth, 0.3);
  Accept(kJune1_2024UtcS + 14 * kDayS, truth, 0.6);
  DailyCheckInputs night = Inputs(true);
  RunDailyChecks(*store_, night);
  testing::RawDb db(dir_ / "pvtwin.db");
  const std::string events =
      "SELECT severity, message FROM monitor_event WHERE kind = 'parameter_drift' ORDER BY id";
  ASSERT_EQ(db.Rows(events).size(), 1u);
  // The next night's fit drifted a little further: the log says so, no new
  // event.
  Accept(kJune1_2024UtcS + 15 * kDayS, truth, 0.65);
  night.now_s += kDayS;
  const auto log = RunDailyChecks(*store_, night);
  EXPECT_EQ(db.Rows(events).size(), 1u);
  EXPECT_NE(std::find_if(log.begin(), log.end(),
                         [](const auto& l) {
                           return l.first == kWarning &&
                                  l.second.find("u_front_w_m2k drifted from") == 0 &&
                                  l.second.find("still open") != std::string::npos;
                         }),
            log.end());
  // Back where it was: the drift ends, once.
  for (int k = 16; k <= 17; ++k) {
    Accept(kJune1_2024UtcS + k * kDayS, truth, 0.0);
    night.now_s += kDayS;
    RunDailyChecks(*store_, night);
  }
  const auto rows = db.Rows(events);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0][0], "warning");
  EXPECT_EQ(rows[1][0], "info");
  EXPECT_EQ(rows[1][1].rfind("u_front_w_m2k no longer drifts: 14.0000 against 14.0000", 0), 0u)
      << rows[1][1];
}

// drift_days shorter than a window and two nights never holds fits a
// window apart: no event, and a warning in the log that says so (never a
// silent no-op).
TEST_F(DailyChecks, DriftDaysShorterThanTwoWindowsIsSaidInTheLog) {
  config_.monitor.drift_days = 10;
  const ParamVector truth = ReferenceTruthParams(config_.plant);
  Accept(kJune1_2024UtcS + 7 * kDayS, truth, 0.3);
  Accept(kJune1_2024UtcS + 14 * kDayS, truth, 0.6);
  const auto log = RunDailyChecks(*store_, Inputs(true));
  testing::RawDb db(dir_ / "pvtwin.db");
  EXPECT_EQ(db.Number("SELECT count(*) FROM monitor_event WHERE kind = 'parameter_drift'"), 0);
  const auto line = std::find_if(log.begin(), log.end(), [](const auto& l) {
    return l.first == kWarning && l.second.find("parameter drift not judged") == 0 &&
           l.second.find("drift_days = 10") != std::string::npos &&
           l.second.find("set drift_days >= 2 x window_days = 28") != std::string::npos;
  });
  EXPECT_NE(line, log.end());
}

// The datasheet power check: a datasheet that promises far more heat than
// the plant makes fails (a warning event), the same outcome the next night
// adds no event, and a modest datasheet passes (an info event: the change).
TEST_F(DailyChecks, TheDatasheetPowerCheckRecordsEachChangeOfItsOutcome) {
  config_.monitor.datasheet_eta0 = 0.95;  // no such collector
  RunDailyChecks(*store_, Inputs(false));
  testing::RawDb db(dir_ / "pvtwin.db");
  const auto failed =
      db.Rows("SELECT severity, message FROM monitor_event WHERE kind = 'power_check'");
  ASSERT_EQ(failed.size(), 1u);
  EXPECT_EQ(failed[0][0], "warning");
  EXPECT_NE(failed[0][1].find(": failed"), std::string::npos) << failed[0][1];
  RunDailyChecks(*store_, Inputs(false));
  EXPECT_EQ(db.Number("SELECT count(*) FROM monitor_event WHERE kind = 'power_check'"), 1);
  config_.monitor.datasheet_eta0 = 0.2;
  config_.monitor.datasheet_c1_w_m2k = 5.0;
  RunDailyChecks(*store_, Inputs(false));
  const auto passed = db.Rows(
      "SELECT severity, message FROM monitor_event WHERE kind = 'power_check' ORDER BY id DESC");
  ASSERT_EQ(passed.size(), 2u);
  EXPECT_EQ(passed[0][0], "info");
  EXPECT_NE(passed[0][1].find(": passed"), std::string::npos) << passed[0][1];
}

}  // namespace
}  // namespace pvtwin::cli
