// The daemon's rule for taking a new calibration (daemon/calibration_acceptance.h).
#include <gtest/gtest.h>

#include "daemon/calibration_acceptance.h"

namespace pvtwin::cli {
namespace {

TEST(CalibrationAcceptance, FirstParametersAreTakenAndTheirBoundsNamed) {
  const AcceptanceDecision d = DecideCalibration(7.0, std::nullopt, {"f_th"}, 1.8);
  EXPECT_TRUE(d.accept);
  EXPECT_EQ(d.reason, "first parameters of this database; 1 parameter at bounds (f_th)");
}

TEST(CalibrationAcceptance, AFitInsideItsBoundsNeedsOnlyToBeNoWorse) {
  AcceptanceDecision d = DecideCalibration(6.0, 6.0, {}, 2.0);
  EXPECT_TRUE(d.accept);
  EXPECT_EQ(d.reason,
            "held-out MAE (P_el + Q_u) 12.00 W (6.00 W/m²) ≤ the current 12.00 W (6.00 W/m²)");
  d = DecideCalibration(6.01, 6.0, {}, 2.0);
  EXPECT_FALSE(d.accept);
  EXPECT_EQ(d.reason,
            "held-out MAE (P_el + Q_u) 12.02 W (6.01 W/m²) exceeds the current 12.00 W "
            "(6.00 W/m²); "
            "parameters kept");
}

TEST(CalibrationAcceptance, AFitAtItsBoundsMustBeTwoPercentBetter) {
  // 1 % better is not enough for parameters at their bounds …
  AcceptanceDecision d = DecideCalibration(5.94, 6.0, {"f_th", "u_front_w_m2k"}, 1.0);
  EXPECT_FALSE(d.accept);
  EXPECT_EQ(d.reason,
            "held-out MAE (P_el + Q_u) 5.94 W (5.94 W/m²) exceeds 2 % below the current 6.00 W "
            "(6.00 W/m²); 2 parameters at bounds (f_th, u_front_w_m2k); parameters kept");
  // … 3 % is.
  d = DecideCalibration(5.82, 6.0, {"f_th"}, 1.0);
  EXPECT_TRUE(d.accept);
  EXPECT_NE(d.reason.find("≤ 2 % below the current"), std::string::npos) << d.reason;
}

}  // namespace
}  // namespace pvtwin::cli
