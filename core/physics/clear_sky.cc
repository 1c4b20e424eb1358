#include "core/physics/clear_sky.h"

#include <algorithm>
#include <cmath>

#include "core/common/units.h"

namespace pvtwin {

namespace {
constexpr double kTwoPi = 2.0 * kPi;
}  // namespace

double DayOfYearUtc(double time_s) {
  constexpr double kMeanYearDays = 365.2425;
  const double days_since_2000 = time_s / 86400.0 - 10957.0;
  double doy = std::fmod(days_since_2000, kMeanYearDays);
  if (doy < 0.0) doy += kMeanYearDays;
  return doy + 1.0;
}

double ExtraterrestrialNormalWM2(double day_of_year) {
  return 1366.1 * (1.0 + 0.033 * std::cos(kTwoPi * day_of_year / 365.0));
}

ClearSkyIrradiance ClearSkyIneichenPerez(const ClearSkyInput& in) {
  const double cos_zenith = std::cos(in.zenith_rad);
  if (!(cos_zenith > 0.0)) return {};
  const double zenith_deg = RadToDeg(in.zenith_rad);
  const double air_mass = 1.0 / (cos_zenith + 0.50572 * std::pow(96.07995 - zenith_deg, -1.6364));
  const double h = in.elevation_m;
  const double fh1 = std::exp(-h / 8000.0);
  const double fh2 = std::exp(-h / 1250.0);
  const double cg1 = 5.09e-5 * h + 0.868;
  const double cg2 = 3.92e-5 * h + 0.0387;
  const double tl = in.linke_turbidity;
  const double i0_w_m2 = ExtraterrestrialNormalWM2(in.day_of_year);
  ClearSkyIrradiance out;
  out.ghi_w_m2 = cg1 * i0_w_m2 * cos_zenith * std::exp(-cg2 * air_mass * (fh1 + fh2 * (tl - 1.0)));
  const double dni_turbidity_w_m2 =
      (0.664 + 0.163 / fh1) * i0_w_m2 * std::exp(-0.09 * air_mass * (tl - 1.0));
  const double dni_ghi_bound_w_m2 =
      out.ghi_w_m2 * (1.0 - (0.1 - 0.2 * std::exp(-tl)) / (0.1 + 0.882 / fh1)) / cos_zenith;
  out.dni_w_m2 = std::max(0.0, std::min(dni_turbidity_w_m2, dni_ghi_bound_w_m2));
  out.dhi_w_m2 = std::max(0.0, out.ghi_w_m2 - out.dni_w_m2 * cos_zenith);
  return out;
}

}  // namespace pvtwin
