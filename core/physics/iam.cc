#include "core/physics/iam.h"

#include <algorithm>
#include <cmath>

#include "core/common/units.h"

namespace pvtwin {

double IamSoukaSafwat(double aoi_rad, double b0) {
  if (std::isnan(aoi_rad) || std::isnan(b0)) return std::nan("");
  const double theta_rad = std::abs(aoi_rad);
  constexpr double kSixtyRad = kPi / 3.0;
  constexpr double kNinetyRad = kPi / 2.0;
  double iam = 0.0;
  if (theta_rad < kSixtyRad) {
    iam = 1.0 - b0 * (1.0 / std::cos(theta_rad) - 1.0);
  } else if (theta_rad <= kNinetyRad) {
    iam = (1.0 - b0) * (1.0 - (theta_rad - kSixtyRad) / (kNinetyRad - kSixtyRad));
  }
  return std::clamp(iam, 0.0, 1.0);
}

namespace {

// τα(θ) · part, with a zero part contributing 0 whatever its angle (the beam
// angle of incidence is often NaN or undefined at night).
double Weighted(double part_w_m2, double theta_rad, double b0) {
  return part_w_m2 == 0.0 ? 0.0 : IamSoukaSafwat(theta_rad, b0) * part_w_m2;
}

}  // namespace

double AbsorbedIrradianceWM2(const PoaComponents& poa, double aoi_rad,
                             const EffectiveDiffuseAngles& diffuse_angles, double b0) {
  return Weighted(poa.beam_w_m2, aoi_rad, b0) +
         Weighted(poa.sky_diffuse_w_m2, diffuse_angles.sky_rad, b0) +
         Weighted(poa.ground_diffuse_w_m2, diffuse_angles.ground_rad, b0);
}

}  // namespace pvtwin
