// core/monitoring.h: the performance index of a day on synthetic data with a
// known answer (the truth model scores 1; a module that lost 15 % of its
// output scores 0.85), the drift rule on analytic nightly fits (a healthy
// wobble, a loss coefficient rising 30 % in six weeks), and the sensor
// faults found where they were planted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <regex>

#include "config/plant_config.h"
#include "core/common/units.h"
#include "core/monitor/monitoring.h"
#include "core/physics/iam.h"
#include "core/physics/solar_position.h"
#include "core/synth/synthetic_plant.h"
#include "io/files/csv.h"
#include "tests/support/fixtures.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

using testing::kDayS;
using testing::kJune1_2024UtcS;

Series ClearDays(const Plant& plant, int days, double step_s = 60.0) {
  WeatherOptions weather;
  weather.start_time_s = kJune1_2024UtcS;
  weather.num_days = days;
  weather.step_s = step_s;
  weather.seed = 7;
  weather.day_types = {DayType::kClear};
  return MakeSyntheticPlantData(plant, weather, testing::SpecOf("2N1Ccolwr"),
                                ReferenceTruthParams(plant), RealisticSensorNoise(3));
}

TEST(Performance, TheTruthModelScoresOneAndLeavesTheBandToTheResidualModel) {
  const Plant plant = DesignExamplePlant();
  const Series s = ClearDays(plant, 2);
  DayPerformance p;
  std::string error;
  ASSERT_TRUE(ScoreDay(s, kJune1_2024UtcS + kDayS, plant, testing::SpecOf("2N1Ccolwr"),
                       ReferenceTruthParams(plant), PerformanceOptions{}, &p, &error))
      << error;
  EXPECT_EQ(p.day_start_s, kJune1_2024UtcS + kDayS);
  EXPECT_GT(p.valid_minutes, 600);  // a clear June day
  ASSERT_TRUE(p.scored_el && p.scored_th);
  // Only sensor noise separates the truth from the measurement: 0.5 % of
  // P_el and 5 W of Q_u per minute, independent, average out over a day.
  EXPECT_NEAR(p.pi_el, 1.0, 0.002);
  EXPECT_NEAR(p.pi_th, 1.0, 0.005);
  EXPECT_NEAR(p.e_el_meas_wh, p.pi_el * p.e_el_model_wh, 1e-9);
  // The band comes from the days before (index_band.h), not from the day.
  EXPECT_TRUE(std::isnan(p.pi_el_low) && std::isnan(p.pi_el_high));
  EXPECT_TRUE(std::isnan(p.pi_th_low) && std::isnan(p.pi_th_high));
}

TEST(Performance, ALossOfFifteenPercentScoresItsShare) {
  const Plant plant = DesignExamplePlant();
  Series s = ClearDays(plant, 2);
  for (double& p : s[Channel::kPElW]) p *= 0.85;  // a string lost, a module soiled
  for (int d = 0; d < 2; ++d) {
    DayPerformance p;
    std::string error;
    ASSERT_TRUE(ScoreDay(s, kJune1_2024UtcS + d * kDayS, plant, testing::SpecOf("2N1Ccolwr"),
                         ReferenceTruthParams(plant), PerformanceOptions{}, &p, &error))
        << error;
    EXPECT_NEAR(p.pi_el, 0.85, 0.003) << d;
    EXPECT_NEAR(p.pi_th, 1.0, 0.005) << d;  // the heat side is untouched
  }
}

TEST(Performance, ADayWithTooFewMinutesIsMarkedNotScored) {
  const Plant plant = DesignExamplePlant();
  const Series s =
      ClearDays(plant, 1).Between(kJune1_2024UtcS + 10 * 3600, kJune1_2024UtcS + 11 * 3600);
  DayPerformance p;
  std::string error;
  ASSERT_TRUE(ScoreDay(s, kJune1_2024UtcS, plant, testing::SpecOf("2N1Ccolwr"),
                       ReferenceTruthParams(plant), PerformanceOptions{}, &p, &error));
  EXPECT_EQ(p.valid_minutes, 60);
  EXPECT_FALSE(p.scored_el);
  EXPECT_FALSE(p.scored_th);
  EXPECT_TRUE(std::isnan(p.pi_el));
  EXPECT_GT(p.e_el_meas_wh, 0.0);  // the energies are still there
}

// A 2-min logger's rows (measurement_interval) count the minutes they cover:
// three hours are 180 minutes, enough to score, not 90.
TEST(Performance, RowsOfACoarserLoggerCountTheMinutesTheyCover) {
  const Plant plant = DesignExamplePlant();
  const Series s =
      ClearDays(plant, 1, 120.0).Between(kJune1_2024UtcS + 9 * 3600, kJune1_2024UtcS + 12 * 3600);
  ASSERT_EQ(s.size(), 90u);
  DayPerformance p;
  std::string error;
  ASSERT_TRUE(ScoreDay(s, kJune1_2024UtcS, plant, testing::SpecOf("2N1Ccolwr"),
                       ReferenceTruthParams(plant), PerformanceOptions{}, &p, &error))
      << error;
  EXPECT_EQ(p.valid_minutes, 180);
  EXPECT_TRUE(p.scored_el);
  EXPECT_NEAR(p.pi_el, 1.0, 0.01);
}

// Nightly fits of 14-day windows: fit n runs at night n over [n − 14, n).
// value(n) gives the estimate, se its standard error.
template <typename F>
std::vector<ParameterPoint> Nightly(int from, int to, double se, F value) {
  std::vector<ParameterPoint> points;
  for (int n = from; n <= to; ++n) {
    const std::int64_t t = n * kDayS;
    points.push_back({t, value(n), se, t - 14 * kDayS, t});
  }
  return points;
}

// A healthy wobble: the fits follow the weather's passing fronts, ±0.2 over
// 9 nights around 10 (2 %), twice the fits' standard error 0.1.
double Wobble(int n) { return 10.0 + 0.2 * std::sin(2.0 * kPi * n / 9.0); }

// A young daemon's four fits, rising with the wobble by 0.35 (more than
// twice their combined error 0.14): three steps one way, which the rule
// before issue 53's fix called a drift. No two of their windows are apart:
// not judged.
TEST(Drift, AYoungDaemonsOverlappingFitsAreNotJudged) {
  const std::vector<ParameterPoint> young = Nightly(16, 19, 0.1, Wobble);
  for (std::size_t k = 1; k < young.size(); ++k) ASSERT_GT(young[k].value, young[k - 1].value);
  ASSERT_GT(young.back().value - young.front().value, 2 * std::hypot(0.1, 0.1));
  const ParameterDrift d = DetectDrift(young);
  EXPECT_FALSE(d.judged);
  EXPECT_FALSE(d.drift);
  EXPECT_EQ(d.calibrations, 4);
}

// Four weeks of the healthy wobble: the newest fit against the oldest whose
// window ended before the newest's began (28 nights apart). The scale is
// the wobble's, sqrt(v·W) from the steps, larger than the fits' errors:
// no drift.
TEST(Drift, AHealthyWobbleOfFourWeeksIsNoDrift) {
  const std::vector<ParameterPoint> month = Nightly(14, 42, 0.1, Wobble);
  const ParameterDrift d = DetectDrift(month);
  ASSERT_TRUE(d.judged);
  EXPECT_FALSE(d.drift);
  EXPECT_DOUBLE_EQ(d.first, Wobble(14));
  EXPECT_DOUBLE_EQ(d.last, Wobble(42));
  EXPECT_EQ(d.steps, 28);
  EXPECT_GT(d.wobble_sd, d.combined_se);
  EXPECT_DOUBLE_EQ(d.scale, d.wobble_sd);
  // The steps of a sine of amplitude a and period 9 have the mean square
  // 2a²·sin²(π/9) (about 0.0094 here); the scale is about sqrt(14·that).
  const double mean_sq = 2.0 * 0.04 * std::pow(std::sin(kPi / 9.0), 2);
  EXPECT_NEAR(d.wobble_sd, std::sqrt(14.0 * mean_sq), 0.05 * std::sqrt(14.0 * mean_sq));
}

// A loss coefficient rising 30 % over six weeks (soiling, fouling, wet
// insulation) under the same wobble: after six weeks of nightly fits, the
// newest against the fit 28 nights before has moved 0.3·10·28/42 = 2.0,
// more than three times the wobble's scale. The rule before (every step
// one way) saw none: the wobble turns the steps back and forth.
TEST(Drift, ALossCoefficientRisingThirtyPercentInSixWeeksIsADrift) {
  auto soiled = [](int n) { return Wobble(n) + 10.0 * 0.3 * (n - 14) / 42.0; };
  const std::vector<ParameterPoint> all = Nightly(14, 56, 0.1, soiled);
  // drift_days = 28: the accepted calibrations of the last 28 days.
  const std::vector<ParameterPoint> recent(all.end() - 29, all.end());
  const ParameterDrift d = DetectDrift(recent);
  ASSERT_TRUE(d.judged);
  EXPECT_TRUE(d.drift);
  EXPECT_NEAR(d.change, 2.0 + Wobble(56) - Wobble(28), 1e-9);
  EXPECT_GT(std::fabs(d.change), kDriftSigmas * d.scale);
  // The steady rise does not widen its own yardstick: the scale is the
  // healthy wobble's.
  EXPECT_NEAR(d.wobble_sd, DetectDrift(Nightly(28, 56, 0.1, Wobble)).wobble_sd, 0.05 * d.wobble_sd);
}

// Without a wobble the fits' errors are the scale: a change beyond three
// times their combined error is a drift, within it none; unknown errors
// and windows do not count.
TEST(Drift, WithoutAWobbleTheFitsErrorsAreTheScale) {
  const std::vector<ParameterPoint> steady = Nightly(14, 42, 0.1, [](int n) {
    return 10.0 + 0.02 * (n - 14);  // 0.56 over 28 nights: 4 times 0.141
  });
  const ParameterDrift d = DetectDrift(steady);
  ASSERT_TRUE(d.judged);
  EXPECT_NEAR(d.wobble_sd, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(d.combined_se, std::hypot(0.1, 0.1));
  EXPECT_TRUE(d.drift);
  std::vector<ParameterPoint> noisy = steady;
  for (ParameterPoint& p : noisy) p.std_error = 0.2;  // 0.56 < 3·0.283
  EXPECT_FALSE(DetectDrift(noisy).drift);
  std::vector<ParameterPoint> unknown = steady;
  unknown.front().std_error = NAN;
  unknown[1].window_end_s = unknown[1].window_start_s;  // no window
  const ParameterDrift u = DetectDrift(unknown);
  EXPECT_EQ(u.calibrations, static_cast<int>(steady.size()) - 2);
  EXPECT_DOUBLE_EQ(u.first, steady[2].value);
}

TEST(SensorFaults, FoundWherePlanted) {
  const Plant plant = DesignExamplePlant();
  Series s = ClearDays(plant, 1);
  s.Ensure(Channel::kLwDownWM2);
  auto row = [](int hour, int minute) {
    return static_cast<std::size_t>((hour * 3600 + minute * 60) / 60);
  };
  // t_amb frozen 02:00–03:30 (90 min), p_el missing 09:00–09:20, a heat
  // meter reading 200 W at zero flow 05:00–05:15 (the pump is off at dawn),
  // the sky 10 K warmer than the air 12:00–12:30 in full sun.
  for (std::size_t i = row(2, 0); i < row(3, 30); ++i) s[Channel::kTAmbC][i] = 12.34;
  for (std::size_t i = row(9, 0); i < row(9, 20); ++i) s[Channel::kPElW][i] = NAN;
  for (std::size_t i = row(5, 0); i < row(5, 15); ++i) {
    s[Channel::kMdotKgS][i] = 0.0;
    s[Channel::kQThW][i] = 200.0;
  }
  for (std::size_t i = row(12, 0); i < row(12, 30); ++i) {
    const double t_sky_k = CToK(s[Channel::kTAmbC][i] + 10.0);
    s[Channel::kLwDownWM2][i] = kStefanBoltzmannW_m2k4 * std::pow(t_sky_k, 4);
  }
  const std::vector<SensorFault> faults = FindSensorFaults(s, plant);
  auto find = [&faults](const std::string& channel, const std::string& kind) {
    for (const SensorFault& f : faults) {
      if (f.channel == channel && f.kind == kind) return &f;
    }
    return static_cast<const SensorFault*>(nullptr);
  };
  const SensorFault* frozen = find("t_amb_c", "frozen");
  ASSERT_NE(frozen, nullptr);
  // The first row of the run is where the value was first seen; the run of
  // identical values starts one row later.
  EXPECT_EQ(frozen->start_s, kJune1_2024UtcS + 2 * 3600 + 60);
  EXPECT_EQ(frozen->end_s, kJune1_2024UtcS + 3 * 3600 + 30 * 60);
  const SensorFault* missing = find("p_el_w", "missing");
  ASSERT_NE(missing, nullptr);
  EXPECT_EQ(missing->start_s, kJune1_2024UtcS + 9 * 3600);
  EXPECT_EQ(missing->end_s, kJune1_2024UtcS + 9 * 3600 + 20 * 60);
  const SensorFault* heat = find("q_th_w", "heat_without_flow");
  ASSERT_NE(heat, nullptr);
  EXPECT_EQ(heat->start_s, kJune1_2024UtcS + 5 * 3600);
  const SensorFault* sky = find("lw_down_w_m2", "sky_warmer_than_air");
  ASSERT_NE(sky, nullptr);
  EXPECT_EQ(sky->start_s, kJune1_2024UtcS + 12 * 3600);
  EXPECT_EQ(sky->end_s, kJune1_2024UtcS + 12 * 3600 + 30 * 60);
  // Nothing else: the untouched channels of a synthetic day are healthy
  // (lw_down is missing outside the planted half hour, which is reported).
  for (const SensorFault& f : faults) {
    const bool planted = &f == frozen || &f == missing || &f == heat || &f == sky ||
                         (f.channel == "lw_down_w_m2" && f.kind == "missing");
    EXPECT_TRUE(planted) << f.channel << " " << f.kind << " " << f.detail;
  }
}

// The power check on an analytic case: a synthetic series built from the
// datasheet equation itself passes with the ratio 1 (within the hourly
// averaging); 20 % less heat fails at a safety factor of 0.9; the filters
// leave out hours below 800 W/m² and hours below 5 °C.
// The irradiance checks on a clear synthetic day (whose sky is Ineichen–
// Perez at Linke turbidity 3.5): nothing on the day as generated; a
// plane-of-array sensor reading 60 % of the truth for an hour disagrees with
// GHI/DHI; one reading 160 % for half an hour lies above the clean clear sky.
TEST(SensorFaults, IrradianceAboveTheClearSkyOrAgainstGhiDhi) {
  const Plant plant = DesignExamplePlant();
  Series s = ClearDays(plant, 1);
  ASSERT_TRUE(s.Has(Channel::kGhiWM2) && s.Has(Channel::kDhiWM2));
  for (const SensorFault& f : FindSensorFaults(s, plant)) {
    ADD_FAILURE() << "on the healthy day: " << f.channel << " " << f.kind << " " << f.detail;
  }
  std::vector<double>& g = s[Channel::kGPoaWM2];
  for (int m = 10 * 60; m < 11 * 60; ++m) g[static_cast<std::size_t>(m)] *= 0.6;
  for (int m = 13 * 60; m < 13 * 60 + 30; ++m) g[static_cast<std::size_t>(m)] *= 1.6;
  bool low = false, high = false, high_also_disagrees = false;
  for (const SensorFault& f : FindSensorFaults(s, plant)) {
    EXPECT_EQ(f.channel, "g_poa_w_m2") << f.kind;
    if (f.kind == "poa_disagrees_with_ghi_dhi" && f.start_s == kJune1_2024UtcS + 10 * 3600) {
      low = true;
      EXPECT_EQ(f.end_s, kJune1_2024UtcS + 11 * 3600);
    } else if (f.kind == "above_clear_sky") {
      high = true;
      EXPECT_GE(f.start_s, kJune1_2024UtcS + 13 * 3600);
      EXPECT_LE(f.end_s, kJune1_2024UtcS + 13 * 3600 + 30 * 60);
    } else if (f.kind == "poa_disagrees_with_ghi_dhi" && f.start_s == kJune1_2024UtcS + 13 * 3600) {
      high_also_disagrees = true;
    } else {
      ADD_FAILURE() << f.kind << " from " << f.start_s - kJune1_2024UtcS << " s: " << f.detail;
    }
  }
  EXPECT_TRUE(low);
  EXPECT_TRUE(high);
  EXPECT_TRUE(high_also_disagrees);
}

// A logger whose irradiance is stamped 20 min late on three clear days: one
// clock_shift per day, each saying 20 min later; the days as generated have
// none (the test above).
TEST(SensorFaults, AClockTwentyMinutesOffIsFoundOnClearDays) {
  const Plant plant = DesignExamplePlant();
  Series s = ClearDays(plant, 3);
  std::vector<double>& g = s[Channel::kGPoaWM2];
  const std::vector<double> original = g;
  for (std::size_t i = 0; i < g.size(); ++i) g[i] = i >= 20 ? original[i - 20] : 0.0;
  int days = 0;
  for (const SensorFault& f : FindSensorFaults(s, plant)) {
    if (f.kind != "clock_shift") continue;
    ++days;
    EXPECT_EQ(f.channel, "time");
    // To the minute or two: the clean clear sky is not this day's sky.
    std::smatch m;
    ASSERT_TRUE(std::regex_search(f.detail, m, std::regex(R"(peaks (\d+) min later than the sun)")))
        << f.detail;
    EXPECT_NEAR(std::stoi(m[1]), 20, 2) << f.detail;
  }
  EXPECT_EQ(days, 3);
}

TEST(PowerCheck, TheDatasheetsOwnEquationPassesAndALossFails) {
  const Plant plant = DesignExamplePlant();
  CollectorDatasheet d;
  d.eta0 = 0.5;
  d.c1_w_m2k = 10.0;
  d.c3_j_m3k = 1.5;
  d.c6_s_m = 0.005;
  Series s = ClearDays(plant, 20);
  // Replace Q_u by the datasheet's: steady hours, the heat as the equation says.
  std::vector<SolarPosition> sun;
  SolarPositionInput site;
  site.latitude_rad = plant.latitude_rad;
  site.longitude_rad = plant.longitude_rad;
  std::vector<double> mid(s.time_s.begin(), s.time_s.end());
  for (double& t : mid) t += 30.0;
  ComputeSolarPositions(mid, site, &sun);
  std::vector<double>& q = s[Channel::kQThW];
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double aoi = AngleOfIncidenceRad(sun[i].zenith_rad, sun[i].azimuth_rad, plant.tilt_rad,
                                           plant.azimuth_rad);
    const double k_b = aoi < kPi / 2 ? IamSoukaSafwat(aoi, plant.iam_b0) : 0.0;
    const double g = s[Channel::kGPoaWM2][i], u = s[Channel::kWindMS][i];
    const double dt = 0.5 * (s[Channel::kTInC][i] + s[Channel::kTOutC][i]) - s[Channel::kTAmbC][i];
    q[i] = plant.area_m2 * (d.eta0 * (0.85 * k_b + 0.15 * d.kd) * g - d.c6_s_m * u * g -
                            (d.c1_w_m2k + d.c3_j_m3k * u) * dt);
    s[Channel::kLwDownWM2][i] = NAN;  // no long-wave term (c4 = 0): not needed
  }
  s.columns[static_cast<std::size_t>(Channel::kLwDownWM2)].clear();
  PowerCheckOptions o;
  const PowerCheckResult ok = CheckPowerAgainstDatasheet(s, plant, d, o);
  ASSERT_GE(ok.intervals, 20);
  EXPECT_TRUE(ok.enough);
  EXPECT_TRUE(ok.pass);
  // Hourly means of products differ from products of hourly means only a little.
  EXPECT_NEAR(ok.ratio, 1.0, 0.01);
  EXPECT_GE(ok.measured_w_m2 / plant.area_m2, 0.0);
  for (double& v : q) v *= 0.8;
  const PowerCheckResult low = CheckPowerAgainstDatasheet(s, plant, d, o);
  EXPECT_EQ(low.intervals, ok.intervals);
  EXPECT_NEAR(low.ratio, 0.8 * ok.ratio, 1e-9);
  EXPECT_FALSE(low.pass);
  // The filters: no hour passes above 2000 W/m², none at 40 °C minimum ambient.
  o.min_g_w_m2 = 2000.0;
  EXPECT_EQ(CheckPowerAgainstDatasheet(s, plant, d, o).intervals, 0);
  o.min_g_w_m2 = 800.0;
  o.min_t_amb_c = 40.0;
  EXPECT_EQ(CheckPowerAgainstDatasheet(s, plant, d, o).intervals, 0);
  // No datasheet, no check.
  EXPECT_EQ(CheckPowerAgainstDatasheet(s, plant, CollectorDatasheet{}, {}).intervals, 0);
}

// Real data: the htw saar collector against its own datasheet (PROVENANCE.md:
// η0 = 0.475, c1 = 7.411 W/m²K, c3 = 1.7 J/m³K, c4 = 0.437, c6 = 0.003 s/m,
// C = 42 200 J/m²K). Each clear day holds 4 hours that pass the filters;
// measured against the datasheet's estimate they give 0.76 (day 1, inlet
// near ambient) and 0.71 (day 3, inlet 7 K above): the collector delivered
// about a quarter less heat than its datasheet at these conditions, and less
// the warmer it ran (its identified η0 is 10 % below the datasheet's, doc/validation.md).
TEST(PowerCheck, TheHtwSaarCollectorAgainstItsDatasheet) {
  Config config;
  Diagnostics errors;
  const std::string dir = std::string(PVTWIN_DATA_DIR) + "/htwsaar-pvt/";
  ASSERT_TRUE(LoadConfig(dir + "plant.toml", &config, &errors));
  CollectorDatasheet d;
  d.eta0 = 0.475;
  d.c1_w_m2k = 7.411;
  d.c3_j_m3k = 1.7;
  d.c4 = 0.437;
  d.c5_j_m2k = 42200;
  d.c6_s_m = 0.003;
  PowerCheckOptions o;
  o.min_intervals = 3;
  int intervals = 0;
  double sum_ratio = 0.0;
  for (const char* day : {"day1_clear_low_dT.csv", "day3_clear_medium_dT.csv"}) {
    CsvReadOptions read;
    read.fluid_density_kg_m3 = config.plant.fluid_density_kg_m3;
    Series s;
    ASSERT_TRUE(ReadCanonicalCsv(dir + day, read, &s, &errors, nullptr)) << day;
    const PowerCheckResult r = CheckPowerAgainstDatasheet(s, config.plant, d, o);
    std::printf("%s: %d hours, measured %.1f W/m², datasheet %.1f W/m², ratio %.3f\n", day,
                r.intervals, r.measured_w_m2, r.estimated_w_m2, r.ratio);
    intervals += r.intervals;
    if (r.intervals > 0) sum_ratio += r.ratio * r.intervals;
  }
  ASSERT_GE(intervals, 3);
  const double ratio = sum_ratio / intervals;
  EXPECT_GT(ratio, 0.65);
  EXPECT_LT(ratio, 0.85);
}

// Real data: the two htw saar days come from a research test bench with
// calibrated sensors (PROVENANCE.md) at 2-min steps. The one finding is the
// long-wave channel: its pyrgeometer implies a sky 14–17 K warmer than the
// air in full sun on both clear days (lw_down ≈ 550–620 W/m² at 27–35 °C
// air), which no clear sky does. Nothing else may fire (a check that fires
// on healthy real data would bury an operator's real faults).
TEST(SensorFaults, OnlyTheLongWaveChannelOnTheHtwSaarDays) {
  Config config;
  Diagnostics errors;
  const std::string dir = std::string(PVTWIN_DATA_DIR) + "/htwsaar-pvt/";
  ASSERT_TRUE(LoadConfig(dir + "plant.toml", &config, &errors));
  for (const char* day : {"day1_clear_low_dT.csv", "day3_clear_medium_dT.csv"}) {
    Series s;
    ASSERT_TRUE(ReadCanonicalCsv(dir + day, CsvReadOptions{}, &s, &errors, nullptr)) << day;
    std::int64_t sky_s = 0;
    for (const SensorFault& f : FindSensorFaults(s, config.plant)) {
      if (f.channel == "lw_down_w_m2" && f.kind == "sky_warmer_than_air") {
        sky_s += f.end_s - f.start_s;
      } else {
        ADD_FAILURE() << day << ": " << f.channel << " " << f.kind << " " << f.detail;
      }
    }
    EXPECT_GE(sky_s, 2 * 3600) << day;
  }
}

}  // namespace
}  // namespace pvtwin
