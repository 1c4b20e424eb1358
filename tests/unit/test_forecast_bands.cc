// Uncertainty bands and the reference forecast (core/forecast/forecast_bands.h,
// forecast.h): the sample quantile against its textbook definition; over a
// month of a synthetic plant with known noise the 10–90 % band covers about
// 80 % of the measured minutes; a weather forecast that is the truth plus a
// realistic error beats smart persistence, and a worse one widens the bands.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/data/resample.h"
#include "core/forecast/forecast.h"
#include "core/forecast/forecast_bands.h"
#include "core/forecast/operation_forecast.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/fixtures.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

using testing::kDayS;

TEST(SampleQuantile, IsHyndmanFanType7) {
  // R: quantile(c(4, 1, 3, 2), c(0, .1, .5, .9, 1)) = 1, 1.3, 2.5, 3.7, 4.
  const double expected[][2] = {{0.0, 1.0}, {0.1, 1.3}, {0.5, 2.5}, {0.9, 3.7}, {1.0, 4.0}};
  for (const auto& [q, value] : expected) {
    std::vector<double> v = {4, 1, 3, 2};
    EXPECT_NEAR(SampleQuantile(&v, q), value, 1e-12) << q;
  }
  std::vector<double> empty;
  EXPECT_TRUE(std::isnan(SampleQuantile(&empty, 0.5)));
}

// A plant of `days` days with realistic noise; the model is the truth, so the
// forecast errs only by its inputs (weather, operation) and the meters' noise.
struct Month {
  Plant plant = DesignExamplePlant();
  ModelSpec spec = testing::SpecOf("2N1Ccolwr");
  ParamVector truth = ReferenceTruthParams(DesignExamplePlant());
  WeatherOptions weather;
  Series data;

  Month(int days, std::uint64_t seed, PumpControl control = PumpControl::kIrradiance) {
    weather.num_days = days;
    weather.seed = seed;
    weather.flow_mode = FlowMode::kVariable;
    weather.pump_control = control;
    data = MakeSyntheticPlantData(plant, weather, spec, truth, RealisticSensorNoise(seed));
  }
  std::size_t RowOf(std::int64_t t) const {
    return static_cast<std::size_t>((t - data.time_s.front()) / 60);
  }
  std::int64_t Day(int d) const { return weather.start_time_s + d * kDayS; }
  Series Span(std::int64_t from, std::int64_t to) const {
    return data.Slice(RowOf(from), std::min(RowOf(to), data.size()));
  }
};

// The truth's weather with a day-ahead forecast's error: the irradiance
// times exp(ε) with ε an hourly AR(1) (ρ = 0.7, σ = sigma), clipped to 1.2 ×
// the truth's clear-sky ceiling of 1300 W/m²; the air temperature plus an
// hourly AR(1) of σ = sigma·4 K; the other weather channels as measured.
Series WeatherForecastWithError(const Series& truth, double sigma, std::uint64_t seed) {
  Series f;
  f.step_s = truth.step_s;
  f.time_s = truth.time_s;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double rho = 0.7, innovation = std::sqrt(1.0 - rho * rho);
  double e_g = 0.0, e_t = 0.0;
  std::int64_t hour = -1;
  const Channel irradiance[] = {Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2,
                                Channel::kGPoaDiffuseWM2};
  for (Channel c : {Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaDiffuseWM2,
                    Channel::kTAmbC, Channel::kWindMS, Channel::kTSkyC}) {
    if (truth.Has(c)) f[c] = truth[c];
  }
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth.time_s[i] / 3600 != hour) {
      hour = truth.time_s[i] / 3600;
      e_g = rho * e_g + innovation * sigma * normal(rng);
      e_t = rho * e_t + innovation * sigma * 4.0 * normal(rng);
    }
    for (Channel c : irradiance) {
      if (f.Has(c)) f[c][i] = std::min(f[c][i] * std::exp(e_g), 1300.0 * 1.2);
    }
    f[Channel::kTAmbC][i] += e_t;
  }
  return f;
}

struct DayScore {
  double covered[2] = {0, 0}, banded[2] = {0, 0};
  double abs_err[2] = {0, 0}, abs_err_ref[2] = {0, 0};
  double width[2] = {0, 0};
  int learned[2] = {0, 0};  // days forecast with the typical day, with the learned rule
};

// Issues the forecast of day d (history: the 14 days before), bands from the
// replay, and scores it against the measured day.
// issue_offset_s: the issue's time after 00:00 UTC of day d; window_days:
// the history the bands learn from. Every row's band holds the forecast and
// its median.
void ScoreDay(const Month& m, int d, const Series* weather_forecast, DayScore* score,
              bool choose_operation = true, std::int64_t issue_offset_s = 0, int window_days = 14) {
  const std::int64_t t0 = m.Day(d) + issue_offset_s;
  const Series history = m.Span(t0 - window_days * kDayS, t0);
  const Series wf_past =
      weather_forecast ? weather_forecast->Slice(m.RowOf(t0 - window_days * kDayS), m.RowOf(t0))
                       : Series{};
  const Series wf_day =
      weather_forecast ? weather_forecast->Slice(m.RowOf(t0), m.RowOf(t0 + kDayS)) : Series{};
  ForecastRequest request;
  request.issued_at_s = t0;
  ForecastErrors errors;
  Forecast f;
  std::string error;
  OperationChoice choice;
  if (choose_operation) {
    ASSERT_TRUE(ChooseOperation(m.plant, m.spec, m.truth, history, request, &choice, &error));
  }
  request.operation = choice.chosen;
  ++score->learned[choice.chosen == OperationForecast::kLearned];
  ASSERT_TRUE(
      ReplayForecastErrors(m.plant, m.spec, m.truth, history, wf_past, request, &errors, &error))
      << error;
  ASSERT_TRUE(
      MakeForecast(m.plant, m.spec, m.truth, history, wf_day, Series{}, request, &f, &error))
      << error;
  const ForecastBands b = BandsFor(m.plant, f, errors);
  const Channel outputs[] = {Channel::kPElW, Channel::kQThW};
  const std::vector<double>* lo[] = {&b.p_el_p10, &b.q_th_p10};
  const std::vector<double>* hi[] = {&b.p_el_p90, &b.q_th_p90};
  const std::vector<double>* mid[] = {&b.p_el_p50, &b.q_th_p50};
  for (std::size_t h = 0; h < f.rows.size(); ++h) {
    const std::size_t i = m.RowOf(f.rows.time_s[h]);
    ASSERT_LT(i, m.data.size()) << "row " << h << " of the forecast runs past the month's data";
    for (int o = 0; o < 2; ++o) {
      const double meas = m.data[outputs[o]][i], fc = f.rows[outputs[o]][h];
      score->abs_err[o] += std::fabs(meas - fc);
      score->abs_err_ref[o] += std::fabs(meas - f.reference[outputs[o]][h]);
      const double l = (*lo[o])[h], u = (*hi[o])[h];
      ASSERT_FALSE(std::isnan(l)) << h;
      ASSERT_LE(l, u);
      ASSERT_LE(l, fc) << (o ? "q_th" : "p_el") << " row " << h;
      ASSERT_LE(fc, u) << (o ? "q_th" : "p_el") << " row " << h;
      ASSERT_LE(l, (*mid[o])[h]) << h;
      ASSERT_LE((*mid[o])[h], u) << h;
      if (u - l <= 0.0) continue;
      score->banded[o] += 1;
      score->width[o] += u - l;
      score->covered[o] += (meas >= l && meas <= u) ? 1 : 0;
    }
  }
}

// The generator's pump switches on above 200 and off below 100 W/m² in the
// plane (weather_generator.h): the learned rule finds the pair on its grid.
TEST(PumpRule, FindsTheIrradianceSwitchOfTheGenerator) {
  const Month m(14, 3);
  const PumpRule rule = LearnPumpRule(m.plant, m.data);
  ASSERT_TRUE(rule.valid);
  EXPECT_NEAR(rule.g_on_w_m2, m.weather.pump_on_w_m2, 25.0);
  EXPECT_NEAR(rule.g_off_w_m2, m.weather.pump_off_w_m2, 25.0);
  EXPECT_GT(rule.accuracy, 0.97);
  EXPECT_TRUE(rule.on_plane);
  // Outside the hours it ever ran, it stays off however bright.
  Series night = m.data.Slice(0, 1440);
  night[Channel::kGPoaWM2].assign(1440, 900.0);
  const std::vector<double> flow = PumpFlow(m.plant, rule, night, false);
  for (std::size_t k = 0; k < flow.size(); ++k) {
    const double hour = SolarHour(m.plant, night.time_s[k]);
    if (hour < rule.first_hour || hour > rule.last_hour) {
      ASSERT_EQ(flow[k], 0.0) << hour;
    }
  }
  EXPECT_NE(rule.Describe().find("pump on at g_poa >="), std::string::npos) << rule.Describe();
}

// A thermostat on the collector-minus-tank difference (the generator's
// differential control, a form the rule does not have) is still caught by an
// irradiance rule on most minutes, and the rule forecasts the heat of the
// last day better than the typical day.
TEST(PumpRule, StandsForADifferentialThermostat) {
  const Month m(15, 6, PumpControl::kDifferential);
  const PumpRule rule = LearnPumpRule(m.plant, m.data.Slice(0, 14 * 1440));
  ASSERT_TRUE(rule.valid);
  EXPECT_GT(rule.accuracy, 0.9) << rule.Describe();
  OperationChoice choice;
  ForecastRequest request;
  std::string error;
  ASSERT_TRUE(ChooseOperation(m.plant, m.spec, m.truth, m.data, request, &choice, &error));
  EXPECT_EQ(choice.chosen, OperationForecast::kLearned) << choice.Describe();
  EXPECT_LT(choice.mae_q_th_learned_w, choice.mae_q_th_typical_w);
}

// Ten days of a 15-min logger (960 rows, fewer than a day of minutes) hold
// the rule as well: a day of rows is counted at their step, and consecutive
// 15-min rows are no gap that would restart the hysteresis at each row.
TEST(PumpRule, IsLearnedFromFifteenMinuteRows) {
  const Month m(10, 3);
  Series rows;
  std::string error;
  ASSERT_TRUE(Resample(m.data, 900.0, &rows, &error)) << error;
  const PumpRule rule = LearnPumpRule(m.plant, rows);
  ASSERT_TRUE(rule.valid) << rule.Describe();
  // A 15-min mean blurs the switch: within two steps of the grid.
  EXPECT_NEAR(rule.g_on_w_m2, m.weather.pump_on_w_m2, 50.0) << rule.Describe();
  EXPECT_NEAR(rule.g_off_w_m2, m.weather.pump_off_w_m2, 50.0) << rule.Describe();
  EXPECT_GT(rule.accuracy, 0.9) << rule.Describe();
}

// Without enough data there is no rule, and the forecast keeps the typical day.
TEST(PumpRule, NeedsADayOfData) {
  const Month m(2, 3);
  EXPECT_FALSE(LearnPumpRule(m.plant, m.data.Slice(0, 600)).valid);
}

TEST(ForecastBands, CoverAboutEightyPercentOverAMonthOfPersistenceForecasts) {
  const Month m(36, 21);
  DayScore score;
  for (int d = 15; d < 36; ++d) ScoreDay(m, d, nullptr, &score);
  for (int o = 0; o < 2; ++o) {
    const double coverage = score.covered[o] / score.banded[o];
    EXPECT_GT(score.banded[o], 21 * 400.0) << o;  // the daylight minutes at least
    EXPECT_NEAR(coverage, 0.80, 0.05) << (o ? "q_th" : "p_el");
  }
}

// Issued at 05:02 (the replays at the same time of day, so that their
// errors have the forecast's lead times), from a week's window: every band
// holds its forecast and median (ScoreDay), and covers about 80 % of the
// minutes of days the bands were not calibrated on.
TEST(ForecastBands, HoldTheForecastAndCoverNominallyFromAWeekIssuedAtAnyTime) {
  const Month m(30, 11);
  DayScore score;
  // Day 28 is the last whose 24 h from 05:02 the month's data still cover.
  for (int d = 8; d < 29; ++d) ScoreDay(m, d, nullptr, &score, true, 5 * 3600 + 120, 7);
  for (int o = 0; o < 2; ++o) {
    const double coverage = score.covered[o] / score.banded[o];
    EXPECT_NEAR(coverage, 0.80, 0.10) << (o ? "q_th" : "p_el");
  }
}

TEST(ForecastBands, AWeatherForecastBeatsSmartPersistenceAndAWorseOneWidensTheBands) {
  const Month m(26, 8);
  const Series good = WeatherForecastWithError(m.data, 0.15, 3);
  const Series poor = WeatherForecastWithError(m.data, 0.45, 3);
  DayScore with_good, with_poor;
  for (int d = 15; d < 26; ++d) {
    ScoreDay(m, d, &good, &with_good);
    ScoreDay(m, d, &poor, &with_poor);
  }
  // The pump follows the irradiance: the learned rule beats the median day.
  EXPECT_EQ(with_good.learned[1], 11);
  for (int o = 0; o < 2; ++o) {
    const double skill = 1.0 - with_good.abs_err[o] / with_good.abs_err_ref[o];
    EXPECT_GT(skill, o ? 0.05 : 0.2) << (o ? "q_th" : "p_el");
    EXPECT_GT(with_poor.width[o] / with_poor.banded[o],
              1.3 * with_good.width[o] / with_good.banded[o])
        << (o ? "q_th" : "p_el");
    EXPECT_NEAR(with_good.covered[o] / with_good.banded[o], 0.80, 0.08);
  }
}

// Smart persistence smooths the clouds over the hour: persisting the minutes
// (with the reference's own operation, the typical day) does not beat it,
// nor is it far behind (a broken reference would be).
TEST(ForecastReference, PersistedWeatherDoesNotBeatSmartPersistence) {
  const Month m(26, 4);
  DayScore score;
  for (int d = 15; d < 26; ++d) ScoreDay(m, d, nullptr, &score, false);
  for (int o = 0; o < 2; ++o) {
    const double skill = 1.0 - score.abs_err[o] / score.abs_err_ref[o];
    EXPECT_LT(skill, 0.02) << (o ? "q_th" : "p_el");
    EXPECT_GT(skill, -0.3) << (o ? "q_th" : "p_el");
  }
}

}  // namespace
}  // namespace pvtwin
