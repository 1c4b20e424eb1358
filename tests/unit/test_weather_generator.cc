#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "core/common/units.h"
#include "core/physics/irradiance.h"
#include "core/physics/solar_position.h"
#include "core/synth/weather_generator.h"
#include "tests/support/fixtures.h"

namespace pvtwin {
namespace {

// The plant of doc/contracts.md's example config: 47.358° N, 16.128° E, 20° tilt,
// facing south.
Plant ExamplePlant() {
  Plant plant;
  plant.latitude_rad = DegToRad(47.358);
  plant.longitude_rad = DegToRad(16.128);
  plant.elevation_m = 300.0;
  plant.tilt_rad = DegToRad(20.0);
  plant.azimuth_rad = DegToRad(180.0);
  plant.area_m2 = 1.8;
  return plant;
}

using testing::kJune20_2024UtcS;

WeatherOptions OneDayOf(DayType type) {
  WeatherOptions options;
  options.start_time_s = kJune20_2024UtcS;
  options.num_days = 1;
  options.day_types = {type};
  options.seed = 7;
  return options;
}

bool BitIdentical(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// Daily clearness index Σ GHI / Σ I0·cos θ_z over daylight rows.
double DailyClearnessIndex(const Series& s, const Plant& plant) {
  SolarPositionInput site;
  site.latitude_rad = plant.latitude_rad;
  site.longitude_rad = plant.longitude_rad;
  double ghi_sum = 0.0;
  double extra_sum = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    site.time_s = static_cast<double>(s.time_s[i]);
    const double cos_zenith = std::cos(ComputeSolarPosition(site).zenith_rad);
    if (cos_zenith <= 0.0) continue;
    ghi_sum += s[Channel::kGhiWM2][i];
    extra_sum += ExtraterrestrialNormalWM2(172.0) * cos_zenith;
  }
  return ghi_sum / extra_sum;
}

TEST(WeatherGenerator, SameSeedGivesBitIdenticalSeries) {
  WeatherOptions options;
  options.num_days = 5;
  options.seed = 12345;
  const Series a = GenerateWeather(ExamplePlant(), options);
  const Series b = GenerateWeather(ExamplePlant(), options);
  ASSERT_EQ(a.time_s, b.time_s);
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    EXPECT_TRUE(BitIdentical(a.columns[c], b.columns[c])) << kChannels[c].name;
  }
}

TEST(WeatherGenerator, DifferentSeedGivesDifferentSeries) {
  WeatherOptions options;
  options.num_days = 3;
  options.seed = 1;
  const Series a = GenerateWeather(ExamplePlant(), options);
  options.seed = 2;
  const Series b = GenerateWeather(ExamplePlant(), options);
  EXPECT_FALSE(BitIdentical(a[Channel::kTAmbC], b[Channel::kTAmbC]));
  EXPECT_FALSE(BitIdentical(a[Channel::kWindMS], b[Channel::kWindMS]));
  EXPECT_FALSE(BitIdentical(a[Channel::kGhiWM2], b[Channel::kGhiWM2]));
}

TEST(WeatherGenerator, RowsAndChannelsFollowTheOptions) {
  WeatherOptions options;
  options.num_days = 2;
  options.step_s = 300.0;
  const Series s = GenerateWeather(ExamplePlant(), options);
  ASSERT_EQ(s.size(), 2u * 288u);
  EXPECT_EQ(s.step_s, 300.0);
  EXPECT_EQ(s.time_s.front(), options.start_time_s);
  EXPECT_EQ(s.time_s[1] - s.time_s[0], 300);
  for (Channel c : {Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaWM2, Channel::kGPoaDiffuseWM2,
                    Channel::kAoiRad, Channel::kTAmbC, Channel::kWindMS, Channel::kLwDownWM2,
                    Channel::kMdotKgS, Channel::kTInC, Channel::kValid}) {
    EXPECT_TRUE(s.Has(c)) << ChannelName(c);
  }
  for (Channel c : {Channel::kTBackC, Channel::kTOutC, Channel::kPElW, Channel::kQThW,
                    Channel::kTPvC, Channel::kTSkyC}) {
    EXPECT_FALSE(s.Has(c)) << ChannelName(c);
  }
}

TEST(WeatherGenerator, ValuesArePhysicallyBounded) {
  const Plant plant = ExamplePlant();
  WeatherOptions options;
  options.num_days = 14;
  options.seed = 99;
  options.start_time_s = 1711929600;  // 2024-04-01
  const Series s = GenerateWeather(plant, options);
  SolarPositionInput site;
  site.latitude_rad = plant.latitude_rad;
  site.longitude_rad = plant.longitude_rad;
  site.elevation_m = plant.elevation_m;
  const double nominal_flow_kg_s = options.flow_kg_s_per_m2 * plant.area_m2;
  int daylight_rows = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    site.time_s = static_cast<double>(s.time_s[i]);
    const SolarPosition sun = ComputeSolarPosition(site);
    ClearSkyInput cs;
    cs.zenith_rad = sun.zenith_rad;
    cs.day_of_year = 92.0 + (site.time_s - options.start_time_s) / 86400.0;
    cs.elevation_m = plant.elevation_m;
    cs.linke_turbidity = options.linke_turbidity;
    const double clear_ghi = ClearSkyIneichenPerez(cs).ghi_w_m2;
    const double ghi = s[Channel::kGhiWM2][i];
    const double dhi = s[Channel::kDhiWM2][i];
    const double g_poa = s[Channel::kGPoaWM2][i];
    const double g_poa_diffuse = s[Channel::kGPoaDiffuseWM2][i];
    ASSERT_GE(dhi, 0.0) << i;
    ASSERT_LE(dhi, ghi) << i;
    ASSERT_LE(ghi, 1.1 * clear_ghi * 1.001 + 0.5) << i;
    ASSERT_GE(g_poa_diffuse, 0.0) << i;
    ASSERT_GE(g_poa - g_poa_diffuse, -1e-9) << i;  // beam in plane ≥ 0
    if (sun.zenith_rad > DegToRad(90.5)) {
      ASSERT_EQ(ghi, 0.0) << i;
      ASSERT_EQ(g_poa, 0.0) << i;
      ASSERT_EQ(s[Channel::kMdotKgS][i], 0.0) << i;
    } else {
      ++daylight_rows;
    }
    const double flow = s[Channel::kMdotKgS][i];
    ASSERT_TRUE(flow == 0.0 || (flow > 0.9 * nominal_flow_kg_s && flow < 1.1 * nominal_flow_kg_s))
        << i;
    ASSERT_GE(s[Channel::kWindMS][i], 0.0);
    ASSERT_LT(s[Channel::kWindMS][i], 40.0);
    ASSERT_GT(s[Channel::kTAmbC][i], -30.0);
    ASSERT_LT(s[Channel::kTAmbC][i], 40.0);
    ASSERT_GT(s[Channel::kLwDownWM2][i], 150.0);
    ASSERT_LT(s[Channel::kLwDownWM2][i], 500.0);
    ASSERT_GT(s[Channel::kTInC][i], options.t_in_base_c - 2.0);
    ASSERT_LT(s[Channel::kTInC][i], options.t_in_base_c + 40.0);
    ASSERT_EQ(s[Channel::kValid][i], 1.0);
  }
  EXPECT_GT(daylight_rows, 14 * 12 * 60);  // April days at 47° N: > 12 h
}

// A clear day near the June solstice at 47° N on a 20° south plane; the
// in-plane daily irradiation of clear days there is about 7.5 … 8.5 kWh/m².
TEST(WeatherGenerator, ClearSummerDayIrradiationIsPlausible) {
  const Plant plant = ExamplePlant();
  const Series s = GenerateWeather(plant, OneDayOf(DayType::kClear));
  double poa_kwh_m2 = 0.0;
  double ghi_kwh_m2 = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    poa_kwh_m2 += s[Channel::kGPoaWM2][i] * s.step_s / 3.6e6;
    ghi_kwh_m2 += s[Channel::kGhiWM2][i] * s.step_s / 3.6e6;
  }
  EXPECT_GT(poa_kwh_m2, 6.0);
  EXPECT_LT(poa_kwh_m2, 9.0);
  EXPECT_GT(ghi_kwh_m2, 6.0);
  EXPECT_LT(ghi_kwh_m2, 9.0);
}

TEST(WeatherGenerator, OvercastIsDarkerThanBrokenIsDarkerThanClear) {
  const Plant plant = ExamplePlant();
  const double kt_clear =
      DailyClearnessIndex(GenerateWeather(plant, OneDayOf(DayType::kClear)), plant);
  const double kt_broken =
      DailyClearnessIndex(GenerateWeather(plant, OneDayOf(DayType::kBrokenClouds)), plant);
  const double kt_overcast =
      DailyClearnessIndex(GenerateWeather(plant, OneDayOf(DayType::kOvercast)), plant);
  EXPECT_GT(kt_clear, 0.6);
  EXPECT_LT(kt_overcast, 0.3);
  EXPECT_LT(kt_overcast, kt_broken);
  EXPECT_LT(kt_broken, kt_clear);
}

// Broken clouds: many minute-to-minute jumps of the in-plane irradiance;
// a clear day has none.
TEST(WeatherGenerator, BrokenCloudsHaveFastTransients) {
  const Plant plant = ExamplePlant();
  auto count_jumps = [](const Series& s) {
    int jumps = 0;
    const auto& g = s[Channel::kGPoaWM2];
    for (std::size_t i = 1; i < s.size(); ++i) jumps += std::abs(g[i] - g[i - 1]) > 200.0;
    return jumps;
  };
  EXPECT_GE(count_jumps(GenerateWeather(plant, OneDayOf(DayType::kBrokenClouds))), 20);
  EXPECT_EQ(count_jumps(GenerateWeather(plant, OneDayOf(DayType::kClear))), 0);
}

TEST(WeatherGenerator, PumpFollowsTheSunWithHysteresis) {
  const Plant plant = ExamplePlant();
  WeatherOptions options = OneDayOf(DayType::kBrokenClouds);
  const Series s = GenerateWeather(plant, options);
  int switches = 0;
  int on_rows = 0;
  double t_in_max_c = -1e9;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const bool on = s[Channel::kMdotKgS][i] > 0.0;
    on_rows += on;
    if (i > 0) switches += on != (s[Channel::kMdotKgS][i - 1] > 0.0);
    // The pump never starts below the start threshold.
    if (on && (i == 0 || s[Channel::kMdotKgS][i - 1] == 0.0)) {
      EXPECT_GT(s[Channel::kGPoaWM2][i], options.pump_on_w_m2);
    }
    t_in_max_c = std::max(t_in_max_c, s[Channel::kTInC][i]);
  }
  EXPECT_GT(on_rows, 5 * 60);
  EXPECT_LE(switches, static_cast<int>(86400.0 / options.pump_min_dwell_s));
  EXPECT_GT(t_in_max_c, options.t_in_base_c + 3.0);  // the tank warms up
}

TEST(WeatherGenerator, VariableFlowFollowsIrradiance) {
  const Plant plant = ExamplePlant();
  WeatherOptions options = OneDayOf(DayType::kBrokenClouds);
  options.flow_mode = FlowMode::kVariable;
  const Series s = GenerateWeather(plant, options);
  const double nominal_flow_kg_s = options.flow_kg_s_per_m2 * plant.area_m2;
  double min_on = 1e9;
  double max_on = 0.0;
  for (double flow : s[Channel::kMdotKgS]) {
    if (flow > 0.0) {
      min_on = std::min(min_on, flow);
      max_on = std::max(max_on, flow);
    }
  }
  EXPECT_GT(min_on, 0.3 * nominal_flow_kg_s * 0.95);
  EXPECT_LT(min_on, 0.6 * nominal_flow_kg_s);
  EXPECT_GT(max_on, 0.9 * nominal_flow_kg_s);
}

TEST(WeatherGenerator, DrawnDayTypesAreReproducibleAndMixed) {
  WeatherOptions options;
  options.num_days = 60;
  options.seed = 3;
  const std::vector<DayType> a = DayTypesFor(options);
  EXPECT_EQ(a, DayTypesFor(options));
  ASSERT_EQ(a.size(), 61u);
  int counts[3] = {0, 0, 0};
  for (DayType t : a) ++counts[static_cast<int>(t)];
  for (int c : counts) EXPECT_GT(c, 5);
  options.day_types = {DayType::kOvercast, DayType::kClear};
  const std::vector<DayType> fixed = DayTypesFor(options);
  EXPECT_EQ(fixed[0], DayType::kOvercast);
  EXPECT_EQ(fixed[1], DayType::kClear);
  EXPECT_EQ(fixed[2], DayType::kOvercast);
}

TEST(WeatherGenerator, InvalidOptionsNameFieldAndRule) {
  WeatherOptions options;
  std::string why;
  EXPECT_TRUE(options.IsValid(&why));
  options.step_s = 0.5;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("step_s = 0.5"), std::string::npos) << why;
  options = WeatherOptions();
  options.pump_off_w_m2 = 300.0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("pump_off_w_m2"), std::string::npos) << why;
  options = WeatherOptions();
  options.p_clear = 0.7;
  options.p_broken = 0.5;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("p_broken"), std::string::npos) << why;
}

TEST(WeatherGenerator, TwentyEightDaysAtOneMinuteTakeWellUnderASecond) {
  WeatherOptions options;
  options.num_days = 28;
  const auto start = std::chrono::steady_clock::now();
  const Series s = GenerateWeather(ExamplePlant(), options);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(s.size(), 28u * 1440u);
  EXPECT_LT(elapsed_s, 1.0);
}

// Erbs is continuous at its breakpoints; Ineichen–Perez gives a plausible
// clear-sky noon at sea level with T_L = 3.5.
TEST(WeatherGenerator, ClearSkyAndDiffuseFractionBuildingBlocks) {
  EXPECT_NEAR(ErbsDiffuseFraction(0.22 - 1e-9), ErbsDiffuseFraction(0.22 + 1e-9), 1e-3);
  EXPECT_NEAR(ErbsDiffuseFraction(0.80 - 1e-9), ErbsDiffuseFraction(0.80 + 1e-9), 1e-3);
  EXPECT_DOUBLE_EQ(ErbsDiffuseFraction(0.0), 1.0);
  ClearSkyInput in;
  in.zenith_rad = DegToRad(25.0);
  const ClearSkyIrradiance noon = ClearSkyIneichenPerez(in);
  EXPECT_GT(noon.ghi_w_m2, 800.0);
  EXPECT_LT(noon.ghi_w_m2, 1000.0);
  EXPECT_GT(noon.dni_w_m2, 700.0);
  EXPECT_LT(noon.dni_w_m2, 1000.0);
  EXPECT_NEAR(noon.dhi_w_m2 + noon.dni_w_m2 * std::cos(in.zenith_rad), noon.ghi_w_m2, 1e-9);
  in.zenith_rad = DegToRad(91.0);
  EXPECT_EQ(ClearSkyIneichenPerez(in).ghi_w_m2, 0.0);
}

}  // namespace
}  // namespace pvtwin
