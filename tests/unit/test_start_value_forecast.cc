// Day one (core/forecast/start_value_forecast.h): the forecast of a plant
// without calibration, from Table 3's start values with the start-value
// envelope as its band. Every row's band holds its point and median; the
// envelope is as wide as it says (its edges run the model from an overcast
// to a clear sky); the clear-sky index follows the measured
// hours; a synthetic plant whose truth lies inside Table 3's ranges stays
// inside the band on most daylight minutes of the next day; and without any
// measured weather it says what is missing.
#include <gtest/gtest.h>

#include <cmath>

#include "core/common/params.h"
#include "core/forecast/start_value_forecast.h"
#include "core/model/thermal_model.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/fixtures.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

using testing::kDayS;

struct Days {
  Plant plant = DesignExamplePlant();
  ModelSpec spec = testing::SpecOf("2N1Ccolwr");
  ParamVector truth = ReferenceTruthParams(DesignExamplePlant());
  WeatherOptions weather;
  Series data;

  explicit Days(std::vector<DayType> types, std::uint64_t seed = 5) {
    weather.num_days = static_cast<int>(types.size());
    weather.day_types = std::move(types);
    weather.seed = seed;
    data = MakeSyntheticPlantData(plant, weather, spec, truth, RealisticSensorNoise(seed));
  }
  std::int64_t At(int day, double hour) const {
    return weather.start_time_s + day * kDayS + static_cast<std::int64_t>(hour * 3600);
  }
};

void ExpectBandsHoldThePoint(const StartValueForecast& f) {
  const BandedForecast& b = f.banded;
  ASSERT_EQ(b.bands.p_el_p10.size(), b.forecast.rows.size());
  for (std::size_t h = 0; h < b.forecast.rows.size(); ++h) {
    const double p = b.forecast.rows[Channel::kPElW][h], q = b.forecast.rows[Channel::kQThW][h];
    ASSERT_TRUE(std::isfinite(p) && std::isfinite(q)) << h;
    ASSERT_LE(b.bands.p_el_p10[h], b.bands.p_el_p50[h]) << h;
    ASSERT_LE(b.bands.p_el_p50[h], b.bands.p_el_p90[h]) << h;
    ASSERT_LE(b.bands.p_el_p10[h], p) << h;
    ASSERT_LE(p, b.bands.p_el_p90[h]) << h;
    ASSERT_LE(b.bands.q_th_p10[h], b.bands.q_th_p50[h]) << h;
    ASSERT_LE(b.bands.q_th_p50[h], b.bands.q_th_p90[h]) << h;
    ASSERT_LE(b.bands.q_th_p10[h], q) << h;
    ASSERT_LE(q, b.bands.q_th_p90[h]) << h;
    ASSERT_GE(b.bands.p_el_p10[h], 0.0) << h;
    ASSERT_TRUE(std::isnan(b.forecast.reference[Channel::kPElW][h])) << h;
  }
}

// Three hours of a new plant's morning: a forecast of 24 h, banded.
TEST(StartValueForecast, ABandHoldsEveryRowsPointFromThreeHoursOfHistory) {
  const Days d({DayType::kClear, DayType::kClear});
  ForecastRequest request;
  request.issued_at_s = d.At(0, 9.0);
  const Series history = d.data.Between(d.At(0, 6.0), request.issued_at_s);
  StartValueForecast f;
  std::string error;
  ASSERT_TRUE(
      MakeStartValueForecast(d.plant, d.spec, history, Series{}, Series{}, request, {}, &f, &error))
      << error;
  ASSERT_EQ(f.banded.forecast.rows.size(), 1440u);
  EXPECT_EQ(f.banded.forecast.rows.time_s.front(), request.issued_at_s);
  ExpectBandsHoldThePoint(f);
  EXPECT_GT(f.daylight_minutes, 60u);
  // The band is wide where the sun shines and closed at night (P_el is 0 in
  // every run).
  const std::size_t noon = static_cast<std::size_t>((d.At(0, 12.0) - request.issued_at_s) / 60);
  const std::size_t night = static_cast<std::size_t>((d.At(1, 0.5) - request.issued_at_s) / 60);
  const ForecastBands& b = f.banded.bands;
  EXPECT_GT(b.p_el_p90[noon] - b.p_el_p10[noon],
            0.5 * f.banded.forecast.rows[Channel::kPElW][noon]);
  EXPECT_EQ(b.p_el_p90[night], b.p_el_p10[night]);
  EXPECT_NE(f.inputs.find("start values (Table 3"), std::string::npos) << f.inputs;
  EXPECT_NE(f.inputs.find("bands: start-value envelope"), std::string::npos) << f.inputs;
}

// The point's clear-sky index comes from the measured daylight: an overcast
// morning forecasts less than a clear one, and both stay in [0.1, 1.1].
TEST(StartValueForecast, TheClearSkyIndexFollowsTheMeasuredMorning) {
  double energy[2] = {0, 0}, index[2] = {0, 0};
  const DayType types[] = {DayType::kClear, DayType::kOvercast};
  for (int i = 0; i < 2; ++i) {
    const Days d({types[i], types[i]});
    ForecastRequest request;
    request.issued_at_s = d.At(0, 11.0);
    StartValueForecast f;
    std::string error;
    ASSERT_TRUE(MakeStartValueForecast(d.plant, d.spec,
                                       d.data.Between(d.At(0, 5.0), request.issued_at_s), Series{},
                                       Series{}, request, {}, &f, &error))
        << error;
    index[i] = f.clear_sky_index;
    for (double p : f.banded.forecast.rows[Channel::kPElW]) energy[i] += p / 60.0;
  }
  EXPECT_GT(index[0], 0.7);
  EXPECT_LT(index[1], 0.5);
  EXPECT_GE(index[1], 0.1);
  EXPECT_GT(energy[0], 1.5 * energy[1]);
}

// With a weather forecast and a plan for every row, the point is the model
// with the start values on exactly those inputs, from the first row (no
// history: no warm-up).
TEST(StartValueForecast, WithoutHistoryThePointIsTheStartValueModelOnTheTablesInputs) {
  const Plant plant = DesignExamplePlant();
  const ModelSpec spec = testing::SpecOf("1N1Cwr");
  testing::ConstantInputs constant;
  constant.g_poa_w_m2 = 700.0;
  Series inputs =
      testing::MakeConstantSeries(180, 60.0, constant, testing::kJune1_2024UtcS + 10 * 3600);
  Series weather, plan;
  weather.step_s = plan.step_s = 60.0;
  weather.time_s = plan.time_s = inputs.time_s;
  for (Channel c : {Channel::kGPoaWM2, Channel::kTAmbC, Channel::kWindMS, Channel::kTSkyC}) {
    weather[c] = inputs[c];
  }
  for (Channel c : {Channel::kTInC, Channel::kMdotKgS}) plan[c] = inputs[c];
  ForecastRequest request;
  request.issued_at_s = inputs.time_s.front();
  request.horizon_s = 180 * 60.0;
  StartValueForecast f;
  std::string error;
  ASSERT_TRUE(MakeStartValueForecast(plant, spec, Series{}, weather, plan, request, {}, &f, &error))
      << error;
  ExpectBandsHoldThePoint(f);

  Series expected_in = f.banded.forecast.inputs_used;
  Drivers drivers;
  ASSERT_TRUE(PrepareDrivers(expected_in, plant, spec, &drivers, &error)) << error;
  SimOutputs sim;
  Simulate(drivers, StartParams(plant), &sim);
  for (std::size_t h = 0; h < 180; ++h) {
    ASSERT_EQ(expected_in[Channel::kGPoaWM2][h], 700.0) << h;
    ASSERT_EQ(expected_in[Channel::kMdotKgS][h], constant.mdot_kg_s) << h;
    ASSERT_EQ(f.banded.forecast.rows[Channel::kPElW][h], sim.p_el_w[h]) << h;
    ASSERT_EQ(f.banded.forecast.rows[Channel::kQThW][h], sim.q_th_w[h]) << h;
  }
  // The clear edge is the model at the clear sky with η_PV and F_th at their
  // Table 3 tops: at 10:00-13:00 on 1 June more than the point's 700 W/m².
  EXPECT_GT(f.banded.bands.p_el_p90[60], f.banded.forecast.rows[Channel::kPElW][60]);
  EXPECT_LT(f.banded.bands.p_el_p10[60], 0.5 * f.banded.forecast.rows[Channel::kPElW][60]);
  EXPECT_NE(f.inputs.find("weather_forecast 180/180"), std::string::npos) << f.inputs;
  EXPECT_NE(f.inputs.find("plan 180/180"), std::string::npos) << f.inputs;
}

// A plant whose truth lies inside Table 3's ranges, on a day of each kind
// after a morning of the same kind: the measured outputs of the next day's
// daylight lie in the band on most minutes: it spans overcast to clear, the
// pump off and on, and the yields over Table 3's range (seed 5: P_el 0.94,
// 0.90, 1.00 and Q_u 0.99, 0.99, 1.00 of the minutes).
TEST(StartValueForecast, TheNextDaysMeasuredOutputsLieInTheBand) {
  for (DayType type : {DayType::kClear, DayType::kBrokenClouds, DayType::kOvercast}) {
    const Days d({type, type, type});
    ForecastRequest request;
    request.issued_at_s = d.At(1, 0.0);
    StartValueForecast f;
    std::string error;
    ASSERT_TRUE(MakeStartValueForecast(d.plant, d.spec,
                                       d.data.Between(d.At(0, 4.0), request.issued_at_s), Series{},
                                       Series{}, request, {}, &f, &error))
        << error;
    ExpectBandsHoldThePoint(f);
    double in[2] = {0, 0}, n = 0;
    const Series& rows = f.banded.forecast.rows;
    const ForecastBands& b = f.banded.bands;
    const std::size_t first = d.data.RowAtOrAfter(request.issued_at_s);
    for (std::size_t h = 0; h < rows.size(); ++h) {
      const std::size_t i = first + h;
      ASSERT_EQ(d.data.time_s[i], rows.time_s[h]);
      if (d.data[Channel::kGPoaWM2][i] < 50.0) continue;
      const double p = d.data[Channel::kPElW][i], q = d.data[Channel::kQThW][i];
      in[0] += p >= b.p_el_p10[h] && p <= b.p_el_p90[h];
      in[1] += q >= b.q_th_p10[h] && q <= b.q_th_p90[h];
      ++n;
    }
    ASSERT_GT(n, 300) << DayTypeName(type);
    EXPECT_GT(in[0] / n, 0.85) << DayTypeName(type) << ": P_el in the band";
    EXPECT_GT(in[1] / n, 0.9) << DayTypeName(type) << ": Q_u in the band";
  }
}

TEST(StartValueForecast, WithoutMeasuredWeatherItSaysWhatIsMissing) {
  const Plant plant = DesignExamplePlant();
  ForecastRequest request;
  request.issued_at_s = testing::kJune1_2024UtcS;
  StartValueForecast f;
  std::string error;
  EXPECT_FALSE(MakeStartValueForecast(plant, testing::SpecOf("2N1Ccolwr"), Series{}, Series{},
                                      Series{}, request, {}, &f, &error));
  EXPECT_NE(error.find("t_amb_c"), std::string::npos) << error;
}

}  // namespace
}  // namespace pvtwin
