// Clear-sky irradiance: what the sun delivers through a cloudless
// atmosphere, the reference for a clear-sky index (synthetic weather, the
// sensor checks, the weather-forecast import's 1-min irradiance).
#pragma once

namespace pvtwin {

// Extraterrestrial normal irradiance I0 = 1366.1 · (1 + 0.033 · cos(2π·n/365))
// W/m², n = day of year (1 … 366). Spencer-type eccentricity correction,
// good to ~0.3 %.
double ExtraterrestrialNormalWM2(double day_of_year);

struct ClearSkyInput {
  double zenith_rad = 0.0;       // θ_z, refraction-corrected solar zenith
  double day_of_year = 172.0;    // n, for I0
  double elevation_m = 0.0;      // h, site altitude
  double linke_turbidity = 3.5;  // T_L (air mass 2), 2 = very clean … 6 = hazy
};

struct ClearSkyIrradiance {
  double ghi_w_m2 = 0.0;  // global horizontal
  double dni_w_m2 = 0.0;  // beam normal
  double dhi_w_m2 = 0.0;  // diffuse horizontal = GHI − DNI·cos θ_z (≥ 0)
};

// Clear-sky irradiance of Ineichen & Perez (2002), "A new airmass independent
// formulation for the Linke turbidity coefficient", Solar Energy 73(3):
//
//   AM  = 1 / (cos θ_z + 0.50572 · (96.07995 − θ_z[°])^−1.6364)  (Kasten & Young)
//   f1  = exp(−h/8000), f2 = exp(−h/1250)
//   c1  = 5.09e−5·h + 0.868, c2 = 3.92e−5·h + 0.0387
//   GHI = c1 · I0 · cos θ_z · exp(−c2 · AM · (f1 + f2·(T_L − 1)))
//   DNI = min((0.664 + 0.163/f1) · I0 · exp(−0.09 · AM · (T_L − 1)),
//             GHI · (1 − (0.1 − 0.2·exp(−T_L)) / (0.1 + 0.882/f1)) / cos θ_z)
//   DHI = GHI − DNI · cos θ_z
//
// without the paper's optional exp(0.01 · AM^1.8) factor on GHI, which
// diverges near the horizon. All zero for θ_z ≥ 90°.
ClearSkyIrradiance ClearSkyIneichenPerez(const ClearSkyInput& in);

// Day of year (1 = 1 January 00:00 UTC, fractional) from unix seconds, using
// the mean Gregorian year anchored at 2000-01-01 (unix day 10957); within
// one day of the calendar value, ample for I0.
double DayOfYearUtc(double time_s);

}  // namespace pvtwin
