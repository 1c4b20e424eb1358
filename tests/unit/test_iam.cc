#include <gtest/gtest.h>

#include <cmath>

#include "core/iam.h"
#include "core/irradiance.h"
#include "core/units.h"

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

TEST(Iam, AbsorbedIrradianceWeightsEachPartAtItsOwnAngle) {
  const PoaComponents poa{600.0, 150.0, 20.0};
  const EffectiveDiffuseAngles angles = BrandemuehlBeckmanAngles(DegToRad(45.0));
  const double aoi_rad = DegToRad(30.0);
  const double expected = IamSoukaSafwat(aoi_rad, kB0) * 600.0 +
                          IamSoukaSafwat(angles.sky_rad, kB0) * 150.0 +
                          IamSoukaSafwat(angles.ground_rad, kB0) * 20.0;
  EXPECT_DOUBLE_EQ(AbsorbedIrradianceWM2(poa, aoi_rad, angles, kB0), expected);
  // With b0 = 0 nothing is lost below 60°: beam and sky (56.5°) pass fully,
  // ground (69.4°) follows the linear segment: 1 − 9.407/30 = 0.68642.
  EXPECT_NEAR(AbsorbedIrradianceWM2(poa, aoi_rad, angles, 0.0),
              600.0 + 150.0 + 20.0 * (1.0 - (69.407325 - 60.0) / 30.0), 1e-9);
  EXPECT_LT(AbsorbedIrradianceWM2(poa, aoi_rad, angles, kB0), poa.global_w_m2());
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
