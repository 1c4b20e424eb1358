// The pure equations the effect modules export (core/effects/<effect>.h),
// each on an analytic case.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/common/units.h"
#include "core/effects/clock_offset.h"
#include "core/effects/flow_dependent_u.h"
#include "core/effects/shading.h"
#include "core/effects/soiling.h"
#include "core/physics/fluid_coupling.h"

namespace pvtwin {
namespace {

// σ(x) = 1/(1 + e^−x); both logistic edges at their half-way point give ¼.
TEST(EffectEquations, ShadedFractionFollowsTheLogisticEdges) {
  const double centre = DegToRad(250.0), width = DegToRad(40.0), edge = DegToRad(35.0);
  // Deep inside the window and well below the edge: fully shaded.
  EXPECT_NEAR(ShadedFraction(centre, DegToRad(10.0), centre, width, edge), 1.0, 1e-4);
  // Exactly on both edges: σ(0)·σ(0).
  EXPECT_NEAR(ShadedFraction(centre + 0.5 * width, edge, centre, width, edge), 0.25, 1e-12);
  // On the azimuth edge, far below the elevation edge: σ(0).
  EXPECT_NEAR(ShadedFraction(centre - 0.5 * width, DegToRad(1.0), centre, width, edge), 0.5, 1e-6);
  // Outside the window, above the obstacle, or with the sun down: no shade.
  EXPECT_LT(ShadedFraction(DegToRad(180.0), DegToRad(10.0), centre, width, edge), 1e-6);
  EXPECT_LT(ShadedFraction(centre, DegToRad(60.0), centre, width, edge), 1e-5);
  EXPECT_EQ(ShadedFraction(centre, -0.1, centre, width, edge), 0.0);
  // The azimuth difference wraps: a window across north acts as one away from it.
  EXPECT_NEAR(ShadedFraction(DegToRad(355.0), DegToRad(5.0), DegToRad(5.0), width, edge),
              ShadedFraction(DegToRad(95.0), DegToRad(5.0), DegToRad(105.0), width, edge), 1e-12);
}

// τ_soil = max(0, 1 − r·d): linear, never negative.
TEST(EffectEquations, SoilingTransmittanceIsLinearAndFloorsAtZero) {
  EXPECT_DOUBLE_EQ(SoilingTransmittance(0.004, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(SoilingTransmittance(0.004, 25.0), 0.9);
  EXPECT_DOUBLE_EQ(SoilingTransmittance(0.01, 250.0), 0.0);
}

// n_flow = 0 is the paper's eq. 2.7; at the reference flow every exponent
// gives the same conductance; below it the turbulent form (0.8) couples less.
TEST(EffectEquations, FlowDependentCouplingReducesToThePaperForm) {
  const double area_m2 = 2.0, cp = 3800.0, r0_per_area = 0.1 / area_m2, r1 = 1.2;
  const double mdot_ref = kFlowReferenceKgSM2 * area_m2;
  for (double mdot : {0.01, 0.04, 0.08}) {
    EXPECT_DOUBLE_EQ(
        FluidConductanceFlowDependentWK(mdot * cp, mdot, r0_per_area, r1, mdot_ref, 0.0),
        GFluidWK(mdot * cp, r0_per_area, r1));
  }
  EXPECT_DOUBLE_EQ(
      FluidConductanceFlowDependentWK(mdot_ref * cp, mdot_ref, r0_per_area, r1, mdot_ref, 0.8),
      GFluidWK(mdot_ref * cp, r0_per_area, r1));
  const double low = 0.5 * mdot_ref;
  EXPECT_LT(FluidConductanceFlowDependentWK(low * cp, low, r0_per_area, r1, mdot_ref, 0.8),
            GFluidWK(low * cp, r0_per_area, r1));
  EXPECT_EQ(FluidConductanceFlowDependentWK(0.0, 0.0, r0_per_area, r1, mdot_ref, 0.8), 0.0);
}

// Linear interpolation at t + Δt, held at the ends.
TEST(EffectEquations, ShiftInTimeInterpolatesAndHoldsTheEnds) {
  Drivers d;
  d.time_s = {0, 60, 120, 180};
  const std::vector<double> v = {0.0, 10.0, 20.0, 40.0};
  std::vector<double> out;
  ShiftInTime(d, v.data(), 30.0, &out);
  EXPECT_EQ(out, (std::vector<double>{5.0, 15.0, 30.0, 40.0}));
  ShiftInTime(d, v.data(), -90.0, &out);
  EXPECT_EQ(out, (std::vector<double>{0.0, 0.0, 5.0, 15.0}));
}

}  // namespace
}  // namespace pvtwin
