#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/common/units.h"
#include "core/model/irradiance_drivers.h"
#include "core/model/thermal_model.h"
#include "core/physics/irradiance.h"
#include "core/physics/solar_position.h"
#include "core/synth/synthetic_plant.h"
#include "core/synth/weather_generator.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

IsotropicSkyInput ClearNoon() {
  IsotropicSkyInput in;
  in.ghi_w_m2 = 800.0;
  in.dhi_w_m2 = 120.0;
  in.zenith_rad = DegToRad(30.0);
  in.aoi_rad = DegToRad(30.0);
  in.tilt_rad = 0.0;
  in.ground_albedo = 0.2;
  return in;
}

TEST(Irradiance, HorizontalPlaneReturnsGhi) {
  IsotropicSkyInput in = ClearNoon();
  for (double zenith_deg : {0.0, 30.0, 60.0, 85.0}) {
    for (double azimuth_deg : {90.0, 180.0, 250.0}) {
      in.zenith_rad = DegToRad(zenith_deg);
      in.aoi_rad = AngleOfIncidenceRad(in.zenith_rad, DegToRad(azimuth_deg), 0.0, kPi);
      const PoaComponents poa = TransposeIsotropicSky(in);
      EXPECT_NEAR(poa.global_w_m2(), in.ghi_w_m2, 1e-9) << zenith_deg;
      EXPECT_DOUBLE_EQ(poa.sky_diffuse_w_m2, in.dhi_w_m2);
      EXPECT_EQ(poa.ground_diffuse_w_m2, 0.0);
    }
  }
}

// β = 90°: I_dsky = DHI/2, I_dgd = ρ/2 · GHI.
TEST(Irradiance, VerticalPlaneSeesHalfTheSkyAndHalfTheGround) {
  IsotropicSkyInput in = ClearNoon();
  in.tilt_rad = DegToRad(90.0);
  in.aoi_rad = DegToRad(60.0);
  const PoaComponents poa = TransposeIsotropicSky(in);
  EXPECT_NEAR(poa.ground_diffuse_w_m2, 0.2 / 2.0 * 800.0, 1e-9);
  EXPECT_NEAR(poa.sky_diffuse_w_m2, 120.0 / 2.0, 1e-9);
  // Beam normal (800 − 120)/cos 30° = 785.196 W/m², times cos 60°.
  EXPECT_NEAR(poa.beam_w_m2, 680.0 / std::cos(DegToRad(30.0)) * 0.5, 1e-9);
}

TEST(Irradiance, PlaneFacingTheSunReceivesBeamNormalIrradiance) {
  IsotropicSkyInput in = ClearNoon();
  in.zenith_rad = DegToRad(50.0);
  in.tilt_rad = in.zenith_rad;
  in.aoi_rad = 0.0;
  const PoaComponents poa = TransposeIsotropicSky(in);
  EXPECT_NEAR(poa.beam_w_m2, 680.0 / std::cos(DegToRad(50.0)), 1e-9);
}

// Beam rule: no beam with cos θ_z < 0.0175 (θ_z > 89.0°), below the
// horizon, or with the sun behind the plane.
TEST(Irradiance, NoBeamNearOrBelowTheHorizonOrFromBehind) {
  IsotropicSkyInput in = ClearNoon();
  in.ghi_w_m2 = 30.0;
  in.dhi_w_m2 = 20.0;
  in.tilt_rad = DegToRad(90.0);
  in.aoi_rad = DegToRad(10.0);
  in.zenith_rad = DegToRad(88.9);  // cos = 0.0192: beam kept
  EXPECT_GT(TransposeIsotropicSky(in).beam_w_m2, 0.0);
  in.zenith_rad = DegToRad(89.2);  // cos = 0.0140: beam dropped
  EXPECT_EQ(TransposeIsotropicSky(in).beam_w_m2, 0.0);
  in.zenith_rad = DegToRad(95.0);
  EXPECT_EQ(TransposeIsotropicSky(in).beam_w_m2, 0.0);
  in.zenith_rad = DegToRad(40.0);
  in.aoi_rad = DegToRad(100.0);
  const PoaComponents behind = TransposeIsotropicSky(in);
  EXPECT_EQ(behind.beam_w_m2, 0.0);
  EXPECT_GT(behind.sky_diffuse_w_m2, 0.0);
}

TEST(Irradiance, DiffuseAboveGlobalAndNegativeValuesAreClipped) {
  IsotropicSkyInput in = ClearNoon();
  in.ghi_w_m2 = 100.0;
  in.dhi_w_m2 = 104.0;
  EXPECT_EQ(TransposeIsotropicSky(in).beam_w_m2, 0.0);
  in.ghi_w_m2 = -3.0;
  in.dhi_w_m2 = -2.0;
  const PoaComponents night = TransposeIsotropicSky(in);
  EXPECT_EQ(night.global_w_m2(), 0.0);
  in.ghi_w_m2 = std::nan("");
  EXPECT_TRUE(std::isnan(TransposeIsotropicSky(in).global_w_m2()));
}

// Hand values: β = 45°: θ_sky = 59.68 − 0.1388·45 + 0.001497·2025
// = 59.68 − 6.246 + 3.031425 = 56.465425°; θ_gnd = 90 − 0.5788·45 +
// 0.002693·2025 = 90 − 26.046 + 5.453325 = 69.407325°. β = 90°: θ_sky =
// 59.68 − 12.492 + 12.1257 = 59.3137°, θ_gnd = 90 − 52.092 + 21.8133 =
// 59.7213°. β = 0: 59.68° and 90°.
TEST(Irradiance, BrandemuehlBeckmanPublishedValues) {
  const EffectiveDiffuseAngles at45 = BrandemuehlBeckmanAngles(DegToRad(45.0));
  EXPECT_NEAR(RadToDeg(at45.sky_rad), 56.465425, 1e-9);
  EXPECT_NEAR(RadToDeg(at45.ground_rad), 69.407325, 1e-9);
  const EffectiveDiffuseAngles at90 = BrandemuehlBeckmanAngles(DegToRad(90.0));
  EXPECT_NEAR(RadToDeg(at90.sky_rad), 59.3137, 1e-9);
  EXPECT_NEAR(RadToDeg(at90.ground_rad), 59.7213, 1e-9);
  const EffectiveDiffuseAngles at0 = BrandemuehlBeckmanAngles(0.0);
  EXPECT_NEAR(RadToDeg(at0.sky_rad), 59.68, 1e-12);
  EXPECT_NEAR(RadToDeg(at0.ground_rad), 90.0, 1e-12);
}

// 900 W/m² global and 200 W/m² diffuse in a 30° plane, GHI 850 W/m²:
// I_dgd = 0.2·(1 − cos 30°)/2·850 = 0.2·0.0669873·850 = 11.38784 W/m².
TEST(Irradiance, SplitMeasuredPoaWithInPlaneDiffuse) {
  MeasuredPoaInput in;
  in.g_poa_w_m2 = 900.0;
  in.g_poa_diffuse_w_m2 = 200.0;
  in.ghi_w_m2 = 850.0;
  in.tilt_rad = DegToRad(30.0);
  in.ground_albedo = 0.2;
  const PoaComponents poa = SplitMeasuredPoa(in);
  EXPECT_NEAR(poa.beam_w_m2, 700.0, 1e-9);
  EXPECT_NEAR(poa.ground_diffuse_w_m2, 11.387841, 1e-6);
  EXPECT_NEAR(poa.sky_diffuse_w_m2, 200.0 - 11.387841, 1e-6);
  EXPECT_NEAR(poa.global_w_m2(), 900.0, 1e-9);

  // Without GHI the in-plane global stands in: 0.2·0.0669873·900 = 12.05771.
  in.ghi_w_m2 = std::nan("");
  EXPECT_NEAR(SplitMeasuredPoa(in).ground_diffuse_w_m2, 12.057714, 1e-6);
}

TEST(Irradiance, SplitMeasuredPoaFallsBackToAllBeamWithoutDiffuse) {
  MeasuredPoaInput in;
  in.g_poa_w_m2 = 640.0;
  in.ghi_w_m2 = 600.0;  // without I_dh the split is not observable
  in.tilt_rad = DegToRad(20.0);
  const PoaComponents poa = SplitMeasuredPoa(in);
  EXPECT_EQ(poa.beam_w_m2, 640.0);
  EXPECT_EQ(poa.sky_diffuse_w_m2, 0.0);
  EXPECT_EQ(poa.ground_diffuse_w_m2, 0.0);
}

TEST(Irradiance, SplitMeasuredPoaKeepsPartsNonNegativeAndSummingToGlobal) {
  MeasuredPoaInput in;
  in.tilt_rad = DegToRad(60.0);
  in.ground_albedo = 0.8;  // snow
  in.ghi_w_m2 = 500.0;
  // Ground estimate 0.8·0.25·500 = 100 W/m² exceeds the measured diffuse.
  in.g_poa_w_m2 = 400.0;
  in.g_poa_diffuse_w_m2 = 60.0;
  PoaComponents poa = SplitMeasuredPoa(in);
  EXPECT_NEAR(poa.ground_diffuse_w_m2, 60.0, 1e-12);
  EXPECT_EQ(poa.sky_diffuse_w_m2, 0.0);
  EXPECT_NEAR(poa.global_w_m2(), 400.0, 1e-9);
  // Diffuse reading above global (sensor mismatch): no beam.
  in.g_poa_diffuse_w_m2 = 420.0;
  poa = SplitMeasuredPoa(in);
  EXPECT_EQ(poa.beam_w_m2, 0.0);
  EXPECT_NEAR(poa.global_w_m2(), 400.0, 1e-9);
  // Night offset.
  in.g_poa_w_m2 = -2.0;
  in.g_poa_diffuse_w_m2 = -1.0;
  EXPECT_EQ(SplitMeasuredPoa(in).global_w_m2(), 0.0);
  in.g_poa_w_m2 = std::nan("");
  EXPECT_TRUE(std::isnan(SplitMeasuredPoa(in).beam_w_m2));
}

// Transposing GHI/DHI and splitting the resulting in-plane global gives the
// same parts back, whether the in-plane diffuse or GHI and DHI stand beside it.
TEST(Irradiance, SplitInvertsTransposition) {
  IsotropicSkyInput sky = ClearNoon();
  sky.tilt_rad = DegToRad(35.0);
  sky.aoi_rad = DegToRad(12.0);
  const PoaComponents forward = TransposeIsotropicSky(sky);
  for (const bool in_plane_diffuse : {true, false}) {
    SCOPED_TRACE(in_plane_diffuse ? "in-plane diffuse" : "GHI and DHI");
    MeasuredPoaInput measured;
    measured.g_poa_w_m2 = forward.global_w_m2();
    if (in_plane_diffuse) {
      measured.g_poa_diffuse_w_m2 = forward.sky_diffuse_w_m2 + forward.ground_diffuse_w_m2;
    } else {
      measured.dhi_w_m2 = sky.dhi_w_m2;
    }
    measured.ghi_w_m2 = sky.ghi_w_m2;
    measured.tilt_rad = sky.tilt_rad;
    measured.ground_albedo = sky.ground_albedo;
    const PoaComponents back = SplitMeasuredPoa(measured);
    EXPECT_NEAR(back.beam_w_m2, forward.beam_w_m2, 1e-9);
    EXPECT_NEAR(back.sky_diffuse_w_m2, forward.sky_diffuse_w_m2, 1e-9);
    EXPECT_NEAR(back.ground_diffuse_w_m2, forward.ground_diffuse_w_m2, 1e-9);
  }
}

// Paper 2.5 with the measured I_gt, I_gh and I_dh (the paper's set-up, Table
// 2) and no in-plane diffuse: β = 30°, ρ = 0.2, I_gt = 800, I_gh = 700,
// I_dh = 150 W/m²:
//   I_dsky = (1 + cos 30°)/2 · 150 = 0.9330127 · 150      = 139.951905 W/m²
//   I_dgd  = 0.2 · (1 − cos 30°)/2 · 700 = 0.2·0.0669873·700 = 9.378222 W/m²
//   beam   = 800 − 139.951905 − 9.378222                  = 650.669873 W/m²
// (the old fallback took all 800 W/m² as beam, giving the diffuse light the
// beam's incidence angle modifier).
TEST(Irradiance, SplitMeasuredPoaWithGhiAndDhiIsThePapersEquation) {
  MeasuredPoaInput in;
  in.g_poa_w_m2 = 800.0;
  in.ghi_w_m2 = 700.0;
  in.dhi_w_m2 = 150.0;
  in.tilt_rad = DegToRad(30.0);
  in.ground_albedo = 0.2;
  PoaComponents poa = SplitMeasuredPoa(in);
  EXPECT_NEAR(poa.sky_diffuse_w_m2, 139.951905, 1e-6);
  EXPECT_NEAR(poa.ground_diffuse_w_m2, 9.378222, 1e-6);
  EXPECT_NEAR(poa.beam_w_m2, 650.669873, 1e-6);
  // An overcast row whose diffuse parts exceed the measured global: no beam,
  // the diffuse parts scaled to the global (120 → 111.96 + 1.61 = 113.57 W/m²
  // of diffuse against 100 W/m² measured).
  in.g_poa_w_m2 = 100.0;
  in.ghi_w_m2 = 120.0;
  in.dhi_w_m2 = 120.0;
  poa = SplitMeasuredPoa(in);
  EXPECT_EQ(poa.beam_w_m2, 0.0);
  EXPECT_NEAR(poa.global_w_m2(), 100.0, 1e-9);
  EXPECT_NEAR(poa.ground_diffuse_w_m2 / poa.sky_diffuse_w_m2,
              0.2 * (1 - std::cos(DegToRad(30.0))) * 120 / ((1 + std::cos(DegToRad(30.0))) * 120),
              1e-12);
  // A measured in-plane diffuse still takes precedence.
  in.g_poa_w_m2 = 800.0;
  in.g_poa_diffuse_w_m2 = 200.0;
  EXPECT_NEAR(SplitMeasuredPoa(in).beam_w_m2, 600.0, 1e-9);
}

// The model end to end: noise-free data of a truth with the beam/diffuse
// split (2N1CcolwrI) whose logger kept the in-plane global, GHI and DHI but
// no in-plane diffuse are simulated by the truth's own parameters as well as
// with the in-plane diffuse (the paper's set-up; before paper 2.5 was used
// here, the diffuse light got the beam IAM and the heat was off).
TEST(Irradiance, AnIVariantWithoutInPlaneDiffuseReproducesItsTruthFromGhiAndDhi) {
  const Plant plant = DesignExamplePlant();
  WeatherOptions weather;
  weather.num_days = 2;
  weather.step_s = 60.0;
  weather.seed = 5;
  const ModelSpec spec = testing::SpecOf("2N1CcolwrI");
  const ParamVector truth = ReferenceTruthParams(plant);
  Series s = MakeSyntheticPlantData(plant, weather, spec, truth, SensorNoise{});
  ASSERT_TRUE(s.Has(Channel::kGhiWM2) && s.Has(Channel::kDhiWM2) && s.Has(Channel::kGPoaWM2));
  s.columns[static_cast<std::size_t>(Channel::kGPoaDiffuseWM2)].clear();
  Drivers drivers;
  std::string error;
  ASSERT_TRUE(PrepareDrivers(s, plant, spec, &drivers, &error)) << error;
  SimOutputs sim;
  Simulate(drivers, truth, &sim);
  double worst_q = 0.0, worst_p = 0.0, max_q = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    worst_q = std::max(worst_q, std::fabs(sim.q_th_w[i] - s[Channel::kQThW][i]));
    worst_p = std::max(worst_p, std::fabs(sim.p_el_w[i] - s[Channel::kPElW][i]));
    max_q = std::max(max_q, std::fabs(s[Channel::kQThW][i]));
  }
  EXPECT_GT(max_q, 100.0) << "no heat to compare";
  EXPECT_LT(worst_q, 1e-6 * max_q + 1e-6);
  EXPECT_LT(worst_p, 1e-6);
}

// SunAtRowMiddles splits a long series between two threads; every row must
// still get the position the one-thread batch gives it, to the bit (14 days
// at 1 min starting mid-day, so that the split falls inside a UT day).
TEST(Irradiance, SunAtRowMiddlesOfALongSeriesEqualsTheOneThreadBatch) {
  Plant plant;
  plant.latitude_rad = DegToRad(49.23);
  plant.longitude_rad = DegToRad(6.99);
  plant.elevation_m = 230.0;
  Series s;
  s.step_s = 60.0;
  for (std::int64_t t = 1718884800; s.size() < 20160; t += 60) s.time_s.push_back(t);
  const std::vector<SolarPosition> split = SunAtRowMiddles(s, plant);

  std::vector<double> mid_s;
  for (std::int64_t t : s.time_s) mid_s.push_back(static_cast<double>(t) + 30.0);
  SolarPositionInput site;
  site.latitude_rad = plant.latitude_rad;
  site.longitude_rad = plant.longitude_rad;
  site.elevation_m = plant.elevation_m;
  std::vector<SolarPosition> batch;
  ComputeSolarPositions(mid_s, site, &batch);

  ASSERT_EQ(split.size(), batch.size());
  auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x); };
  for (std::size_t i = 0; i < batch.size(); ++i) {
    ASSERT_EQ(bits(split[i].zenith_rad), bits(batch[i].zenith_rad)) << "row " << i;
    ASSERT_EQ(bits(split[i].azimuth_rad), bits(batch[i].azimuth_rad)) << "row " << i;
    ASSERT_EQ(bits(split[i].elevation_rad), bits(batch[i].elevation_rad)) << "row " << i;
    ASSERT_EQ(bits(split[i].declination_rad), bits(batch[i].declination_rad)) << "row " << i;
    ASSERT_EQ(bits(split[i].hour_angle_rad), bits(batch[i].hour_angle_rad)) << "row " << i;
  }
}

// The backtest computes the sun once for its whole series and hands each
// slice its part (PrepareDrivers with `sun`): a slice's drivers and outputs
// must be those of the slice prepared alone, to the bit, for a variant with
// the beam/diffuse split and one whose effects read the sun (shading, the
// clock offset). A wrong number of positions is an error.
TEST(Irradiance, ASliceWithItsPartOfTheSeriesSunPreparesAsTheSliceAlone) {
  const Plant plant = DesignExamplePlant();
  WeatherOptions weather;
  weather.num_days = 3;
  weather.step_s = 60.0;
  weather.seed = 9;
  const ParamVector truth = ReferenceTruthParams(plant);
  const Series s =
      MakeSyntheticPlantData(plant, weather, testing::SpecOf("2N1CcolwrI"), truth, SensorNoise{});
  const std::vector<SolarPosition> sun = SunAtRowMiddles(s, plant);
  const std::size_t begin = 700, end = 3500;  // from a morning to an afternoon
  const Series slice = s.Slice(begin, end);
  const std::span<const SolarPosition> part = std::span(sun).subspan(begin, end - begin);
  auto bits = [](const std::vector<double>& v) {
    std::vector<std::uint64_t> b;
    for (double x : v) b.push_back(std::bit_cast<std::uint64_t>(x));
    return b;
  };
  for (const char* variant : {"2N1CcolwrI", "2N1Ccolwr+shading+clock_offset"}) {
    SCOPED_TRACE(variant);
    const ModelSpec spec = testing::SpecOf(variant);
    Drivers alone, given;
    std::string error;
    ASSERT_TRUE(PrepareDrivers(slice, plant, spec, &alone, &error)) << error;
    ASSERT_TRUE(PrepareDrivers(slice, plant, spec, part, &given, &error)) << error;
    EXPECT_EQ(bits(given.aoi_rad), bits(alone.aoi_rad));
    EXPECT_EQ(bits(given.g_poa_w_m2), bits(alone.g_poa_w_m2));
    EXPECT_EQ(bits(given.g_abs_w_m2), bits(alone.g_abs_w_m2));
    EXPECT_EQ(bits(given.sun_azimuth_rad), bits(alone.sun_azimuth_rad));
    EXPECT_EQ(bits(given.sun_elevation_rad), bits(alone.sun_elevation_rad));
    const ParamVector params = TruthParamsFor(plant, spec);
    SimOutputs a, g;
    Simulate(alone, params, &a);
    Simulate(given, params, &g);
    EXPECT_EQ(bits(g.p_el_w), bits(a.p_el_w));
    EXPECT_EQ(bits(g.q_th_w), bits(a.q_th_w));
    // The outputs are not trivially equal: the day has sun and heat.
    EXPECT_GT(*std::max_element(a.q_th_w.begin(), a.q_th_w.end()), 100.0);

    Drivers wrong;
    EXPECT_FALSE(PrepareDrivers(slice, plant, spec, part.first(part.size() - 1), &wrong, &error));
    EXPECT_NE(error.find("2799 sun positions for 2800 rows"), std::string::npos) << error;
  }
}

// PrepareDrivers splits its row-local work on a long series between two
// threads (ForRowHalves): each row's drivers must be those of a slice
// prepared alone on one thread, to the bit, in both halves and across the
// seam (5 days at 5 s, the seam at noon of day 2; slices of 5000 rows, some
// 7 hours of daylight each). Rows with a gap in g_poa (transposed from GHI
// and DHI), calm wind (ln 0) and a missing inlet temperature (not usable)
// take the loops' other branches; the sky temperature is measured or
// estimated, as [plant] sky says, so that it too is row-local.
TEST(Irradiance, TheDriversOfALongSeriesAreThoseOfItsSlicesPreparedAlone) {
  Plant plant = DesignExamplePlant();
  WeatherOptions weather;
  weather.num_days = 5;
  weather.step_s = 5.0;
  weather.seed = 4;
  const ParamVector truth = ReferenceTruthParams(plant);
  Series s =
      MakeSyntheticPlantData(plant, weather, testing::SpecOf("2N1CcolwrI"), truth, SensorNoise{});
  ASSERT_GE(s.size(), kRowsToSplit);
  ASSERT_TRUE(s.Has(Channel::kGhiWM2) && s.Has(Channel::kDhiWM2) && s.Has(Channel::kWindMS));
  const std::size_t n_all = s.size();
  const std::size_t seam = n_all / 2;
  const std::size_t slices[] = {6000, seam - 2500, n_all - 10000};
  for (std::size_t at :
       {std::size_t{8000}, seam - 2000, seam - 1, seam, seam + 1500, n_all - 8000}) {
    std::size_t sunny = at;  // the first sunny row from `at` on
    while (sunny + 1 < n_all && !(s[Channel::kGPoaWM2][sunny] > 200.0)) ++sunny;
    s[Channel::kGPoaWM2][sunny] = std::nan("");
    s[Channel::kWindMS][at] = 0.0;
    s[Channel::kTInC][at + 3] = std::nan("");
  }
  // "" when whole[begin + i] and alone[i] have the same bits for every i
  // (or both are empty: a field the variant does not fill), else the first
  // row that differs.
  auto differs = [](const auto& whole, const auto& alone, std::size_t begin) -> std::string {
    if (whole.empty() && alone.empty()) return "";
    if (whole.size() < begin + alone.size() || alone.empty()) return "too few rows";
    for (std::size_t i = 0; i < alone.size(); ++i) {
      const auto w = whole[begin + i];
      const auto a = alone[i];
      if (std::memcmp(&w, &a, sizeof(w)) != 0) {
        return "row " + std::to_string(begin + i) + ": " + std::to_string(w) + " against " +
               std::to_string(a);
      }
    }
    return "";
  };
  struct Case {
    const char* variant;
    SkySource sky;
  };
  for (const Case c :
       {Case{"2N1CcolwrI", SkySource::kMeasured}, Case{"1Nwr", SkySource::kEstimated}}) {
    SCOPED_TRACE(c.variant);
    plant.sky = c.sky;
    const ModelSpec spec = testing::SpecOf(c.variant);
    Drivers whole;
    std::string error;
    ASSERT_TRUE(PrepareDrivers(s, plant, spec, &whole, &error)) << error;
    std::size_t transposed = 0, calm = 0, unusable = 0;
    for (const std::size_t begin : slices) {
      const std::size_t end = begin + 5000;
      SCOPED_TRACE(begin);
      ASSERT_LT(end - begin, kSunRowsToSplit);
      Drivers alone;
      ASSERT_TRUE(PrepareDrivers(s.Slice(begin, end), plant, spec, &alone, &error)) << error;
      const std::size_t n = end - begin;
      const std::pair<const char*, std::vector<double> Drivers::*> fields[] = {
          {"aoi_rad", &Drivers::aoi_rad},
          {"g_poa_w_m2", &Drivers::g_poa_w_m2},
          {"g_abs_w_m2", &Drivers::g_abs_w_m2},
          {"sun_azimuth_rad", &Drivers::sun_azimuth_rad},
          {"sun_elevation_rad", &Drivers::sun_elevation_rad},
          {"g_beam_w_m2", &Drivers::g_beam_w_m2},
          {"g_ref_w_m2", &Drivers::g_ref_w_m2},
          {"t_sky_c", &Drivers::t_sky_c},
          {"wind_m_s", &Drivers::wind_m_s},
          {"ln_wind", &Drivers::ln_wind},
          {"t_sky_k4", &Drivers::t_sky_k4},
          {"capacity_flow_w_k", &Drivers::capacity_flow_w_k}};
      for (const auto& [name, field] : fields) {
        EXPECT_EQ(differs(whole.*field, alone.*field, begin), "") << name;
      }
      const Drivers::IamParts& w = whole.iam_parts;
      const Drivers::IamParts& a = alone.iam_parts;
      EXPECT_EQ(w.beam_w_m2.empty(), !spec.iam);
      EXPECT_EQ(a.beam_w_m2.empty(), !spec.iam);
      EXPECT_EQ(differs(w.beam_w_m2, a.beam_w_m2, begin), "");
      EXPECT_EQ(differs(w.sky_w_m2, a.sky_w_m2, begin), "");
      EXPECT_EQ(differs(w.ground_w_m2, a.ground_w_m2, begin), "");
      EXPECT_EQ(differs(w.beam_excess, a.beam_excess, begin), "");
      EXPECT_EQ(differs(w.paper_k_beam, a.paper_k_beam, begin), "");
      EXPECT_EQ(differs(whole.usable, alone.usable, begin), "") << "usable";
      for (std::size_t i = 0; i < n; ++i) {
        transposed += std::isnan(s[Channel::kGPoaWM2][begin + i]) && alone.g_poa_w_m2[i] > 0.0;
        calm += alone.ln_wind[i] == -std::numeric_limits<double>::infinity();
        unusable += alone.usable[i] == 0;
      }
    }
    // The loops' other branches were taken: transposed sun, calm rows (both
    // variants read the wind), unusable rows.
    EXPECT_GE(transposed, 3U);
    EXPECT_GE(calm, 3U);
    EXPECT_GE(unusable, 3U);
  }
}

}  // namespace
}  // namespace pvtwin
