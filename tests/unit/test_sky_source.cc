// Where the model's sky temperature comes from ([plant] sky,
// SkyTemperaturesC): Swinbank's clear-sky law by hand, the implausibility
// rule on a long-wave channel that puts the sky above the air in full sun,
// and the config key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "config/plant_config.h"
#include "core/common/units.h"
#include "core/model/thermal_model.h"
#include "core/physics/sky_radiation.h"

namespace pvtwin {
namespace {

// Swinbank 1963: T_sky = 0.0552·T_air^1.5. At 293.15 K: 293.15^1.5 =
// 5019.24, × 0.0552 = 277.06 K; at 303.15 K: 5278.24 × 0.0552 = 291.36 K.
TEST(SkySource, SwinbankByHand) {
  EXPECT_NEAR(SwinbankSkyTemperatureK(293.15), 277.06, 0.01);
  EXPECT_NEAR(SwinbankSkyTemperatureK(303.15), 291.36, 0.01);
}

// 60 rows in full sun at 30 °C air; the long-wave channel gives the sky
// `excess_k` above the air on the first `warm` rows and 15 K below on the rest.
Series Sunny(double excess_k, int warm) {
  Series s;
  s.step_s = 60;
  std::vector<double> g, t_amb, lw;
  for (int i = 0; i < 60; ++i) {
    s.time_s.push_back(1717243200 + 60 * i);
    g.push_back(800.0);
    t_amb.push_back(30.0);
    const double t_sky_k = CToK(30.0 + (i < warm ? excess_k : -15.0));
    lw.push_back(kStefanBoltzmannW_m2k4 * std::pow(t_sky_k, 4));
  }
  s[Channel::kGPoaWM2] = g;
  s[Channel::kTAmbC] = t_amb;
  s[Channel::kLwDownWM2] = lw;
  return s;
}

TEST(SkySource, AnImplausibleChannelIsReplacedAndSaysWhy) {
  Plant plant;
  std::string note;
  // 40 of 60 sunny rows 15 K above the air: implausible, the estimate is used.
  std::vector<double> t = SkyTemperaturesC(Sunny(15.0, 40), plant, &note);
  EXPECT_NEAR(t[0], KToC(SwinbankSkyTemperatureK(CToK(30.0))), 1e-9);
  EXPECT_NE(note.find("40 of 60 rows in full sun"), std::string::npos) << note;
  EXPECT_NE(note.find("Swinbank"), std::string::npos) << note;
  // 20 of 60: a few warm rows (thin cloud) are no reason, the channel stays.
  t = SkyTemperaturesC(Sunny(15.0, 20), plant, &note);
  EXPECT_NEAR(t[59], 15.0, 1e-6);
  EXPECT_EQ(note, "");
  // [plant] sky = "measured" keeps even an implausible channel; "estimated"
  // never reads it.
  plant.sky = SkySource::kMeasured;
  t = SkyTemperaturesC(Sunny(15.0, 60), plant, &note);
  EXPECT_NEAR(t[0], 45.0, 1e-6);
  EXPECT_EQ(note, "");
  plant.sky = SkySource::kEstimated;
  t = SkyTemperaturesC(Sunny(-15.0, 0), plant, &note);
  EXPECT_NEAR(t[0], KToC(SwinbankSkyTemperatureK(CToK(30.0))), 1e-9);
  EXPECT_NE(note.find("estimated"), std::string::npos);
}

// Dew point by Magnus with Alduchov & Eskridge's coefficients against
// psychrometric tables (dew point at 20 °C, 50 % RH: 9.3 °C; at 30 °C, 80 %:
// 26.2 °C; at 0 °C, 100 %: 0 °C by definition), to their 0.1 K.
TEST(SkySource, DewPointMatchesPsychrometricTables) {
  EXPECT_NEAR(DewPointC(20.0, 50.0), 9.3, 0.05);
  EXPECT_NEAR(DewPointC(30.0, 80.0), 26.2, 0.05);
  EXPECT_NEAR(DewPointC(0.0, 100.0), 0.0, 1e-12);
  EXPECT_TRUE(std::isnan(DewPointC(20.0, 0.0)));
  EXPECT_TRUE(std::isnan(DewPointC(20.0, 120.0)));
}

// Berdahl & Martin's clear-sky emittance by hand from the published formula
// ε = 0.711 + 0.56·(t_d/100) + 0.73·(t_d/100)² + 0.013·cos(2π·h/24)
//     + 0.00012·(p − 1000):
//   t_d = 10 °C: 0.711 + 0.056 + 0.0073 = 0.7743;
//   at midnight (cos 0 = 1): + 0.013 = 0.7873, without a pressure;
//   at solar noon (cos π = −1) and 950 hPa: 0.7743 − 0.013 − 0.006 = 0.7553.
//   t_d = −10 °C at 6 h (cos π/2 = 0), 1000 hPa: 0.711 − 0.056 + 0.0073 = 0.6623.
// The sky temperature of ε = 0.7553 over 25 °C air: 0.7553^¼ = 0.932245,
// × 298.15 K = 277.95 K.
TEST(SkySource, BerdahlMartinEmittanceByHand) {
  const double nan = std::nan("");
  EXPECT_NEAR(BerdahlMartinClearSkyEmittance(10.0, 0.0, nan), 0.7873, 1e-12);
  EXPECT_NEAR(BerdahlMartinClearSkyEmittance(10.0, 12.0, 950.0), 0.7553, 1e-12);
  EXPECT_NEAR(BerdahlMartinClearSkyEmittance(-10.0, 6.0, 1000.0), 0.6623, 1e-12);
  EXPECT_NEAR(SkyTemperatureFromEmittanceK(0.7553, 298.15), 277.95, 0.01);
}

// With rh_pct in the data the estimate that replaces an implausible
// long-wave channel is the dew-point sky, and the note names it. Rows at
// 30 °C, 40 % RH, 950 hPa, 2024-06-01 12:00 UTC onwards at longitude 0:
// t_d = 14.93 °C (Magnus); at noon ε = 0.711 + 0.0836 + 0.0163 − 0.013 −
// 0.006 = 0.7919, T_sky = 0.7919^¼ · 303.15 K = 285.97 K (12.8 °C), 5.4 K
// colder than Swinbank's 18.2 °C.
TEST(SkySource, WithHumidityTheDewPointSkyReplacesTheChannel) {
  Plant plant;
  Series s = Sunny(15.0, 60);
  s[AirChannel::kRhPct].assign(s.size(), 40.0);
  s[AirChannel::kPAirHpa].assign(s.size(), 950.0);
  std::string note;
  SkyUsed used = SkyUsed::kMeasured;
  const std::vector<double> t = SkyTemperaturesC(s, plant, &note, &used);
  EXPECT_EQ(used, SkyUsed::kDewPoint);
  EXPECT_NE(note.find("implausible"), std::string::npos) << note;
  EXPECT_NE(note.find("Berdahl & Martin"), std::string::npos) << note;
  EXPECT_EQ(note.find("on the rest"), std::string::npos) << note;
  const double t_d = DewPointC(30.0, 40.0);
  EXPECT_NEAR(t_d, 14.93, 0.01);
  // Row 0 starts at 12:00 UTC, its middle is 12:00:30: h = 12.00833.
  const double eps = BerdahlMartinClearSkyEmittance(t_d, 12.0 + 30.0 / 3600.0, 950.0);
  EXPECT_NEAR(t[0], KToC(std::sqrt(std::sqrt(eps)) * CToK(30.0)), 1e-9);
  EXPECT_NEAR(t[0], 12.82, 0.01);
  // A row without humidity falls back to Swinbank, and the note says so.
  s[AirChannel::kRhPct][5] = std::nan("");
  const std::vector<double> u = SkyTemperaturesC(s, plant, &note, &used);
  EXPECT_NEAR(u[5], KToC(SwinbankSkyTemperatureK(CToK(30.0))), 1e-9);
  EXPECT_NE(note.find("59 of 60 rows"), std::string::npos) << note;
  EXPECT_NE(note.find("Swinbank"), std::string::npos) << note;
  // Without the channel, the air-temperature sky.
  s[AirChannel::kRhPct].clear();
  SkyTemperaturesC(s, plant, &note, &used);
  EXPECT_EQ(used, SkyUsed::kAirTemperature);
}

TEST(SkySource, TheConfigKeyTakesThreeWordsAndNamesItsLine) {
  Config config;
  Diagnostics errors;
  const std::string plant =
      "[plant]\nlatitude_deg = 47\nlongitude_deg = 16\ntilt_deg = 20\nazimuth_deg = 180\n"
      "area_m2 = 2\n";
  ASSERT_TRUE(ParseConfig(plant + "sky = \"estimated\"\n", "c.toml", &config, &errors));
  EXPECT_EQ(config.plant.sky, SkySource::kEstimated);
  errors.clear();
  EXPECT_FALSE(ParseConfig(plant + "sky = \"cloudy\"\n", "c.toml", &config, &errors));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].ToString().find("c.toml:7: sky = \"cloudy\""), std::string::npos)
      << errors[0].ToString();
  EXPECT_NE(errors[0].ToString().find("auto, measured, estimated"), std::string::npos);
}

}  // namespace
}  // namespace pvtwin
