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
