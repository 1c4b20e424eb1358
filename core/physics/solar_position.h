// Solar position: the NREL Solar Position Algorithm (SPA) and the angle of
// incidence of beam radiation on a tilted plane.
//
// Source: I. Reda, A. Andreas, "Solar Position Algorithm for Solar Radiation
// Applications", NREL/TP-560-34302, revised January 2008 (NREL SPA, Reda &
// Andreas 2008). Stated uncertainty ±0.0003° for the years −2000 … 6000.
//
// Conventions:
//   - time is unix seconds UTC (UT1 ≈ UTC to < 1 s, which moves the sun by
//     < 0.004°); ΔT = TT − UT1 is an input,
//   - latitude north positive, longitude east positive,
//   - azimuth from north, clockwise (east = π/2, south = π); the report's
//     "astronomers' azimuth" (from south, westward) is Φ − π,
//   - every angle in radians.
#pragma once

#include <span>
#include <vector>

#include "core/common/plant.h"

namespace pvtwin {

struct SolarPositionInput {
  double time_s = 0.0;            // unix seconds UTC (fractional allowed)
  double latitude_rad = 0.0;      // φ, north positive
  double longitude_rad = 0.0;     // σ, east positive
  double elevation_m = 0.0;       // E, observer height above sea level
  double pressure_hpa = 1013.25;  // P, annual mean local pressure, for refraction
  double temperature_c = 12.0;    // T, annual mean local temperature, for refraction
  double delta_t_s = 69.0;        // ΔT = TT − UT1
};

struct SolarPosition {
  double zenith_rad = 0.0;             // θ, topocentric, refraction-corrected
  double azimuth_rad = 0.0;            // Φ, topocentric, from north clockwise, [0, 2π)
  double elevation_rad = 0.0;          // e = π/2 − θ, refraction-corrected
  double declination_rad = 0.0;        // δ', topocentric
  double hour_angle_rad = 0.0;         // H', topocentric local hour angle, (−π, π], west > 0
  double right_ascension_rad = 0.0;    // α', topocentric, [0, 2π)
  double earth_sun_distance_au = 0.0;  // R
};

// Every intermediate quantity of the SPA, in the order the report computes
// them (report section 3 numbering). Angles in radians except where the name
// says otherwise; exposed so that tests can compare each step with the
// report's worked example (its Table A4.1 / A5.1 listing).
struct SolarPositionTrace {
  double julian_day = 0.0;                      // JD, UT
  double julian_century = 0.0;                  // JC
  double julian_ephemeris_day = 0.0;            // JDE, TT
  double julian_ephemeris_century = 0.0;        // JCE
  double julian_ephemeris_millennium = 0.0;     // JME
  double heliocentric_longitude_rad = 0.0;      // L, [0, 2π)
  double heliocentric_latitude_rad = 0.0;       // B
  double earth_sun_distance_au = 0.0;           // R
  double geocentric_longitude_rad = 0.0;        // Θ = L + π
  double geocentric_latitude_rad = 0.0;         // β = −B
  double mean_elongation_moon_deg = 0.0;        // X0 (not reduced to [0, 360))
  double mean_anomaly_sun_deg = 0.0;            // X1
  double mean_anomaly_moon_deg = 0.0;           // X2
  double moon_argument_latitude_deg = 0.0;      // X3
  double moon_ascending_node_deg = 0.0;         // X4
  double nutation_longitude_rad = 0.0;          // Δψ
  double nutation_obliquity_rad = 0.0;          // Δε
  double mean_obliquity_arcsec = 0.0;           // ε0
  double true_obliquity_rad = 0.0;              // ε
  double aberration_rad = 0.0;                  // Δτ
  double apparent_sun_longitude_rad = 0.0;      // λ
  double mean_sidereal_time_rad = 0.0;          // ν0, Greenwich, [0, 2π)
  double apparent_sidereal_time_rad = 0.0;      // ν, Greenwich, [0, 2π)
  double geocentric_right_ascension_rad = 0.0;  // α, [0, 2π)
  double geocentric_declination_rad = 0.0;      // δ
  double geocentric_hour_angle_rad = 0.0;       // H, [0, 2π)
  double equatorial_parallax_rad = 0.0;         // ξ
  double parallax_right_ascension_rad = 0.0;    // Δα
  double elevation_no_refraction_rad = 0.0;     // e0, topocentric
  double refraction_rad = 0.0;                  // Δe
  SolarPosition position;                       // final result
};

// NREL SPA, Reda & Andreas 2008, all steps 3.1 … 3.15 (the incidence angle of
// step 3.16 is AngleOfIncidenceRad below). Refraction (eq. 42) is applied
// only while the geometric sun is above −(0.26667° + 0.5667°), i.e. while
// its upper limb can still appear above the horizon; below that the
// refraction term is 0. Cost: about 290 trigonometric calls.
SolarPositionTrace ComputeSolarPositionTrace(const SolarPositionInput& in);

// ComputeSolarPositionTrace(in).position.
SolarPosition ComputeSolarPosition(const SolarPositionInput& in);

// Solar position for many timestamps at one site. The site fields of `site`
// are used, its time_s is ignored. out is resized to times_s.size().
// The geocentric part of the SPA (heliocentric terms, nutation, obliquity,
// aberration: α, δ, R and the nutation in sidereal time) changes smoothly
// and is evaluated exactly once per UT day at 0 h and interpolated
// quadratically through the values at 0 h of the day before, the day and the
// day after (as the report does for rise/transit/set, its appendix A.2);
// sidereal time and the topocentric and refraction steps are exact for each
// timestamp. The interpolation error is below 1e-5°; a day's 1440 minute
// rows cost about as much as 3 full SPA evaluations plus 1440 cheap ones.
void ComputeSolarPositions(std::span<const double> times_s, const SolarPositionInput& site,
                           std::vector<SolarPosition>* out);
// The same into out[i] for times_s[i] (out.size() == times_s.size()).
void ComputeSolarPositions(std::span<const double> times_s, const SolarPositionInput& site,
                           std::span<SolarPosition> out);

// The plant's site with the standard-atmosphere pressure of its elevation,
// P = 1013.25 hPa · exp(−h / 8434.5 m) (scale height 8.4 km), for the
// refraction of the synthetic weather and the clear-sky grid.
SolarPositionInput SiteAtStandardPressure(const Plant& plant);

// Angle of incidence θ_inc between the sun direction and the normal of a
// plane tilted by β from horizontal whose normal points, in plan view, to
// azimuth γ (from north, clockwise):
//
//   cos θ_inc = cos θ_z · cos β + sin θ_z · sin β · cos(Φ − γ)
//
//   θ_z = zenith_rad, Φ = azimuth_rad (sun, from north clockwise),
//   β = tilt_rad (0 = horizontal, π/2 = vertical), γ = surface_azimuth_rad.
//
// NREL SPA eq. 47 (there with azimuths from south; the difference Φ − γ is
// the same). Returns θ_inc in [0, π]; > π/2 means the sun is behind the plane.
double AngleOfIncidenceRad(double zenith_rad, double azimuth_rad, double tilt_rad,
                           double surface_azimuth_rad);

}  // namespace pvtwin
