// A provider's weather forecast brought to 1 min (core/forecast/
// weather_resample.h) and the sub-models it uses, against hand calculations
// from the published formulas.
#include <gtest/gtest.h>

#include <cmath>

#include "core/common/units.h"
#include "core/forecast/weather_resample.h"
#include "core/physics/clear_sky.h"
#include "core/physics/sky_radiation.h"
#include "core/physics/wind.h"
#include "tests/support/fixtures.h"

namespace pvtwin {
namespace {

// 2024-06-01 00:00 UTC.
using testing::kJune1_2024UtcS;

Plant SitePlant() {
  Plant p;
  p.latitude_rad = DegToRad(47.358);
  p.longitude_rad = DegToRad(16.128);
  p.tilt_rad = DegToRad(20.0);
  p.azimuth_rad = DegToRad(180.0);
  return p;
}

// Hand-chosen hourly GHI/DHI of a clear June day at 47° N (Open-Meteo
// convention: the value at hh:00 is the mean of the hour before).
const std::vector<double> kGhi = {0,   0,   0,   0,   25,  120, 270, 430, 580, 705, 800, 850,
                                  850, 800, 705, 580, 430, 270, 120, 25,  0,   0,   0,   0};
const std::vector<double> kDhi = {0,   0,   0,   0,   20, 55, 80, 95, 105, 110, 115, 115,
                                  115, 115, 110, 105, 95, 80, 55, 20, 0,   0,   0,   0};

ProviderWeather HourlyDay() {
  ProviderWeather w;
  for (int h = 0; h < 24; ++h) w.time_s.push_back(kJune1_2024UtcS + h * 3600);
  w.step_s = 3600.0;
  w.irradiance_offset_s = -3600.0;
  w.ghi_w_m2 = kGhi;
  w.dhi_w_m2 = kDhi;
  for (int h = 0; h < 24; ++h) {
    w.t_amb_c.push_back(15.0 + 8.0 * std::sin(kPi * (h - 5) / 18.0));
    w.wind_m_s.push_back(2.0 + 0.1 * h);
    w.dew_point_c.push_back(11.0);
    w.cloud_cover_pct.push_back(20.0);
  }
  return w;
}

double MeanOver(const Series& s, Channel c, std::int64_t from, std::int64_t to) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.time_s[i] >= from && s.time_s[i] < to) {
      sum += s[c][i];
      ++n;
    }
  }
  EXPECT_EQ(n, (to - from) / 60);
  return sum / n;
}

// The bound of each minute from physics alone (the header's rule, not the
// code's vectors): 2 × the minute's clear sky + 50 W/m², at most the 2500
// W/m² physical limit. For the plane the clear sky is the larger of the
// plane's and the horizontal's.
std::vector<double> BoundOf(const ClearSkyGrid& g, bool plane) {
  std::vector<double> bound(g.time_s.size());
  for (std::size_t k = 0; k < bound.size(); ++k) {
    const double clear =
        plane ? std::max(g.clear_poa_w_m2[k], g.clear_ghi_w_m2[k]) : g.clear_ghi_w_m2[k];
    bound[k] = std::min(2500.0, 2.0 * clear + 50.0);
  }
  return bound;
}

// BSRN's physically possible GHI (Long & Dutton): 1.5·S_a·cos(θz)^1.2 +
// 100 W/m², 100 W/m² with the sun down.
double BsrnPossibleGhi(double zenith_rad, double time_s) {
  const double mu = std::max(0.0, std::cos(zenith_rad));
  return 1.5 * ExtraterrestrialNormalWM2(DayOfYearUtc(time_s)) * std::pow(mu, 1.2) + 100.0;
}

// The power law with α = 1/7, by hand: (2 m / 10 m)^(1/7) = exp(ln 0.2 / 7)
// = exp(−1.609438 / 7) = exp(−0.229920) = 0.794597, so 5 m/s at 10 m is
// 3.97299 m/s at 2 m; 3 m: 0.3^(1/7) = 0.841982 → 4.20991 m/s.
TEST(WindHeightLaw, PowerLawWithHellmannExponentMatchesHandCalculation) {
  EXPECT_NEAR(WindAtHeightPowerLaw(5.0, 10.0, 2.0), 3.97299, 1e-5);
  EXPECT_NEAR(WindAtHeightPowerLaw(5.0, 10.0, 3.0), 4.20991, 1e-5);
  EXPECT_DOUBLE_EQ(WindAtHeightPowerLaw(5.0, 10.0, 10.0), 5.0);
  EXPECT_DOUBLE_EQ(WindAtHeightPowerLaw(0.0, 10.0, 2.0), 0.0);
}

// Brunt (1932) with the Crawford & Duchon (1999) cloud term, by hand, for air
// at 20 °C, dew point 10 °C, half the sky covered:
//   e_a   = 6.112·exp(17.62·10 / 253.12)          = 12.2603 hPa
//   ε_clr = 0.52 + 0.065·√12.2603                 = 0.747596
//   ε     = 0.5 + 0.5·0.747596                    = 0.873798
//   σT⁴   = 5.670374e-8 · 293.15⁴                 = 418.766 W/m²
//   L     = 0.873798 · 418.766 (horizontal)       = 365.917 W/m²
//   T_sky = (L/σ)^¼ − 273.15                      = 10.278 °C
// tilted 30°: (1 + cos 30°)/2·ε·σT⁴ + (1 − cos 30°)/2·σT⁴ = 369.457 W/m².
TEST(SkyModel, BruntWithCloudCorrectionMatchesHandCalculation) {
  const double e_a = SaturationVapourPressureHpa(10.0);
  EXPECT_NEAR(e_a, 12.2603, 1e-4);
  const double eps_clear = BruntClearSkyEmissivity(e_a);
  EXPECT_NEAR(eps_clear, 0.747596, 1e-6);
  const double eps = CloudySkyEmissivity(eps_clear, 0.5);
  EXPECT_NEAR(eps, 0.873798, 1e-6);
  const double lw = LongWaveOnPlaneWM2(eps, 20.0, 0.0);
  EXPECT_NEAR(lw, 365.917, 1e-3);
  EXPECT_NEAR(SkyTemperatureK(lw) - kZeroCelsiusK, 10.278, 1e-3);
  EXPECT_NEAR(LongWaveOnPlaneWM2(eps, 20.0, DegToRad(30.0)), 369.457, 1e-3);
}

// Each hour's energy is kept exactly by the 1-min irradiance (GHI, DHI and
// an in-plane GTI), and the minutes follow the sun (not a step function).
TEST(WeatherResample, EveryIntervalKeepsItsEnergy) {
  ProviderWeather w = HourlyDay();
  w.gti_w_m2 = kGhi;
  for (double& v : w.gti_w_m2) v *= 1.1;
  Series out;
  WeatherResampleSummary summary;
  std::string error;
  ASSERT_TRUE(ResampleWeatherTo1Min(SitePlant(), w, {}, &out, &summary, &error)) << error;
  ASSERT_EQ(out.size(), 24u * 60u);
  EXPECT_EQ(out.time_s.front(), kJune1_2024UtcS - 3600);
  for (std::size_t i = 0; i < w.time_s.size(); ++i) {
    const std::int64_t from = w.time_s[i] - 3600, to = w.time_s[i];
    EXPECT_NEAR(MeanOver(out, Channel::kGhiWM2, from, to), kGhi[i], 1e-9 * (1 + kGhi[i])) << i;
    EXPECT_NEAR(MeanOver(out, Channel::kDhiWM2, from, to), kDhi[i], 1e-9 * (1 + kDhi[i])) << i;
    EXPECT_NEAR(MeanOver(out, Channel::kGPoaWM2, from, to), w.gti_w_m2[i],
                1e-9 * (1 + w.gti_w_m2[i]))
        << i;
  }
  // 07:00-08:00 UTC, a rising morning hour: the first minute below the last.
  const std::size_t first =
      static_cast<std::size_t>((kJune1_2024UtcS + 7 * 3600 - out.time_s[0]) / 60);
  EXPECT_LT(out[Channel::kGhiWM2][first] + 50.0, out[Channel::kGhiWM2][first + 59]);
  for (std::size_t k = 0; k < out.size(); ++k) {
    EXPECT_LE(out[Channel::kDhiWM2][k], out[Channel::kGhiWM2][k] + 1e-9) << k;
    EXPECT_GE(out[Channel::kGhiWM2][k], 0.0) << k;
  }
  // A physical day: nothing above its clear sky, nothing flagged.
  EXPECT_TRUE(summary.above_clear_sky.empty());
  EXPECT_TRUE(summary.above_clear_sky_rows.empty());
}

// 18:00-19:00 UTC holds the sunset (about 18:47 UTC at the plant on 1 June).
// A value the clear sky cannot shape (index above 2) but the minutes' bounds
// can hold is spread over the minutes with the sun up, within their bounds:
// the hour's energy kept, nothing after sunset, nothing flagged. A value
// beyond the bounds (100 W/m² in an hour whose clear sky gives a few W/m²)
// is flagged and stored at the bounds: its mean is their mean.
TEST(WeatherResample, AnUnshapeableSunsetHourKeepsItsEnergyInDaylight) {
  const std::int64_t from = kJune1_2024UtcS + 18 * 3600, to = kJune1_2024UtcS + 19 * 3600;
  const ClearSkyGrid g =
      MakeClearSkyGrid(SitePlant(), kJune1_2024UtcS - 3600, kJune1_2024UtcS + 23 * 3600, 3.0);
  const std::vector<double> bound = BoundOf(g, false);
  const std::size_t first = static_cast<std::size_t>((from - g.time_s[0]) / 60);
  double clear_mean = 0.0, bound_mean = 0.0;
  int daylight = 0;
  for (std::size_t k = first; k < first + 60; ++k) {
    clear_mean += g.clear_ghi_w_m2[k] / 60.0;
    const bool up = g.zenith_rad[k] < kPi / 2;
    bound_mean += up ? bound[k] / 60.0 : 0.0;
    daylight += up ? 1 : 0;
  }
  ASSERT_GT(daylight, 40);
  ASSERT_LT(daylight, 60);
  // Index above 2, below the bounds' mean (which is 2·clear_mean +
  // 50·daylight/60 W/m²).
  const double fits = 2.0 * clear_mean + 25.0 * daylight / 60.0;
  ASSERT_GT(bound_mean, fits);
  for (const double value : {fits, 100.0}) {
    ProviderWeather w = HourlyDay();
    w.ghi_w_m2[19] = value;
    w.dhi_w_m2[19] = 0.9 * value;
    Series out;
    WeatherResampleSummary summary;
    std::string error;
    ASSERT_TRUE(ResampleWeatherTo1Min(SitePlant(), w, {}, &out, &summary, &error)) << error;
    ASSERT_EQ(out.time_s, g.time_s);
    EXPECT_GE(summary.flat_intervals, 1u);
    EXPECT_GT(out[Channel::kGhiWM2][first], std::min(value, bound_mean));  // daylight carries it
    EXPECT_EQ(out[Channel::kGhiWM2][first + 59], 0.0);                     // 18:59, after sunset
    for (std::size_t k = first; k < first + 60; ++k) {
      EXPECT_LE(out[Channel::kGhiWM2][k], bound[k] + 1e-9) << k;
      EXPECT_LE(out[Channel::kDhiWM2][k], bound[k] + 1e-9) << k;
    }
    if (value == fits) {
      EXPECT_NEAR(MeanOver(out, Channel::kGhiWM2, from, to), value, 1e-9);
      EXPECT_NEAR(MeanOver(out, Channel::kDhiWM2, from, to), 0.9 * value, 1e-9);
      EXPECT_TRUE(summary.above_clear_sky.empty());
      continue;
    }
    ASSERT_GT(100.0, bound_mean);
    EXPECT_NEAR(MeanOver(out, Channel::kGhiWM2, from, to), bound_mean, 1e-9);
    ASSERT_FALSE(summary.above_clear_sky.empty());
    const IrradianceAboveClearSky& a = summary.above_clear_sky.front();
    EXPECT_EQ(a.channel, Channel::kGhiWM2);
    EXPECT_EQ(a.from_s, from);
    EXPECT_EQ(a.to_s, to);
    EXPECT_EQ(a.value_w_m2, 100.0);
    EXPECT_NEAR(a.clear_sky_w_m2, clear_mean, 1e-9);
    EXPECT_NEAR(a.bound_w_m2, bound_mean, 1e-9);
  }
}

// The hand-chosen clear June day, as a provider in local time (UTC+3)
// labelled UTC would send it: each value 3 h late. The evening hours then
// carry 430, 270, 120 W/m² after our sunset (18:47 UTC): no minute may hold
// that, each such interval is named, and nothing above the bound is stored.
TEST(WeatherResample, AnswerShiftedByHoursIsClippedToItsClearSkyAndNamed) {
  ProviderWeather w = HourlyDay();
  w.gti_w_m2 = kGhi;
  for (double& v : w.gti_w_m2) v *= 1.1;
  for (std::vector<double>* c : {&w.ghi_w_m2, &w.dhi_w_m2, &w.gti_w_m2}) {
    std::vector<double> shifted(c->size(), 0.0);
    for (std::size_t i = 3; i < c->size(); ++i) shifted[i] = (*c)[i - 3];
    *c = shifted;
  }
  Series out;
  WeatherResampleSummary summary;
  std::string error;
  ASSERT_TRUE(ResampleWeatherTo1Min(SitePlant(), w, {}, &out, &summary, &error)) << error;
  const ClearSkyGrid g =
      MakeClearSkyGrid(SitePlant(), out.time_s.front(), out.time_s.back() + 60, 3.0);
  const std::vector<double> ghi_bound = BoundOf(g, false), poa_bound = BoundOf(g, true);
  for (std::size_t k = 0; k < out.size(); ++k) {
    EXPECT_LE(out[Channel::kGhiWM2][k], ghi_bound[k] + 1e-9) << k;
    EXPECT_LE(out[Channel::kDhiWM2][k], ghi_bound[k] + 1e-9) << k;
    EXPECT_LE(out[Channel::kGPoaWM2][k], poa_bound[k] + 1e-9) << k;
    EXPECT_LE(out[Channel::kGhiWM2][k], BsrnPossibleGhi(g.zenith_rad[k], g.time_s[k] + 30.0)) << k;
  }
  // 19:00-20:00 UTC (stamped 20:00) is night for the whole hour at the
  // plant: its 270 W/m² (kGhi[17]) cannot be there.
  const std::int64_t night_from = kJune1_2024UtcS + 19 * 3600,
                     night_to = kJune1_2024UtcS + 20 * 3600;
  bool named = false;
  for (const IrradianceAboveClearSky& a : summary.above_clear_sky) {
    EXPECT_GT(a.value_w_m2, a.bound_w_m2);
    EXPECT_LT(a.clear_sky_w_m2, a.value_w_m2);
    if (a.channel == Channel::kGhiWM2 && a.from_s == night_from && a.to_s == night_to) {
      named = true;
      EXPECT_EQ(a.value_w_m2, 270.0);
      EXPECT_EQ(a.clear_sky_w_m2, 0.0);
      EXPECT_NEAR(a.bound_w_m2, 50.0, 1e-9);  // the allowance, the sun being down
    }
  }
  EXPECT_TRUE(named);
  ASSERT_EQ(summary.above_clear_sky_rows.size(), out.size());
  const std::size_t night = static_cast<std::size_t>((night_from - out.time_s[0]) / 60);
  EXPECT_EQ(summary.above_clear_sky_rows[night], 1);
  EXPECT_EQ(summary.above_clear_sky_rows[night + 59], 1);
  // 09:00-10:00 UTC (stamped 10:00) carries kGhi[7] = 430 W/m², a value its
  // clear sky can give: kept exactly, not flagged.
  const std::int64_t from = kJune1_2024UtcS + 9 * 3600, to = kJune1_2024UtcS + 10 * 3600;
  EXPECT_NEAR(MeanOver(out, Channel::kGhiWM2, from, to), w.ghi_w_m2[10], 1e-9);
  EXPECT_EQ(summary.above_clear_sky_rows[static_cast<std::size_t>((from - out.time_s[0]) / 60)], 0);
}

TEST(WeatherResample, GhiDhiAreTransposedToThePlaneWithoutTiltedIrradiance) {
  Series out;
  WeatherResampleSummary summary;
  std::string error;
  ASSERT_TRUE(ResampleWeatherTo1Min(SitePlant(), HourlyDay(), {}, &out, &summary, &error));
  ASSERT_TRUE(out.Has(Channel::kGPoaWM2));
  ASSERT_TRUE(out.Has(Channel::kGPoaDiffuseWM2));
  // Around noon a south plane tilted 20° at 47° N gets more than GHI.
  const std::size_t noon =
      static_cast<std::size_t>((kJune1_2024UtcS + 11 * 3600 - out.time_s[0]) / 60);
  EXPECT_GT(out[Channel::kGPoaWM2][noon], out[Channel::kGhiWM2][noon]);
  EXPECT_LT(out[Channel::kGPoaWM2][noon], 1.2 * out[Channel::kGhiWM2][noon]);
}

// Instantaneous values: linear between the stamps at the minute's middle;
// wind brought from 10 m to the collector's height.
TEST(WeatherResample, TemperatureInterpolatedAndWindAtCollectorHeight) {
  const ProviderWeather w = HourlyDay();
  WeatherResampleOptions options;
  options.collector_height_m = 2.0;
  Series out;
  WeatherResampleSummary summary;
  std::string error;
  ASSERT_TRUE(ResampleWeatherTo1Min(SitePlant(), w, options, &out, &summary, &error));
  EXPECT_NEAR(summary.wind_factor, 0.794597, 1e-6);
  // The minute 10:14-10:15 has its middle at 10:14:30, 14.5/60 of the way.
  const std::size_t k =
      static_cast<std::size_t>((kJune1_2024UtcS + 10 * 3600 + 14 * 60 - out.time_s[0]) / 60);
  const double x = 14.5 / 60.0;
  EXPECT_NEAR(out[Channel::kTAmbC][k], w.t_amb_c[10] + x * (w.t_amb_c[11] - w.t_amb_c[10]), 1e-9);
  EXPECT_NEAR(out[Channel::kWindMS][k],
              0.794597 * (w.wind_m_s[10] + x * (w.wind_m_s[11] - w.wind_m_s[10])), 1e-5);
  // Sky from Brunt: colder than the air, warmer than -60 °C.
  EXPECT_LT(out[Channel::kTSkyC][k], out[Channel::kTAmbC][k]);
  EXPECT_GT(out[Channel::kTSkyC][k], -60.0);
}

// A missing provider value stays missing (NaN), never zero.
TEST(WeatherResample, MissingValuesStayMissing) {
  ProviderWeather w = HourlyDay();
  w.ghi_w_m2[12] = std::nan("");
  w.t_amb_c[12] = std::nan("");
  Series out;
  WeatherResampleSummary summary;
  std::string error;
  ASSERT_TRUE(ResampleWeatherTo1Min(SitePlant(), w, {}, &out, &summary, &error));
  const std::size_t k =
      static_cast<std::size_t>((kJune1_2024UtcS + 11 * 3600 + 30 * 60 - out.time_s[0]) / 60);
  EXPECT_TRUE(std::isnan(out[Channel::kGhiWM2][k]));
  EXPECT_TRUE(std::isnan(out[Channel::kGPoaWM2][k]));
  EXPECT_TRUE(std::isnan(out[Channel::kTAmbC][k]));
  EXPECT_FALSE(std::isnan(out[Channel::kGhiWM2][k + 60]));
}

// DHI from DNI: GHI − DNI·cos θ_z, never above GHI, energy of GHI kept.
TEST(WeatherResample, DiffuseFromBeamNormalStaysWithinGlobal) {
  ProviderWeather w = HourlyDay();
  w.dhi_w_m2.clear();
  for (double g : kGhi) w.dni_w_m2.push_back(g > 100 ? 780.0 : 0.0);
  Series out;
  WeatherResampleSummary summary;
  std::string error;
  ASSERT_TRUE(ResampleWeatherTo1Min(SitePlant(), w, {}, &out, &summary, &error));
  for (std::size_t k = 0; k < out.size(); ++k) {
    EXPECT_GE(out[Channel::kDhiWM2][k], 0.0);
    EXPECT_LE(out[Channel::kDhiWM2][k], out[Channel::kGhiWM2][k] + 1e-9);
  }
}

TEST(WeatherResample, RefusesUnevenStamps) {
  ProviderWeather w = HourlyDay();
  w.time_s[5] += 60;
  Series out;
  WeatherResampleSummary summary;
  std::string error;
  EXPECT_FALSE(ResampleWeatherTo1Min(SitePlant(), w, {}, &out, &summary, &error));
  EXPECT_NE(error.find("row 5"), std::string::npos) << error;
}

}  // namespace
}  // namespace pvtwin
