#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/common/units.h"
#include "core/physics/solar_position.h"

namespace pvtwin {
namespace {

// NREL SPA report (Reda & Andreas, NREL/TP-560-34302, rev. 2008), appendix
// A5 worked example: 2003-10-17 12:30:30 local time at UTC−7, i.e.
// 19:30:30 UTC = unix 1066419030, ΔT = 67 s, Golden, Colorado.
SolarPositionInput ReportExampleInput() {
  SolarPositionInput in;
  in.time_s = 1066419030.0;
  in.latitude_rad = DegToRad(39.742476);
  in.longitude_rad = DegToRad(-105.1786);
  in.elevation_m = 1830.14;
  in.pressure_hpa = 820.0;
  in.temperature_c = 11.0;
  in.delta_t_s = 67.0;
  return in;
}

// Tolerances follow the number of decimals the report prints for each value.
// The report derives JC, JCE and JME from JD rounded to 6 decimals (a 2.8e-7
// day difference, 6e-12 in JC), and prints H = 11.105900° although its own
// ν + σ − α = 318.511910 − 105.1786 − 202.227408 = 11.105902°; likewise it
// prints H' = 11.10629° where H − Δα = 11.105902 + 0.000369 = 11.106271°.
TEST(SolarPosition, ReportWorkedExampleIntermediateValues) {
  const SolarPositionTrace t = ComputeSolarPositionTrace(ReportExampleInput());
  EXPECT_NEAR(t.julian_day, 2452930.312847, 1e-6);
  EXPECT_NEAR(t.julian_century, 0.0379277986858, 1e-11);
  EXPECT_NEAR(t.julian_ephemeris_day, 2452930.313623, 1e-6);
  EXPECT_NEAR(t.julian_ephemeris_century, 0.037927819916852, 1e-11);
  EXPECT_NEAR(t.julian_ephemeris_millennium, 0.003792781991685, 1e-12);
  EXPECT_NEAR(RadToDeg(t.heliocentric_longitude_rad), 24.0182616917, 1e-7);
  EXPECT_NEAR(RadToDeg(t.heliocentric_latitude_rad), -0.0001011219, 1e-9);
  EXPECT_NEAR(t.earth_sun_distance_au, 0.9965422974, 1e-9);
  EXPECT_NEAR(RadToDeg(t.geocentric_longitude_rad), 204.0182616917, 1e-7);
  EXPECT_NEAR(RadToDeg(t.geocentric_latitude_rad), 0.0001011219, 1e-9);
  EXPECT_NEAR(t.mean_elongation_moon_deg, 17185.861179, 1e-5);
  EXPECT_NEAR(t.mean_anomaly_sun_deg, 1722.893218, 1e-5);
  EXPECT_NEAR(t.mean_anomaly_moon_deg, 18234.075703, 1e-5);
  EXPECT_NEAR(t.moon_argument_latitude_deg, 18420.071012, 1e-5);
  EXPECT_NEAR(t.moon_ascending_node_deg, 51.686951, 1e-6);
  EXPECT_NEAR(RadToDeg(t.nutation_longitude_rad), -0.00399840, 1e-8);
  EXPECT_NEAR(RadToDeg(t.nutation_obliquity_rad), 0.00166657, 1e-8);
  EXPECT_NEAR(t.mean_obliquity_arcsec, 84379.672625, 1e-6);
  EXPECT_NEAR(RadToDeg(t.true_obliquity_rad), 23.440465, 1e-6);
  EXPECT_NEAR(RadToDeg(t.aberration_rad), -0.005711, 1e-6);
  EXPECT_NEAR(RadToDeg(t.apparent_sun_longitude_rad), 204.0085519281, 1e-7);
  EXPECT_NEAR(RadToDeg(t.mean_sidereal_time_rad), 318.515579, 1e-6);
  EXPECT_NEAR(RadToDeg(t.apparent_sidereal_time_rad), 318.511910, 1e-6);
  EXPECT_NEAR(RadToDeg(t.geocentric_right_ascension_rad), 202.227408, 1e-6);
  EXPECT_NEAR(RadToDeg(t.geocentric_declination_rad), -9.314340, 1e-6);
  EXPECT_NEAR(RadToDeg(t.geocentric_hour_angle_rad), 11.105900, 5e-6);
  EXPECT_NEAR(RadToDeg(t.equatorial_parallax_rad), 0.002451, 1e-6);
  EXPECT_NEAR(RadToDeg(t.parallax_right_ascension_rad), -0.000369, 1e-6);
  EXPECT_NEAR(RadToDeg(t.position.right_ascension_rad), 202.22704, 1e-5);
  EXPECT_NEAR(RadToDeg(t.position.declination_rad), -9.316179, 1e-6);
  EXPECT_NEAR(RadToDeg(t.position.hour_angle_rad), 11.10629, 3e-5);
  EXPECT_NEAR(RadToDeg(t.position.hour_angle_rad),
              RadToDeg(t.geocentric_hour_angle_rad - t.parallax_right_ascension_rad), 1e-12);
  EXPECT_NEAR(RadToDeg(t.elevation_no_refraction_rad), 39.872046, 1e-6);
  EXPECT_NEAR(RadToDeg(t.refraction_rad), 0.016332, 1e-6);
  EXPECT_NEAR(RadToDeg(t.position.elevation_rad), 39.888378, 1e-6);
}

TEST(SolarPosition, ReportWorkedExampleZenithAzimuthIncidence) {
  const SolarPosition p = ComputeSolarPosition(ReportExampleInput());
  EXPECT_NEAR(RadToDeg(p.zenith_rad), 50.11162, 1e-5);
  EXPECT_NEAR(RadToDeg(p.azimuth_rad), 194.34024, 1e-5);
  EXPECT_NEAR(p.earth_sun_distance_au, 0.9965422974, 1e-9);
  // Slope 30°, azimuth rotation −10° from south (east of south) = 170° from
  // north, clockwise.
  const double aoi_rad =
      AngleOfIncidenceRad(p.zenith_rad, p.azimuth_rad, DegToRad(30.0), DegToRad(170.0));
  EXPECT_NEAR(RadToDeg(aoi_rad), 25.18700, 1e-5);
}

// 2024 March equinox: 2024-03-20 03:06 UTC (unix 1710903960). The apparent
// sun longitude crosses 0 and the geocentric declination is 0 to within the
// sun's motion in the rounding minute (≈ 0.0003°).
TEST(SolarPosition, DeclinationVanishesAtTheMarchEquinox) {
  SolarPositionInput in;
  in.time_s = 1710903960.0;
  const SolarPositionTrace t = ComputeSolarPositionTrace(in);
  EXPECT_NEAR(RadToDeg(t.geocentric_declination_rad), 0.0, 0.005);
  const double lambda_deg = RadToDeg(t.apparent_sun_longitude_rad);
  EXPECT_NEAR(std::min(lambda_deg, 360.0 - lambda_deg), 0.0, 0.01);
}

// At 12:00 UTC on the equinox day the sun stands within the equation of
// time (≈ −7.5 min ⇒ ≈ 1.9° of hour angle) and the declination (≈ 0.4°) of
// the zenith at (0°, 0°); at the subsolar point (latitude δ, longitude −H as
// seen from (0°, 0°)) the zenith is 0 up to parallax (< 0.003°).
TEST(SolarPosition, SunIsOverheadAtTheSubsolarPoint) {
  SolarPositionInput in;
  in.time_s = 1710936000.0;  // 2024-03-20 12:00 UTC
  const SolarPosition at_origin = ComputeSolarPosition(in);
  EXPECT_LT(RadToDeg(at_origin.zenith_rad), 2.5);
  EXPECT_GT(RadToDeg(at_origin.zenith_rad), 1.0);
  EXPECT_LT(at_origin.hour_angle_rad, 0.0);  // before local apparent noon
  in.latitude_rad = at_origin.declination_rad;
  in.longitude_rad = -at_origin.hour_angle_rad;
  const SolarPosition overhead = ComputeSolarPosition(in);
  EXPECT_LT(RadToDeg(overhead.zenith_rad), 0.01);
}

// Local apparent noon at the June solstice, 47° N: zenith = φ − δ with
// δ = 23.44° (ε), refraction at 66° elevation < 0.01°.
TEST(SolarPosition, NoonZenithAtJuneSolsticeIsLatitudeMinusObliquity) {
  SolarPositionInput in;
  in.latitude_rad = DegToRad(47.0);
  in.longitude_rad = DegToRad(16.0);
  // 2024-06-20 20:51 UTC is the solstice; local noon at 16° E is ≈ 10:58 UTC
  // on 2024-06-20 (unix 1718841600 = 00:00 UTC), 10 h from the solstice.
  double best_zenith_rad = kPi;
  for (double t = 1718841600.0 + 10.0 * 3600.0; t < 1718841600.0 + 12.0 * 3600.0; t += 10.0) {
    in.time_s = t;
    best_zenith_rad = std::min(best_zenith_rad, ComputeSolarPosition(in).zenith_rad);
  }
  EXPECT_NEAR(RadToDeg(best_zenith_rad), 47.0 - 23.44, 0.02);
}

TEST(SolarPosition, AzimuthIsEastInTheMorningAndWestInTheAfternoon) {
  SolarPositionInput in;
  in.latitude_rad = DegToRad(47.0);
  in.longitude_rad = DegToRad(16.0);
  in.time_s = 1718841600.0 + 6.0 * 3600.0;  // ≈ 07:00 local solar time
  const SolarPosition morning = ComputeSolarPosition(in);
  in.time_s = 1718841600.0 + 15.0 * 3600.0;  // ≈ 16:00 local solar time
  const SolarPosition afternoon = ComputeSolarPosition(in);
  EXPECT_GT(morning.azimuth_rad, DegToRad(45.0));
  EXPECT_LT(morning.azimuth_rad, DegToRad(135.0));
  EXPECT_GT(afternoon.azimuth_rad, DegToRad(225.0));
  EXPECT_LT(afternoon.azimuth_rad, DegToRad(315.0));
  EXPECT_LT(morning.hour_angle_rad, 0.0);
  EXPECT_GT(afternoon.hour_angle_rad, 0.0);
}

TEST(SolarPosition, NoRefractionFarBelowTheHorizon) {
  SolarPositionInput in = ReportExampleInput();
  in.time_s += 12.0 * 3600.0;  // local midnight
  const SolarPositionTrace t = ComputeSolarPositionTrace(in);
  EXPECT_GT(RadToDeg(t.position.zenith_rad), 120.0);
  EXPECT_EQ(t.refraction_rad, 0.0);
  EXPECT_DOUBLE_EQ(t.position.elevation_rad, t.elevation_no_refraction_rad);
}

TEST(SolarPosition, AngleOfIncidenceOnHorizontalPlaneIsZenith) {
  for (double zenith_deg : {0.0, 10.0, 45.0, 80.0, 95.0}) {
    for (double azimuth_deg : {0.0, 90.0, 200.0}) {
      EXPECT_NEAR(
          AngleOfIncidenceRad(DegToRad(zenith_deg), DegToRad(azimuth_deg), 0.0, DegToRad(180.0)),
          DegToRad(zenith_deg), 1e-7);
    }
  }
}

TEST(SolarPosition, AngleOfIncidenceOnPlaneFacingTheSunIsZero) {
  const double zenith_rad = DegToRad(35.0);
  const double azimuth_rad = DegToRad(140.0);
  EXPECT_NEAR(AngleOfIncidenceRad(zenith_rad, azimuth_rad, zenith_rad, azimuth_rad), 0.0, 1e-7);
  // The back of that plane faces away: θ_inc = π.
  EXPECT_NEAR(AngleOfIncidenceRad(zenith_rad, azimuth_rad, kPi - zenith_rad, azimuth_rad + kPi),
              kPi, 1e-7);
  // Sun on the horizon due east, vertical south wall: θ_inc = 90°.
  EXPECT_NEAR(AngleOfIncidenceRad(DegToRad(90.0), DegToRad(90.0), DegToRad(90.0), DegToRad(180.0)),
              DegToRad(90.0), 1e-12);
}

// The batch path interpolates the geocentric part between daily knots; it
// must agree with the full algorithm, also across the 0/2π cut of the right
// ascension (March equinox) and across day boundaries.
TEST(SolarPosition, BatchAgreesWithFullAlgorithm) {
  SolarPositionInput site;
  site.latitude_rad = DegToRad(47.358);
  site.longitude_rad = DegToRad(16.128);
  site.elevation_m = 300.0;
  std::vector<double> times_s;
  for (double start : {1710720000.0 /* 2024-03-18 */, 1718841600.0, 1066419030.0}) {
    for (double t = start; t < start + 4.0 * 86400.0; t += 419.0) times_s.push_back(t);
  }
  std::vector<SolarPosition> batch;
  ComputeSolarPositions(times_s, site, &batch);
  ASSERT_EQ(batch.size(), times_s.size());
  double max_err_deg = 0.0;
  for (std::size_t i = 0; i < times_s.size(); ++i) {
    SolarPositionInput in = site;
    in.time_s = times_s[i];
    const SolarPosition exact = ComputeSolarPosition(in);
    max_err_deg = std::max(max_err_deg, std::abs(RadToDeg(batch[i].zenith_rad - exact.zenith_rad)));
    const double daz = std::remainder(batch[i].azimuth_rad - exact.azimuth_rad, 2.0 * kPi);
    max_err_deg = std::max(max_err_deg, std::abs(RadToDeg(daz)) * std::sin(exact.zenith_rad));
    max_err_deg =
        std::max(max_err_deg, std::abs(RadToDeg(batch[i].declination_rad - exact.declination_rad)));
  }
  EXPECT_LT(max_err_deg, 1e-5);
}

}  // namespace
}  // namespace pvtwin
