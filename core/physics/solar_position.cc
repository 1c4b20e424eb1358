#include "core/physics/solar_position.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>

#include "core/common/units.h"

namespace pvtwin {
namespace {

// ---------------------------------------------------------------------------
// Earth periodic terms (NREL SPA report, Table A4.2; a truncation of
// VSOP87). Each term contributes A · cos(B + C · JME), A in 1e-8 rad (1e-8 AU
// for R), B in rad, C in rad per Julian millennium.
struct PeriodicTerm {
  double a;
  double b;
  double c;
};

constexpr PeriodicTerm kL0[] = {
    {175347046.0, 0.0, 0.0},       {3341656.0, 4.6692568, 6283.07585},
    {34894.0, 4.6261, 12566.1517}, {3497.0, 2.7441, 5753.3849},
    {3418.0, 2.8289, 3.5231},      {3136.0, 3.6277, 77713.7715},
    {2676.0, 4.4181, 7860.4194},   {2343.0, 6.1352, 3930.2097},
    {1324.0, 0.7425, 11506.7698},  {1273.0, 2.0371, 529.691},
    {1199.0, 1.1096, 1577.3435},   {990.0, 5.233, 5884.927},
    {902.0, 2.045, 26.298},        {857.0, 3.508, 398.149},
    {780.0, 1.179, 5223.694},      {753.0, 2.533, 5507.553},
    {505.0, 4.583, 18849.228},     {492.0, 4.205, 775.523},
    {357.0, 2.92, 0.067},          {317.0, 5.849, 11790.629},
    {284.0, 1.899, 796.298},       {271.0, 0.315, 10977.079},
    {243.0, 0.345, 5486.778},      {206.0, 4.806, 2544.314},
    {205.0, 1.869, 5573.143},      {202.0, 2.458, 6069.777},
    {156.0, 0.833, 213.299},       {132.0, 3.411, 2942.463},
    {126.0, 1.083, 20.775},        {115.0, 0.645, 0.98},
    {103.0, 0.636, 4694.003},      {102.0, 0.976, 15720.839},
    {102.0, 4.267, 7.114},         {99.0, 6.21, 2146.17},
    {98.0, 0.68, 155.42},          {86.0, 5.98, 161000.69},
    {85.0, 1.3, 6275.96},          {85.0, 3.67, 71430.7},
    {80.0, 1.81, 17260.15},        {79.0, 3.04, 12036.46},
    {75.0, 1.76, 5088.63},         {74.0, 3.5, 3154.69},
    {74.0, 4.68, 801.82},          {70.0, 0.83, 9437.76},
    {62.0, 3.98, 8827.39},         {61.0, 1.82, 7084.9},
    {57.0, 2.78, 6286.6},          {56.0, 4.39, 14143.5},
    {56.0, 3.47, 6279.55},         {52.0, 0.19, 12139.55},
    {52.0, 1.33, 1748.02},         {51.0, 0.28, 5856.48},
    {49.0, 0.49, 1194.45},         {41.0, 5.37, 8429.24},
    {41.0, 2.4, 19651.05},         {39.0, 6.17, 10447.39},
    {37.0, 6.04, 10213.29},        {37.0, 2.57, 1059.38},
    {36.0, 1.71, 2352.87},         {36.0, 1.78, 6812.77},
    {33.0, 0.59, 17789.85},        {30.0, 0.44, 83996.85},
    {30.0, 2.74, 1349.87},         {25.0, 3.16, 4690.48},
};

constexpr PeriodicTerm kL1[] = {
    {628331966747.0, 0.0, 0.0},   {206059.0, 2.678235, 6283.07585},
    {4303.0, 2.6351, 12566.1517}, {425.0, 1.59, 3.523},
    {119.0, 5.796, 26.298},       {109.0, 2.966, 1577.344},
    {93.0, 2.59, 18849.23},       {72.0, 1.14, 529.69},
    {68.0, 1.87, 398.15},         {67.0, 4.41, 5507.55},
    {59.0, 2.89, 5223.69},        {56.0, 2.17, 155.42},
    {45.0, 0.4, 796.3},           {36.0, 0.47, 775.52},
    {29.0, 2.65, 7.11},           {21.0, 5.34, 0.98},
    {19.0, 1.85, 5486.78},        {19.0, 4.97, 213.3},
    {17.0, 2.99, 6275.96},        {16.0, 0.03, 2544.31},
    {16.0, 1.43, 2146.17},        {15.0, 1.21, 10977.08},
    {12.0, 2.83, 1748.02},        {12.0, 3.26, 5088.63},
    {12.0, 5.27, 1194.45},        {12.0, 2.08, 4694.0},
    {11.0, 0.77, 553.57},         {10.0, 1.3, 6286.6},
    {10.0, 4.24, 1349.87},        {9.0, 2.7, 242.73},
    {9.0, 5.64, 951.72},          {8.0, 5.3, 2352.87},
    {6.0, 2.65, 9437.76},         {6.0, 4.67, 4690.48},
};

constexpr PeriodicTerm kL2[] = {
    {52919.0, 0.0, 0.0},    {8720.0, 1.0721, 6283.0758}, {309.0, 0.867, 12566.152},
    {27.0, 0.05, 3.52},     {16.0, 5.19, 26.3},          {16.0, 3.68, 155.42},
    {10.0, 0.76, 18849.23}, {9.0, 2.06, 77713.77},       {7.0, 0.83, 775.52},
    {5.0, 4.66, 1577.34},   {4.0, 1.03, 7.11},           {4.0, 3.44, 5573.14},
    {3.0, 5.14, 796.3},     {3.0, 6.05, 5507.55},        {3.0, 1.19, 242.73},
    {3.0, 6.12, 529.69},    {3.0, 0.31, 398.15},         {3.0, 2.28, 553.57},
    {2.0, 4.38, 5223.69},   {2.0, 3.75, 0.98},
};

constexpr PeriodicTerm kL3[] = {
    {289.0, 5.844, 6283.076}, {35.0, 0.0, 0.0},     {17.0, 5.49, 12566.15}, {3.0, 5.2, 155.42},
    {1.0, 4.72, 3.52},        {1.0, 5.3, 18849.23}, {1.0, 5.97, 242.73},
};

constexpr PeriodicTerm kL4[] = {
    {114.0, 3.142, 0.0},
    {8.0, 4.13, 6283.08},
    {1.0, 3.84, 12566.15},
};

constexpr PeriodicTerm kL5[] = {
    {1.0, 3.14, 0.0},
};

constexpr PeriodicTerm kB0[] = {
    {280.0, 3.199, 84334.662}, {102.0, 5.422, 5507.553}, {80.0, 3.88, 5223.69},
    {44.0, 3.7, 2352.87},      {32.0, 4.0, 1577.34},
};

constexpr PeriodicTerm kB1[] = {
    {9.0, 3.9, 5507.55},
    {6.0, 1.73, 5223.69},
};

constexpr PeriodicTerm kR0[] = {
    {100013989.0, 0.0, 0.0},        {1670700.0, 3.0984635, 6283.07585},
    {13956.0, 3.05525, 12566.1517}, {3084.0, 5.1985, 77713.7715},
    {1628.0, 1.1739, 5753.3849},    {1576.0, 2.8469, 7860.4194},
    {925.0, 5.453, 11506.77},       {542.0, 4.564, 3930.21},
    {472.0, 3.661, 5884.927},       {346.0, 0.964, 5507.553},
    {329.0, 5.9, 5223.694},         {307.0, 0.299, 5573.143},
    {243.0, 4.273, 11790.629},      {212.0, 5.847, 1577.344},
    {186.0, 5.022, 10977.079},      {175.0, 3.012, 18849.228},
    {110.0, 5.055, 5486.778},       {98.0, 0.89, 6069.78},
    {86.0, 5.69, 15720.84},         {86.0, 1.27, 161000.69},
    {65.0, 0.27, 17260.15},         {63.0, 0.92, 529.69},
    {57.0, 2.01, 83996.85},         {56.0, 5.24, 71430.7},
    {49.0, 3.25, 2544.31},          {47.0, 2.58, 775.52},
    {45.0, 5.54, 9437.76},          {43.0, 6.01, 6275.96},
    {39.0, 5.36, 4694.0},           {38.0, 2.39, 8827.39},
    {37.0, 0.83, 19651.05},         {37.0, 4.9, 12139.55},
    {36.0, 1.67, 12036.46},         {35.0, 1.84, 2942.46},
    {33.0, 0.24, 7084.9},           {32.0, 0.18, 5088.63},
    {32.0, 1.78, 398.15},           {28.0, 1.21, 6286.6},
    {28.0, 1.9, 6279.55},           {26.0, 4.59, 10447.39},
};

constexpr PeriodicTerm kR1[] = {
    {103019.0, 1.10749, 6283.07585},
    {1721.0, 1.0644, 12566.1517},
    {702.0, 3.142, 0.0},
    {32.0, 1.02, 18849.23},
    {31.0, 2.84, 5507.55},
    {25.0, 1.32, 5223.69},
    {18.0, 1.42, 1577.34},
    {10.0, 5.91, 10977.08},
    {9.0, 1.42, 6275.96},
    {9.0, 0.27, 5486.78},
};

constexpr PeriodicTerm kR2[] = {
    {4359.0, 5.7846, 6283.0758}, {124.0, 5.579, 12566.152}, {12.0, 3.14, 0.0},
    {9.0, 3.63, 77713.77},       {6.0, 1.87, 5573.14},      {3.0, 5.47, 18849.23},
};

constexpr PeriodicTerm kR3[] = {
    {145.0, 4.273, 6283.076},
    {7.0, 3.92, 12566.15},
};

constexpr PeriodicTerm kR4[] = {
    {4.0, 2.56, 6283.08},
};

// ---------------------------------------------------------------------------
// Nutation in longitude and obliquity (NREL SPA report, Table A4.3).
// Argument Σ_j Y_j · X_j with X0 … X4 the fundamental arguments below;
// Δψ term (a + b·JCE) · sin(arg), Δε term (c + d·JCE) · cos(arg), both in
// units of 0.0001 arcsec.
struct NutationTerm {
  std::int8_t y0, y1, y2, y3, y4;
  double a, b, c, d;
};

constexpr NutationTerm kNutation[] = {
    {0, 0, 0, 0, 1, -171996.0, -174.2, 92025.0, 8.9},
    {-2, 0, 0, 2, 2, -13187.0, -1.6, 5736.0, -3.1},
    {0, 0, 0, 2, 2, -2274.0, -0.2, 977.0, -0.5},
    {0, 0, 0, 0, 2, 2062.0, 0.2, -895.0, 0.5},
    {0, 1, 0, 0, 0, 1426.0, -3.4, 54.0, -0.1},
    {0, 0, 1, 0, 0, 712.0, 0.1, -7.0, 0.0},
    {-2, 1, 0, 2, 2, -517.0, 1.2, 224.0, -0.6},
    {0, 0, 0, 2, 1, -386.0, -0.4, 200.0, 0.0},
    {0, 0, 1, 2, 2, -301.0, 0.0, 129.0, -0.1},
    {-2, -1, 0, 2, 2, 217.0, -0.5, -95.0, 0.3},
    {-2, 0, 1, 0, 0, -158.0, 0.0, 0.0, 0.0},
    {-2, 0, 0, 2, 1, 129.0, 0.1, -70.0, 0.0},
    {0, 0, -1, 2, 2, 123.0, 0.0, -53.0, 0.0},
    {2, 0, 0, 0, 0, 63.0, 0.0, 0.0, 0.0},
    {0, 0, 1, 0, 1, 63.0, 0.1, -33.0, 0.0},
    {2, 0, -1, 2, 2, -59.0, 0.0, 26.0, 0.0},
    {0, 0, -1, 0, 1, -58.0, -0.1, 32.0, 0.0},
    {0, 0, 1, 2, 1, -51.0, 0.0, 27.0, 0.0},
    {-2, 0, 2, 0, 0, 48.0, 0.0, 0.0, 0.0},
    {0, 0, -2, 2, 1, 46.0, 0.0, -24.0, 0.0},
    {2, 0, 0, 2, 2, -38.0, 0.0, 16.0, 0.0},
    {0, 0, 2, 2, 2, -31.0, 0.0, 13.0, 0.0},
    {0, 0, 2, 0, 0, 29.0, 0.0, 0.0, 0.0},
    {-2, 0, 1, 2, 2, 29.0, 0.0, -12.0, 0.0},
    {0, 0, 0, 2, 0, 26.0, 0.0, 0.0, 0.0},
    {-2, 0, 0, 2, 0, -22.0, 0.0, 0.0, 0.0},
    {0, 0, -1, 2, 1, 21.0, 0.0, -10.0, 0.0},
    {0, 2, 0, 0, 0, 17.0, -0.1, 0.0, 0.0},
    {2, 0, -1, 0, 1, 16.0, 0.0, -8.0, 0.0},
    {-2, 2, 0, 2, 2, -16.0, 0.1, 7.0, 0.0},
    {0, 1, 0, 0, 1, -15.0, 0.0, 9.0, 0.0},
    {-2, 0, 1, 0, 1, -13.0, 0.0, 7.0, 0.0},
    {0, -1, 0, 0, 1, -12.0, 0.0, 6.0, 0.0},
    {0, 0, 2, -2, 0, 11.0, 0.0, 0.0, 0.0},
    {2, 0, -1, 2, 1, -10.0, 0.0, 5.0, 0.0},
    {2, 0, 1, 2, 2, -8.0, 0.0, 3.0, 0.0},
    {0, 1, 0, 2, 2, 7.0, 0.0, -3.0, 0.0},
    {-2, 1, 1, 0, 0, -7.0, 0.0, 0.0, 0.0},
    {0, -1, 0, 2, 2, -7.0, 0.0, 3.0, 0.0},
    {2, 0, 0, 2, 1, -7.0, 0.0, 3.0, 0.0},
    {2, 0, 1, 0, 0, 6.0, 0.0, 0.0, 0.0},
    {-2, 0, 2, 2, 2, 6.0, 0.0, -3.0, 0.0},
    {-2, 0, 1, 2, 1, 6.0, 0.0, -3.0, 0.0},
    {2, 0, -2, 0, 1, -6.0, 0.0, 3.0, 0.0},
    {2, 0, 0, 0, 1, -6.0, 0.0, 3.0, 0.0},
    {0, -1, 1, 0, 0, 5.0, 0.0, 0.0, 0.0},
    {-2, -1, 0, 2, 1, -5.0, 0.0, 3.0, 0.0},
    {-2, 0, 0, 0, 1, -5.0, 0.0, 3.0, 0.0},
    {0, 0, 2, 2, 1, -5.0, 0.0, 3.0, 0.0},
    {-2, 0, 2, 0, 1, 4.0, 0.0, 0.0, 0.0},
    {-2, 1, 0, 2, 1, 4.0, 0.0, 0.0, 0.0},
    {0, 0, 1, -2, 0, 4.0, 0.0, 0.0, 0.0},
    {-1, 0, 1, 0, 0, -4.0, 0.0, 0.0, 0.0},
    {-2, 1, 0, 0, 0, -4.0, 0.0, 0.0, 0.0},
    {1, 0, 0, 0, 0, -4.0, 0.0, 0.0, 0.0},
    {0, 0, 1, 2, 0, 3.0, 0.0, 0.0, 0.0},
    {0, 0, -2, 2, 2, -3.0, 0.0, 0.0, 0.0},
    {-1, -1, 1, 0, 0, -3.0, 0.0, 0.0, 0.0},
    {0, 1, 1, 0, 0, -3.0, 0.0, 0.0, 0.0},
    {0, -1, 1, 2, 2, -3.0, 0.0, 0.0, 0.0},
    {2, -1, -1, 2, 2, -3.0, 0.0, 0.0, 0.0},
    {0, 0, 3, 2, 2, -3.0, 0.0, 0.0, 0.0},
    {2, -1, 0, 2, 2, -3.0, 0.0, 0.0, 0.0},
};

static_assert(std::size(kL0) == 64 && std::size(kL1) == 34 && std::size(kL2) == 20 &&
              std::size(kL3) == 7 && std::size(kL4) == 3 && std::size(kL5) == 1);
static_assert(std::size(kB0) == 5 && std::size(kB1) == 2);
static_assert(std::size(kR0) == 40 && std::size(kR1) == 10 && std::size(kR2) == 6 &&
              std::size(kR3) == 2 && std::size(kR4) == 1);
static_assert(std::size(kNutation) == 63);

constexpr double kSecondsPerDay = 86400.0;
constexpr double kUnixEpochJulianDay = 2440587.5;  // 1970-01-01 00:00 UTC
constexpr double kJ2000JulianDay = 2451545.0;      // 2000-01-01 12:00
constexpr double kJ2000UnixS = (kJ2000JulianDay - kUnixEpochJulianDay) * kSecondsPerDay;
constexpr double kDaysPerJulianCentury = 36525.0;
constexpr double kArcsecPerDeg = 3600.0;
// Refraction is applied while e0 ≥ −(sun's apparent radius + refraction at
// the horizon), SPA report section 3.14 and its reference code.
constexpr double kSunRadiusDeg = 0.26667;
constexpr double kHorizonRefractionDeg = 0.5667;

// Σ A · cos(B + C · jme) over one table.
template <std::size_t N>
double SumTerms(const PeriodicTerm (&terms)[N], double jme) {
  double sum = 0.0;
  for (const PeriodicTerm& t : terms) sum += t.a * std::cos(t.b + t.c * jme);
  return sum;
}

// Reduces an angle in degrees to [0, 360).
double WrapDeg360(double deg) {
  double r = std::fmod(deg, 360.0);
  if (r < 0.0) r += 360.0;
  return r;
}

// Reduces an angle in radians to [0, 2π).
double WrapRad2Pi(double rad) {
  double r = std::fmod(rad, 2.0 * kPi);
  if (r < 0.0) r += 2.0 * kPi;
  return r;
}

// Reduces an angle in radians to (−π, π].
double WrapRadPi(double rad) {
  double r = WrapRad2Pi(rad);
  if (r > kPi) r -= 2.0 * kPi;
  return r;
}

// Greenwich mean sidereal time ν0 in degrees, [0, 360), report eq. 12, with
// JD − 2451545 formed from unix time directly for precision.
double MeanSiderealTimeDeg(double time_s) {
  const double days_since_j2000 = (time_s - kJ2000UnixS) / kSecondsPerDay;
  const double jc = days_since_j2000 / kDaysPerJulianCentury;
  return WrapDeg360(280.46061837 + 360.98564736629 * days_since_j2000 + 0.000387933 * jc * jc -
                    jc * jc * jc / 38710000.0);
}

// Steps 3.1 … 3.9 of the report, the part that does not depend on the
// observer: Julian dates, Earth heliocentric position, nutation, obliquity,
// aberration, apparent sun longitude, apparent sidereal time, geocentric
// right ascension and declination. Fills the matching fields of *t.
void ComputeGeocentric(double time_s, double delta_t_s, SolarPositionTrace* t) {
  // 3.1 Julian dates (eqs. 4–8).
  const double days_since_j2000 = (time_s - kJ2000UnixS) / kSecondsPerDay;
  t->julian_day = kJ2000JulianDay + days_since_j2000;
  t->julian_century = days_since_j2000 / kDaysPerJulianCentury;
  const double ephemeris_days_since_j2000 = days_since_j2000 + delta_t_s / kSecondsPerDay;
  t->julian_ephemeris_day = kJ2000JulianDay + ephemeris_days_since_j2000;
  const double jce = ephemeris_days_since_j2000 / kDaysPerJulianCentury;
  const double jme = jce / 10.0;
  t->julian_ephemeris_century = jce;
  t->julian_ephemeris_millennium = jme;

  // 3.2 Earth heliocentric longitude L, latitude B, radius vector R
  // (eqs. 9–12): a polynomial in JME whose coefficients are the series sums.
  const double l_series[] = {SumTerms(kL0, jme), SumTerms(kL1, jme), SumTerms(kL2, jme),
                             SumTerms(kL3, jme), SumTerms(kL4, jme), SumTerms(kL5, jme)};
  double l_1e8_rad = 0.0;
  for (int i = 5; i >= 0; --i) l_1e8_rad = l_1e8_rad * jme + l_series[i];
  const double helio_longitude_rad = WrapRad2Pi(l_1e8_rad * 1e-8);
  const double helio_latitude_rad = (SumTerms(kB0, jme) + SumTerms(kB1, jme) * jme) * 1e-8;
  const double r_series[] = {SumTerms(kR0, jme), SumTerms(kR1, jme), SumTerms(kR2, jme),
                             SumTerms(kR3, jme), SumTerms(kR4, jme)};
  double r_1e8_au = 0.0;
  for (int i = 4; i >= 0; --i) r_1e8_au = r_1e8_au * jme + r_series[i];
  const double earth_sun_distance_au = r_1e8_au * 1e-8;
  t->heliocentric_longitude_rad = helio_longitude_rad;
  t->heliocentric_latitude_rad = helio_latitude_rad;
  t->earth_sun_distance_au = earth_sun_distance_au;

  // 3.3 Geocentric longitude Θ and latitude β (eqs. 13–14).
  const double geo_longitude_rad = WrapRad2Pi(helio_longitude_rad + kPi);
  const double geo_latitude_rad = -helio_latitude_rad;
  t->geocentric_longitude_rad = geo_longitude_rad;
  t->geocentric_latitude_rad = geo_latitude_rad;

  // 3.4 Nutation (eqs. 15–23). Fundamental arguments in degrees:
  // X0 mean elongation of the moon from the sun, X1 mean anomaly of the sun,
  // X2 mean anomaly of the moon, X3 moon's argument of latitude, X4 longitude
  // of the ascending node of the moon's mean orbit.
  const double jce2 = jce * jce;
  const double jce3 = jce2 * jce;
  const double x[5] = {
      297.85036 + 445267.111480 * jce - 0.0019142 * jce2 + jce3 / 189474.0,
      357.52772 + 35999.050340 * jce - 0.0001603 * jce2 - jce3 / 300000.0,
      134.96298 + 477198.867398 * jce + 0.0086972 * jce2 + jce3 / 56250.0,
      93.27191 + 483202.017538 * jce - 0.0036825 * jce2 + jce3 / 327270.0,
      125.04452 - 1934.136261 * jce + 0.0020708 * jce2 + jce3 / 450000.0,
  };
  t->mean_elongation_moon_deg = x[0];
  t->mean_anomaly_sun_deg = x[1];
  t->mean_anomaly_moon_deg = x[2];
  t->moon_argument_latitude_deg = x[3];
  t->moon_ascending_node_deg = x[4];
  double x_rad[5];
  for (int j = 0; j < 5; ++j) x_rad[j] = DegToRad(WrapDeg360(x[j]));
  double dpsi_1e4_arcsec = 0.0;
  double deps_1e4_arcsec = 0.0;
  for (const NutationTerm& n : kNutation) {
    const double arg_rad =
        n.y0 * x_rad[0] + n.y1 * x_rad[1] + n.y2 * x_rad[2] + n.y3 * x_rad[3] + n.y4 * x_rad[4];
    dpsi_1e4_arcsec += (n.a + n.b * jce) * std::sin(arg_rad);
    deps_1e4_arcsec += (n.c + n.d * jce) * std::cos(arg_rad);
  }
  const double nutation_longitude_rad = DegToRad(dpsi_1e4_arcsec / 36000000.0);
  const double nutation_obliquity_rad = DegToRad(deps_1e4_arcsec / 36000000.0);
  t->nutation_longitude_rad = nutation_longitude_rad;
  t->nutation_obliquity_rad = nutation_obliquity_rad;

  // 3.5 True obliquity of the ecliptic ε (eqs. 24–25), U = JME / 10.
  const double u = jme / 10.0;
  constexpr double kObliquityCoeffArcsec[] = {84381.448, -4680.93, -1.55, 1999.25, -51.38, -249.67,
                                              -39.05,    7.12,     27.87, 5.79,    2.45};
  double mean_obliquity_arcsec = 0.0;
  for (int i = 10; i >= 0; --i) {
    mean_obliquity_arcsec = mean_obliquity_arcsec * u + kObliquityCoeffArcsec[i];
  }
  const double true_obliquity_rad =
      DegToRad(mean_obliquity_arcsec / kArcsecPerDeg) + nutation_obliquity_rad;
  t->mean_obliquity_arcsec = mean_obliquity_arcsec;
  t->true_obliquity_rad = true_obliquity_rad;

  // 3.6 Aberration correction Δτ (eq. 26).
  const double aberration_rad = DegToRad(-20.4898 / (kArcsecPerDeg * earth_sun_distance_au));
  t->aberration_rad = aberration_rad;

  // 3.7 Apparent sun longitude λ (eq. 27).
  const double apparent_longitude_rad =
      WrapRad2Pi(geo_longitude_rad + nutation_longitude_rad + aberration_rad);
  t->apparent_sun_longitude_rad = apparent_longitude_rad;

  // 3.8 Apparent sidereal time at Greenwich ν (eqs. 28–29).
  const double mean_sidereal_rad = DegToRad(MeanSiderealTimeDeg(time_s));
  t->mean_sidereal_time_rad = mean_sidereal_rad;
  t->apparent_sidereal_time_rad =
      WrapRad2Pi(mean_sidereal_rad + nutation_longitude_rad * std::cos(true_obliquity_rad));

  // 3.9 Geocentric right ascension α and declination δ (eqs. 30–31).
  const double sin_lambda = std::sin(apparent_longitude_rad);
  const double sin_eps = std::sin(true_obliquity_rad);
  const double cos_eps = std::cos(true_obliquity_rad);
  t->geocentric_right_ascension_rad =
      WrapRad2Pi(std::atan2(sin_lambda * cos_eps - std::tan(geo_latitude_rad) * sin_eps,
                            std::cos(apparent_longitude_rad)));
  t->geocentric_declination_rad = std::asin(std::sin(geo_latitude_rad) * cos_eps +
                                            std::cos(geo_latitude_rad) * sin_eps * sin_lambda);
}

// The observer's terms of steps 3.11 and 3.14 that depend on the site alone
// (eqs. 34–37 and sin φ, cos φ): computed once for a run of positions.
struct SiteTerms {
  double x = 0.0, y = 0.0;  // observer's geocentric position terms (eqs. 36, 37)
  double sin_lat = 0.0, cos_lat = 0.0;
};

SiteTerms ComputeSiteTerms(const SolarPositionInput& site) {
  // Ellipsoid with flattening ratio 0.99664719 and equatorial radius 6378140 m.
  constexpr double kPolarToEquatorialRatio = 0.99664719;
  constexpr double kEquatorialRadiusM = 6378140.0;
  const double lat_rad = site.latitude_rad;
  const double u_rad = std::atan(kPolarToEquatorialRatio * std::tan(lat_rad));  // eq. 35
  const double height_ratio = site.elevation_m / kEquatorialRadiusM;
  SiteTerms s;
  s.sin_lat = std::sin(lat_rad);
  s.cos_lat = std::cos(lat_rad);
  s.x = std::cos(u_rad) + height_ratio * s.cos_lat;
  s.y = kPolarToEquatorialRatio * std::sin(u_rad) + height_ratio * s.sin_lat;
  return s;
}

// Steps 3.10 … 3.15 of the report, the observer-dependent part: local hour
// angle, parallax, topocentric coordinates, refraction, zenith and azimuth.
// Reads α, δ, ν and R from *t and fills the rest; `terms` are the site's
// (ComputeSiteTerms(site)).
void ComputeTopocentric(const SolarPositionInput& site, const SiteTerms& terms,
                        SolarPositionTrace* t) {
  const double alpha_rad = t->geocentric_right_ascension_rad;
  const double delta_rad = t->geocentric_declination_rad;

  // 3.10 Observer local hour angle H (eq. 32).
  const double hour_angle_rad =
      WrapRad2Pi(t->apparent_sidereal_time_rad + site.longitude_rad - alpha_rad);
  t->geocentric_hour_angle_rad = hour_angle_rad;

  // 3.11 Topocentric right ascension α' (eqs. 33–38): equatorial horizontal
  // parallax ξ and the site's x, y.
  const double parallax_rad = DegToRad(8.794 / (kArcsecPerDeg * t->earth_sun_distance_au));
  t->equatorial_parallax_rad = parallax_rad;
  const double x = terms.x;
  const double y = terms.y;
  const double sin_xi = std::sin(parallax_rad);
  const double cos_delta = std::cos(delta_rad);
  const double denom = cos_delta - x * sin_xi * std::cos(hour_angle_rad);
  const double parallax_ra_rad = std::atan2(-x * sin_xi * std::sin(hour_angle_rad), denom);
  t->parallax_right_ascension_rad = parallax_ra_rad;
  const double topo_ra_rad = WrapRad2Pi(alpha_rad + parallax_ra_rad);

  // 3.12 Topocentric declination δ' (eq. 39).
  const double topo_decl_rad =
      std::atan2((std::sin(delta_rad) - y * sin_xi) * std::cos(parallax_ra_rad), denom);

  // 3.13 Topocentric local hour angle H' (eq. 40).
  const double topo_hour_angle_rad = hour_angle_rad - parallax_ra_rad;

  // 3.14 Topocentric elevation e0 without refraction (eq. 41), refraction
  // correction Δe (eq. 42, P in hPa = mbar, T in °C, e0 in degrees inside the
  // tangent), refracted elevation e (eq. 43) and zenith θ (eq. 44).
  const double sin_lat = terms.sin_lat;
  const double cos_lat = terms.cos_lat;
  const double cos_topo_ha = std::cos(topo_hour_angle_rad);
  const double elevation0_rad = std::asin(sin_lat * std::sin(topo_decl_rad) +
                                          cos_lat * std::cos(topo_decl_rad) * cos_topo_ha);
  t->elevation_no_refraction_rad = elevation0_rad;
  const double elevation0_deg = RadToDeg(elevation0_rad);
  double refraction_deg = 0.0;
  if (elevation0_deg >= -(kSunRadiusDeg + kHorizonRefractionDeg)) {
    refraction_deg = (site.pressure_hpa / 1010.0) * (283.0 / (273.0 + site.temperature_c)) * 1.02 /
                     (60.0 * std::tan(DegToRad(elevation0_deg + 10.3 / (elevation0_deg + 5.11))));
  }
  const double refraction_rad = DegToRad(refraction_deg);
  t->refraction_rad = refraction_rad;
  const double elevation_rad = elevation0_rad + refraction_rad;

  // 3.15 Topocentric azimuth: astronomers' azimuth Γ from south, westward
  // (eq. 45), then Φ = Γ + π from north, clockwise (eq. 46).
  const double astronomers_azimuth_rad = std::atan2(
      std::sin(topo_hour_angle_rad), cos_topo_ha * sin_lat - std::tan(topo_decl_rad) * cos_lat);

  SolarPosition& p = t->position;
  p.zenith_rad = kPi / 2.0 - elevation_rad;
  p.azimuth_rad = WrapRad2Pi(astronomers_azimuth_rad + kPi);
  p.elevation_rad = elevation_rad;
  p.declination_rad = topo_decl_rad;
  p.hour_angle_rad = WrapRadPi(topo_hour_angle_rad);
  p.right_ascension_rad = topo_ra_rad;
  p.earth_sun_distance_au = t->earth_sun_distance_au;
}

// Observer-independent values at 0 h UT of one day, for interpolation.
struct DailyKnot {
  double right_ascension_rad;
  double declination_rad;
  double earth_sun_distance_au;
  double sidereal_nutation_rad;  // Δψ · cos ε, the apparent − mean sidereal time
};

DailyKnot KnotAt(double time_s, double delta_t_s) {
  SolarPositionTrace t;
  ComputeGeocentric(time_s, delta_t_s, &t);
  return {t.geocentric_right_ascension_rad, t.geocentric_declination_rad, t.earth_sun_distance_au,
          t.nutation_longitude_rad * std::cos(t.true_obliquity_rad)};
}

// Quadratic through (−1, f_m), (0, f_0), (1, f_p), evaluated at n.
double Quadratic(double f_m, double f_0, double f_p, double n) {
  return f_0 + 0.5 * n * (f_p - f_m) + 0.5 * n * n * (f_p - 2.0 * f_0 + f_m);
}

}  // namespace

SolarPositionTrace ComputeSolarPositionTrace(const SolarPositionInput& in) {
  SolarPositionTrace t;
  ComputeGeocentric(in.time_s, in.delta_t_s, &t);
  ComputeTopocentric(in, ComputeSiteTerms(in), &t);
  return t;
}

SolarPosition ComputeSolarPosition(const SolarPositionInput& in) {
  return ComputeSolarPositionTrace(in).position;
}

void ComputeSolarPositions(std::span<const double> times_s, const SolarPositionInput& site,
                           std::vector<SolarPosition>* out) {
  out->resize(times_s.size());
  ComputeSolarPositions(times_s, site, std::span<SolarPosition>(*out));
}

void ComputeSolarPositions(std::span<const double> times_s, const SolarPositionInput& site,
                           std::span<SolarPosition> out) {
  assert(out.size() == times_s.size());
  const SiteTerms terms = ComputeSiteTerms(site);
  SolarPositionInput at = site;
  double cached_day = std::nan("");
  DailyKnot knots[3] = {};  // 0 h UT of the day before, the day, the day after
  for (std::size_t i = 0; i < times_s.size(); ++i) {
    const double time_s = times_s[i];
    if (!std::isfinite(time_s)) {
      const double nan = std::nan("");
      out[i] = {nan, nan, nan, nan, nan, nan, nan};
      continue;
    }
    const double day = std::floor(time_s / kSecondsPerDay);
    if (day != cached_day) {
      for (int k = 0; k < 3; ++k) {
        knots[k] = KnotAt((day + k - 1) * kSecondsPerDay, site.delta_t_s);
      }
      // Unwrap α across the 0/2π cut so that the quadratic sees a smooth curve.
      for (int k : {0, 2}) {
        const double d = knots[k].right_ascension_rad - knots[1].right_ascension_rad;
        if (d > kPi) knots[k].right_ascension_rad -= 2.0 * kPi;
        if (d < -kPi) knots[k].right_ascension_rad += 2.0 * kPi;
      }
      cached_day = day;
    }
    const double n = time_s / kSecondsPerDay - day;  // fraction of the UT day, [0, 1)
    SolarPositionTrace t;
    t.geocentric_right_ascension_rad =
        WrapRad2Pi(Quadratic(knots[0].right_ascension_rad, knots[1].right_ascension_rad,
                             knots[2].right_ascension_rad, n));
    t.geocentric_declination_rad =
        Quadratic(knots[0].declination_rad, knots[1].declination_rad, knots[2].declination_rad, n);
    t.earth_sun_distance_au =
        Quadratic(knots[0].earth_sun_distance_au, knots[1].earth_sun_distance_au,
                  knots[2].earth_sun_distance_au, n);
    const double nutation_rad =
        Quadratic(knots[0].sidereal_nutation_rad, knots[1].sidereal_nutation_rad,
                  knots[2].sidereal_nutation_rad, n);
    t.apparent_sidereal_time_rad = WrapRad2Pi(DegToRad(MeanSiderealTimeDeg(time_s)) + nutation_rad);
    at.time_s = time_s;
    ComputeTopocentric(at, terms, &t);
    out[i] = t.position;
  }
}

double AngleOfIncidenceRad(double zenith_rad, double azimuth_rad, double tilt_rad,
                           double surface_azimuth_rad) {
  const double cos_aoi =
      std::cos(zenith_rad) * std::cos(tilt_rad) +
      std::sin(zenith_rad) * std::sin(tilt_rad) * std::cos(azimuth_rad - surface_azimuth_rad);
  return std::acos(std::clamp(cos_aoi, -1.0, 1.0));
}

SolarPositionInput SiteAtStandardPressure(const Plant& plant) {
  SolarPositionInput site;
  site.latitude_rad = plant.latitude_rad;
  site.longitude_rad = plant.longitude_rad;
  site.elevation_m = plant.elevation_m;
  site.pressure_hpa = 1013.25 * std::exp(-plant.elevation_m / 8434.5);
  return site;
}

}  // namespace pvtwin
