// Forecasts (core/forecast/forecast.h): with perfect inputs a forecast of the true
// model reproduces the truth; without a weather forecast it persists the last
// measured day; without a plan it runs the window's typical day.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/data/resample.h"
#include "core/forecast/forecast.h"
#include "core/model/thermal_model.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/fixtures.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

using testing::kDayS;

struct ForecastCase {
  Plant plant = DesignExamplePlant();
  ModelSpec spec = testing::SpecOf("2N1Ccolwr");
  ParamVector truth = ReferenceTruthParams(DesignExamplePlant());
  Series data;  // 15 days, noise-free truth outputs
  std::int64_t t_forecast = 0;

  ForecastCase() {
    WeatherOptions weather;
    weather.num_days = 15;
    weather.seed = 5;
    weather.flow_mode = FlowMode::kVariable;
    data = MakeSyntheticPlantData(plant, weather, spec, truth, SensorNoise{});
    t_forecast = weather.start_time_s + 14 * kDayS;
  }
  std::size_t RowOf(std::int64_t t) const {
    return static_cast<std::size_t>((t - data.time_s.front()) / 60);
  }
  Series Before(std::int64_t t) const { return data.Slice(0, RowOf(t)); }
  Series From(std::int64_t t) const { return data.Slice(RowOf(t), data.size()); }
};

double MaxAbsDiff(const std::vector<double>& a, const std::vector<double>& b, std::size_t offset) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::isnan(a[i]) || std::isnan(b[offset + i])) return INFINITY;
    m = std::max(m, std::fabs(a[i] - b[offset + i]));
  }
  return m;
}

TEST(Forecast, PerfectInputsReproduceTheTruthModel) {
  const ForecastCase c;
  const Series future = c.From(c.t_forecast);
  ForecastRequest request;
  request.issued_at_s = c.t_forecast;
  Forecast f;
  std::string error;
  ASSERT_TRUE(MakeForecast(c.plant, c.spec, c.truth, c.Before(c.t_forecast), future, future,
                           request, &f, &error))
      << error;
  ASSERT_EQ(f.rows.size(), 1440u);
  EXPECT_EQ(f.rows.time_s.front(), c.t_forecast);
  EXPECT_EQ(f.inputs.weather_forecast, 1440u);
  EXPECT_EQ(f.inputs.operation_plan, 1440u);
  EXPECT_EQ(f.inputs.weather_persistence, 0u);
  // The truth ran without a break; the forecast restarts a day earlier from a
  // steady state, which the collector forgets within hours (τ = C/U).
  const std::size_t offset = c.RowOf(c.t_forecast);
  EXPECT_LT(MaxAbsDiff(f.rows[Channel::kPElW], c.data[Channel::kPElW], offset), 1e-6);
  EXPECT_LT(MaxAbsDiff(f.rows[Channel::kQThW], c.data[Channel::kQThW], offset), 1e-6);
  EXPECT_LT(MaxAbsDiff(f.rows[Channel::kTOutC], c.data[Channel::kTOutC], offset), 1e-6);
}

TEST(Forecast, WithoutWeatherForecastPersistsTheLastDay) {
  const ForecastCase c;
  const Series plan = c.From(c.t_forecast);
  // Broken clouds on the last day: every other 5 minutes at 30 % of the sun.
  Series history = c.Before(c.t_forecast);
  const std::size_t yesterday = history.RowAtOrAfter(c.t_forecast - kDayS);
  for (Channel ch :
       {Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaDiffuseWM2}) {
    if (!history.Has(ch)) continue;
    for (std::size_t i = yesterday; i < history.size(); ++i) {
      if ((i - yesterday) / 5 % 2 == 1) history[ch][i] *= 0.3;
    }
  }
  ForecastRequest request;
  request.issued_at_s = c.t_forecast;
  Forecast f;
  std::string error;
  ASSERT_TRUE(MakeForecast(c.plant, c.spec, c.truth, history, Series{}, plan, request, &f, &error))
      << error;
  EXPECT_EQ(f.inputs.weather_forecast, 0u);
  EXPECT_EQ(f.inputs.weather_persistence, 1440u);
  EXPECT_EQ(f.inputs.weather_missing, 0u);
  ASSERT_EQ(history.size() - yesterday, 1440u);
  for (Channel ch : {Channel::kTAmbC, Channel::kWindMS}) {
    if (!history.Has(ch)) continue;
    for (std::size_t i = 0; i < 1440; i += 97) {
      EXPECT_EQ(f.inputs_used[ch][i], history[ch][yesterday + i])
          << ChannelName(ch) << " row " << i;
    }
  }
  // The irradiance is the last day's as smart persistence (forecast.h): its
  // clear-sky index over the hour, so the day keeps its energy (the sun's
  // path differs by a day's declination only), nights stay dark, and the
  // clouds that passed minute by minute are averaged, not replayed.
  const std::vector<double>& g = f.inputs_used[Channel::kGPoaWM2];
  const std::vector<double>& measured = history[Channel::kGPoaWM2];
  double energy = 0.0, energy_yesterday = 0.0, variation = 0.0, variation_yesterday = 0.0;
  for (std::size_t i = 0; i < 1440; ++i) {
    energy += g[i];
    energy_yesterday += measured[yesterday + i];
    if (measured[yesterday + i] == 0.0) {
      EXPECT_EQ(g[i], 0.0) << "row " << i;
    }
    if (i == 0) continue;
    variation += std::fabs(g[i] - g[i - 1]);
    variation_yesterday += std::fabs(measured[yesterday + i] - measured[yesterday + i - 1]);
  }
  EXPECT_NEAR(energy / energy_yesterday, 1.0, 0.02);
  EXPECT_LT(variation, 0.1 * variation_yesterday);
  EXPECT_NE(f.inputs.Describe().find("persistence 1440/1440"), std::string::npos);
}

TEST(Forecast, WithoutPlanRunsTheMedianDayOfTheWindow) {
  const ForecastCase c;
  Series history = c.Before(c.t_forecast);
  // Inlet temperature: 30 °C on most days, 50 °C on a minority; the typical
  // day is the median, not the mean.
  auto& t_in = history[Channel::kTInC];
  for (std::size_t i = 0; i < history.size(); ++i) {
    const std::int64_t day = (history.time_s[i] - history.time_s.front()) / kDayS;
    t_in[i] = day % 3 == 0 ? 50.0 : 30.0;
  }
  ForecastRequest request;
  request.issued_at_s = c.t_forecast;
  Forecast f;
  std::string error;
  ASSERT_TRUE(MakeForecast(c.plant, c.spec, c.truth, history, c.From(c.t_forecast), Series{},
                           request, &f, &error))
      << error;
  EXPECT_EQ(f.inputs.operation_plan, 0u);
  EXPECT_EQ(f.inputs.operation_typical, 1440u);
  for (double v : f.inputs_used[Channel::kTInC]) ASSERT_EQ(v, 30.0);
}

// A history of 15-min interval rows (a coarser logger's, issue 53) is
// forecast at 15 min: each row's weather from the weather_forecast table is
// the mean of the table's minutes over the row's interval, as the measured
// rows are means, not the table's value at the interval's start; the rows
// then carry the energy of the minutes.
TEST(Forecast, AtAFifteenMinuteStepTheWeatherForecastIsAveragedOverEachRow) {
  const ForecastCase c;
  Series history;
  std::string error;
  ASSERT_TRUE(Resample(c.Before(c.t_forecast), 900.0, &history, &error)) << error;
  const Series minutes = c.From(c.t_forecast);
  ForecastRequest request;
  request.issued_at_s = c.t_forecast;
  request.step_s = 900.0;
  Forecast f;
  ASSERT_TRUE(
      MakeForecast(c.plant, c.spec, c.truth, history, minutes, Series{}, request, &f, &error))
      << error;
  ASSERT_EQ(f.rows.size(), 96u);
  EXPECT_EQ(f.inputs.weather_forecast, 96u);
  double energy_rows_wh = 0.0, energy_minutes_wh = 0.0, largest_start_gap_w_m2 = 0.0;
  for (std::size_t k = 0; k < f.rows.size(); ++k) {
    double sum = 0.0;
    for (std::size_t m = 0; m < 15; ++m) sum += minutes[Channel::kGPoaWM2][15 * k + m];
    ASSERT_NEAR(f.inputs_used[Channel::kGPoaWM2][k], sum / 15.0, 1e-9) << k;
    largest_start_gap_w_m2 = std::max(largest_start_gap_w_m2,
                                      std::fabs(sum / 15.0 - minutes[Channel::kGPoaWM2][15 * k]));
    energy_rows_wh += f.inputs_used[Channel::kGPoaWM2][k] * 0.25;
  }
  for (std::size_t m = 0; m < 1440; ++m) energy_minutes_wh += minutes[Channel::kGPoaWM2][m] / 60.0;
  EXPECT_GT(largest_start_gap_w_m2, 10.0);  // the start of an interval is not its mean
  EXPECT_NEAR(energy_rows_wh, energy_minutes_wh, 1e-6 * energy_minutes_wh);
}

// The inputs column says, per channel, where the values came from, and names
// the weather_forecast rows' source where the table was used.
TEST(Forecast, InputsNameTheSourceOfEachChannel) {
  const ForecastCase c;
  Series weather = c.From(c.t_forecast);
  weather[Channel::kTAmbC].clear();  // the air temperature is not forecast: persisted
  ForecastRequest request;
  request.issued_at_s = c.t_forecast;
  Forecast f;
  std::string error;
  ASSERT_TRUE(MakeForecast(c.plant, c.spec, c.truth, c.Before(c.t_forecast), weather, Series{},
                           request, &f, &error))
      << error;
  f.inputs.weather_sources = {"fetch http://127.0.0.1:8080/v1/forecast (Open-Meteo JSON, hourly)"};
  const std::string text = f.inputs.Describe();
  EXPECT_NE(text.find("g_poa_w_m2=weather_forecast 1440"), std::string::npos) << text;
  EXPECT_NE(text.find("t_amb_c=persistence 1440"), std::string::npos) << text;
  EXPECT_NE(text.find("t_in_c=typical_day 1440"), std::string::npos) << text;
  EXPECT_NE(text.find("; weather_forecast source: fetch http://127.0.0.1:8080/v1/forecast"),
            std::string::npos)
      << text;
  // Without any weather_forecast row used, no source is named.
  Forecast persisted;
  ASSERT_TRUE(MakeForecast(c.plant, c.spec, c.truth, c.Before(c.t_forecast), Series{}, Series{},
                           request, &persisted, &error));
  persisted.inputs.weather_sources = f.inputs.weather_sources;
  EXPECT_EQ(persisted.inputs.Describe().find("source:"), std::string::npos);
}

// Weather rows stored clipped because their interval carried more
// irradiance than its clear sky gives (import-weather marks their source):
// the forecast's inputs say so; rows of a physical file do not.
TEST(Forecast, InputsWarnOfWeatherAboveItsClearSky) {
  const ForecastCase c;
  ForecastRequest request;
  request.issued_at_s = c.t_forecast;
  Forecast f;
  std::string error;
  ASSERT_TRUE(MakeForecast(c.plant, c.spec, c.truth, c.Before(c.t_forecast), c.From(c.t_forecast),
                           Series{}, request, &f, &error))
      << error;
  const std::string plain = "import-weather shifted.json (Open-Meteo JSON, hourly)";
  f.inputs.weather_sources = {plain};
  EXPECT_EQ(f.inputs.Describe().find("weather_warning"), std::string::npos) << f.inputs.Describe();
  f.inputs.weather_sources = {plain, plain + " [clipped: irradiance above clear sky]"};
  const std::string text = f.inputs.Describe();
  EXPECT_NE(text.find("; weather_warning=irradiance_above_clear_sky"), std::string::npos) << text;
  EXPECT_NE(text.find("| " + plain + " [clipped: irradiance above clear sky]"), std::string::npos)
      << text;
}

TEST(Forecast, RefusesHistoryShorterThanADay) {
  const ForecastCase c;
  ForecastRequest request;
  request.issued_at_s = c.t_forecast;
  const Series short_history = c.data.Slice(c.RowOf(c.t_forecast) - 600, c.RowOf(c.t_forecast));
  Forecast f;
  std::string error;
  EXPECT_FALSE(MakeForecast(c.plant, c.spec, c.truth, short_history, Series{}, Series{}, request,
                            &f, &error));
  EXPECT_NE(error.find("less than one day"), std::string::npos);
}

// A provider that gives the in-plane global irradiance but no in-plane
// diffuse: yesterday's measured diffuse is not persisted beside today's
// forecast global (the model splits the forecast's own irradiance), and the
// rows count as weather-forecast rows for the bands.
TEST(Forecast, AnIrradianceChannelTheWeatherForecastLacksIsLeftOutNotPersisted) {
  const ForecastCase c;
  ASSERT_TRUE(c.data.Has(Channel::kGPoaDiffuseWM2));
  Series weather = c.From(c.t_forecast);
  weather[Channel::kGPoaDiffuseWM2].clear();
  ForecastRequest request;
  request.issued_at_s = c.t_forecast;
  Forecast f;
  std::string error;
  ASSERT_TRUE(MakeForecast(c.plant, c.spec, c.truth, c.Before(c.t_forecast), weather, Series{},
                           request, &f, &error))
      << error;
  EXPECT_FALSE(f.inputs_used.Has(Channel::kGPoaDiffuseWM2));
  EXPECT_EQ(f.inputs.weather_forecast, 1440u);
  EXPECT_EQ(std::count(f.weather_from_forecast.begin(), f.weather_from_forecast.end(), 1), 1440);
  EXPECT_EQ(f.inputs.Describe().find("g_poa_diffuse_w_m2="), std::string::npos);
  // Without a weather forecast the channel is persisted as before.
  ASSERT_TRUE(MakeForecast(c.plant, c.spec, c.truth, c.Before(c.t_forecast), Series{}, Series{},
                           request, &f, &error));
  EXPECT_TRUE(f.inputs_used.Has(Channel::kGPoaDiffuseWM2));
}

}  // namespace
}  // namespace pvtwin
