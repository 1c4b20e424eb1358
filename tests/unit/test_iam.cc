#include <gtest/gtest.h>

#include <cmath>

#include "core/common/units.h"
#include "core/physics/iam.h"
#include "core/physics/irradiance.h"

namespace pvtwin {
namespace {

constexpr double kB0 = 0.05;  // paper Table 3

TEST(Iam, IsOneAtNormalIncidence) { EXPECT_DOUBLE_EQ(IamSoukaSafwat(0.0, kB0), 1.0); }

TEST(Iam, IsZeroAtAndBeyondNinetyDegrees) {
  EXPECT_NEAR(IamSoukaSafwat(DegToRad(90.0), kB0), 0.0, 1e-12);
  EXPECT_EQ(IamSoukaSafwat(DegToRad(90.5), kB0), 0.0);
  EXPECT_EQ(IamSoukaSafwat(DegToRad(150.0), kB0), 0.0);
}

// Both branches give 1 − b0 at 60°: 1 − b0·(1/cos 60° − 1) = 1 − b0·(2 − 1).
TEST(Iam, IsContinuousAtSixtyDegrees) {
  const double eps = 1e-9;
  const double below = IamSoukaSafwat(DegToRad(60.0) - eps, kB0);
  const double at = IamSoukaSafwat(DegToRad(60.0), kB0);
  EXPECT_NEAR(below, 1.0 - kB0, 1e-8);
  EXPECT_NEAR(at, 1.0 - kB0, 1e-12);
}

// Hand values: θ = 45°: 1 − 0.05·(√2 − 1) = 0.979289; θ = 75°: linear
// segment halfway, (1 − 0.05)·0.5 = 0.475.
TEST(Iam, MatchesHandComputedValues) {
  EXPECT_NEAR(IamSoukaSafwat(DegToRad(45.0), kB0), 0.9792893219, 1e-9);
  EXPECT_NEAR(IamSoukaSafwat(DegToRad(75.0), kB0), 0.475, 1e-12);
  EXPECT_NEAR(IamSoukaSafwat(DegToRad(-45.0), kB0), 0.9792893219, 1e-9);
}

TEST(Iam, IsMonotoneDecreasingAndWithinUnitInterval) {
  double previous = 1.0;
  for (double deg = 0.0; deg <= 100.0; deg += 0.25) {
    const double iam = IamSoukaSafwat(DegToRad(deg), 0.1);
    EXPECT_LE(iam, previous + 1e-15) << deg;
    EXPECT_GE(iam, 0.0);
    EXPECT_LE(iam, 1.0);
    previous = iam;
  }
  // A large b0 drives the first branch negative before 60°: clamped to 0.
  EXPECT_EQ(IamSoukaSafwat(DegToRad(59.0), 1.5), 0.0);
  EXPECT_TRUE(std::isnan(IamSoukaSafwat(std::nan(""), kB0)));
}

// Hand values (paper 2.5), tilt β = 45°, beam at θ = 30°, b0 = 0.05:
//   θ_eff,sky = 59.68 − 0.1388·45 + 0.001497·45² = 59.68 − 6.246 + 3.031425 = 56.465425°
//   θ_eff,gnd = 90 − 0.5788·45 + 0.002693·45² = 90 − 26.046 + 5.453325 = 69.407325°
//   beam:   K(30°) = 1 − 0.05·(2/√3 − 1) = 1 − 0.05·0.1547005384 = 0.9922649731
//           600·0.9922649731 = 595.3589838486
//   sky:    cos 56.465425° = 0.5524400912, 1/cos = 1.8101510299,
//           K = 1 − 0.05·0.8101510299 = 0.9594924485; 150·K = 143.9238672758
//   ground: linear segment, K = 0.95·(1 − 9.407325/30) = 0.95·0.6864225 = 0.652101375;
//           20·K = 13.0420275
//   I_at = 595.3589838486 + 143.9238672758 + 13.0420275 = 752.3248786244 W/m²
// Were the three parts weighted at one angle (the beam's, say) the sum would
// be 0.9922649731·770 = 764.04 W/m²: the test tells the two apart.
TEST(Iam, AbsorbedIrradianceWeightsEachPartAtItsOwnAngle) {
  const EffectiveDiffuseAngles angles = BrandemuehlBeckmanAngles(DegToRad(45.0));
  EXPECT_NEAR(angles.sky_rad, DegToRad(56.465425), 1e-12);
  EXPECT_NEAR(angles.ground_rad, DegToRad(69.407325), 1e-12);
  const double aoi_rad = DegToRad(30.0);
  // Each part alone, then all three.
  EXPECT_NEAR(AbsorbedIrradianceWM2({600.0, 0.0, 0.0}, aoi_rad, angles, kB0), 595.3589838486, 1e-9);
  EXPECT_NEAR(AbsorbedIrradianceWM2({0.0, 150.0, 0.0}, aoi_rad, angles, kB0), 143.9238672758, 1e-9);
  EXPECT_NEAR(AbsorbedIrradianceWM2({0.0, 0.0, 20.0}, aoi_rad, angles, kB0), 13.0420275, 1e-9);
  const PoaComponents poa{600.0, 150.0, 20.0};
  EXPECT_NEAR(AbsorbedIrradianceWM2(poa, aoi_rad, angles, kB0), 752.3248786244, 1e-9);
  // With b0 = 0 nothing is lost below 60°: beam and sky (56.5°) pass fully,
  // ground (69.4°) follows the linear segment: 1 − 9.407325/30 = 0.6864225,
  // 600 + 150 + 20·0.6864225 = 763.72845.
  EXPECT_NEAR(AbsorbedIrradianceWM2(poa, aoi_rad, angles, 0.0), 763.72845, 1e-9);
}

TEST(Iam, AbsorbedIrradianceIgnoresTheAngleOfAZeroBeam) {
  const PoaComponents poa{0.0, 80.0, 5.0};
  const EffectiveDiffuseAngles angles = BrandemuehlBeckmanAngles(DegToRad(20.0));
  const double value = AbsorbedIrradianceWM2(poa, std::nan(""), angles, kB0);
  EXPECT_TRUE(std::isfinite(value));
  EXPECT_GT(value, 0.0);
  EXPECT_LT(value, 85.0);
}

}  // namespace
}  // namespace pvtwin
