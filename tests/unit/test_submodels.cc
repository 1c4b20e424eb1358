// The small physical sub-models of the thermal model against values worked
// out by hand from the equations in their headers (the arithmetic is in the
// comments): sky radiation (core/physics/sky_radiation.h), PV efficiency
// (core/physics/pv_efficiency.h), fluid coupling (core/physics/fluid_coupling.h) and both
// wind forms (core/physics/wind.h). Every expected number is a literal, never a call
// of the function under test, so a changed formula fails here.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/physics/fluid_coupling.h"
#include "core/physics/pv_efficiency.h"
#include "core/physics/sky_radiation.h"
#include "core/physics/wind.h"

namespace pvtwin {
namespace {

// Relative tolerance of the hand values: they carry 12+ significant digits.
constexpr double kRel = 1e-9;

void ExpectRel(double actual, double expected, const char* what) {
  EXPECT_NEAR(actual, expected, kRel * std::fabs(expected)) << what;
}

// σ = 5.670374419e-8 W/(m²K⁴) (CODATA 2018, core/common/units.h).
// A sky at 280 K sends L↓ = σ·280⁴ = 5.670374419e-8 · 6 146 560 000
//   = 348.5329658885 W/m²; the inverse must give back 280 K.
TEST(SkyRadiation, SkyTemperatureFromLongWaveIrradiance) {
  ExpectRel(SkyTemperatureK(348.5329658885), 280.0, "T_sky of 348.53 W/m2");
  // 0 W/m² is absolute zero (the domain's edge).
  EXPECT_EQ(SkyTemperatureK(0.0), 0.0);
}

// ε = 0.9, T_PV = 320 K, T_sky = 270 K:
//   T_PV⁴ = 10 485 760 000, T_sky⁴ = 5 314 410 000, difference 5 171 350 000
//   q_rad = 0.9 · 5.670374419e-8 · 5 171 350 000 = 263.9114167653 W/m²
//   dq/dT = 4 · 0.9 · 5.670374419e-8 · 320³ (= 32 768 000) = 6.689045842625 W/m²K
//   U_rad = 0.9 · σ · (320 + 270) · (320² + 270²) = 0.9 · σ · 590 · 175 300
//         = 5.278228335305 W/m²K, and U_rad · (320 − 270) = q_rad (the paper's
//   eq. 2.6 is the exact factorisation a⁴ − b⁴ = (a + b)(a² + b²)(a − b)).
TEST(SkyRadiation, LossDerivativeAndEquivalentCoefficientByHand) {
  const SkyRadiationLoss loss = SkyRadiation(0.9, 320.0, 270.0 * 270.0 * 270.0 * 270.0);
  ExpectRel(loss.q_w_m2, 263.9114167653, "q_rad");
  ExpectRel(loss.dq_dt_w_m2k, 6.689045842625, "dq_rad/dT");
  ExpectRel(URadWM2K(0.9, 320.0, 270.0), 5.278228335305, "U_rad");
  ExpectRel(URadWM2K(0.9, 320.0, 270.0) * 50.0, 263.9114167653, "U_rad·ΔT");
  // A collector colder than the sky gains: the same numbers, sign reversed.
  EXPECT_NEAR(SkyRadiation(0.9, 270.0, 320.0 * 320.0 * 320.0 * 320.0).q_w_m2, -263.9114167653,
              kRel * 263.9114167653);
}

// Paper Table 3 values: η_ref = 0.15, f_corr_T = −0.004 1/K, f_corr_I =
// 3.6e-5 m²/W, T_ref = 25 °C, I_ref = 1000 W/m². At I_gt = 800 W/m² and
// T_PV = 45 °C:
//   irradiance factor 1 + 3.6e-5 · (800 − 1000) = 1 − 0.0072 = 0.9928
//   temperature factor 1 − 0.004 · (45 − 25) = 0.92
//   η_PV = 0.15 · 0.92 · 0.9928 = 0.1370064
//   η at T_ref: 0.15 · 0.9928 = 0.14892, slope 0.14892 · (−0.004) = −5.9568e-4 1/K
TEST(PvEfficiency, PaperEquationByHand) {
  const PvEfficiencyParams p{0.15, -0.004, 3.6e-5, 25.0, 1000.0};
  const PvEfficiencyLinear eta = PvEfficiencyAt(p, 800.0);
  ExpectRel(eta.eta_at_ref_temp, 0.14892, "η at T_ref");
  ExpectRel(eta.slope_per_k, -5.9568e-4, "dη/dT");
  ExpectRel(eta.At(45.0), 0.1370064, "η(45 °C, 800 W/m²)");
  ExpectRel(eta.SlopeAt(45.0), -5.9568e-4, "slope at 45 °C");
  // At I_ref and T_ref both factors are 1.
  ExpectRel(PvEfficiencyAt(p, 1000.0).At(25.0), 0.15, "η at STC");
  // The linear form reaches 0 at T = 25 + 1/0.004 = 275 °C; beyond it is
  // clamped at 0 and has no slope.
  EXPECT_EQ(eta.At(300.0), 0.0);
  EXPECT_EQ(eta.SlopeAt(300.0), 0.0);
}

// ṁ = 0.03 kg/s, c_p = 3650 J/(kgK), A = 1.8 m², r0 = 0.1 m²K/W, r1 = 1:
//   ṁ·c_p = 109.5 W/K, w = 109.5/1.8 W/(m²K), r1/(2w) = 1.8/219 m²K/W
//   1/U = 1.8/219 + 21.9/219 = 23.7/219 → U_fluid = 219/23.7 = 9.240506329114 W/(m²K)
//   field: U·A = 394.2/23.7 = 16.63291139241 W/K; GFluidWK's own form
//   2·109.5/(1 + 219·0.1/1.8) = 219/13.1666… gives the same.
TEST(FluidCoupling, KoschenzLehmannByHand) {
  ExpectRel(UFluidWM2K(0.03, 3650.0, 1.8, 0.1, 1.0), 9.240506329114, "U_fluid");
  ExpectRel(GFluidWK(109.5, 0.1 / 1.8, 1.0), 16.63291139241, "U_fluid·A");
  // No flow, no heat extracted (the paper's boolean ṁ > 0).
  EXPECT_EQ(UFluidWM2K(0.0, 3650.0, 1.8, 0.1, 1.0), 0.0);
  EXPECT_EQ(GFluidWK(0.0, 0.1 / 1.8, 1.0), 0.0);
  // r0 → 0: U = 2w/r1 = 2·109.5/1.8 = 121.6666666667 W/(m²K).
  ExpectRel(UFluidWM2K(0.03, 3650.0, 1.8, 0.0, 1.0), 121.6666666667, "U_fluid, r0 = 0");
}

// U_front = 10 W/(m²K), v = 4 m/s.
//  n = 0.5: v^n = 2.
//   paper 'w': 1/(1/10 + 0.02·2) = 1/0.14 = 7.142857142857 W/(m²K)
//   "+wind":   10 + 3·2 = 16 W/(m²K)
//  n = 0.8: v^n = 4^0.8 = 2^1.6 = 3.031433133021.
//   paper 'w': 1/(0.1 + 0.02·3.031433133021) = 1/0.1606286627 = 6.225538975657
//   "+wind":   10 + 3·3.031433133021 = 19.09429939906
TEST(Wind, PaperAndConvectiveFormsByHand) {
  const double ln_v = std::log(4.0);
  ExpectRel(WindPower(ln_v, 0.5), 2.0, "4^0.5");
  ExpectRel(WindPower(ln_v, 0.8), 3.031433133021, "4^0.8");
  ExpectRel(FrontConductancePaperWM2K(0.1, 0.02, 2.0), 7.142857142857, "paper, n = 0.5");
  ExpectRel(FrontConductanceConvectiveWM2K(10.0, 3.0, 2.0), 16.0, "+wind, n = 0.5");
  ExpectRel(FrontConductancePaperWM2K(0.1, 0.02, WindPower(ln_v, 0.8)), 6.225538975657,
            "paper, n = 0.8");
  ExpectRel(FrontConductanceConvectiveWM2K(10.0, 3.0, WindPower(ln_v, 0.8)), 19.09429939906,
            "+wind, n = 0.8");
  // The two forms move in opposite directions with wind (wind.h's note):
  // the paper's falls below U_front, the physical one rises above it.
  EXPECT_LT(FrontConductancePaperWM2K(0.1, 0.02, 2.0), 10.0);
  EXPECT_GT(FrontConductanceConvectiveWM2K(10.0, 3.0, 2.0), 10.0);
  // Calm: ln v = −inf, v^n = 0, both forms give U_front.
  const double calm = WindPower(-std::numeric_limits<double>::infinity(), 0.8);
  EXPECT_EQ(calm, 0.0);
  ExpectRel(FrontConductancePaperWM2K(0.1, 0.02, calm), 10.0, "paper, calm");
  ExpectRel(FrontConductanceConvectiveWM2K(10.0, 3.0, calm), 10.0, "+wind, calm");
}

}  // namespace
}  // namespace pvtwin
