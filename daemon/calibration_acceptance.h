// Whether the daemon takes a new calibration: on the held-out day, by the
// paper's objective (MAE of P_el + MAE of Q_u per m²), against the current
// parameters. A fit whose parameters sit at the bounds of their search
// range is less trustworthy (the data or the model could not hold them in
// their physical range, e.g. a front loss at 1000 W/(m²K)); it replaces
// working parameters only when it is clearly better.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace pvtwin::cli {

// A fit with parameters at bounds must beat the current one by this fraction.
inline constexpr double kAtBoundsMargin = 0.02;

struct AcceptanceDecision {
  bool accept = false;
  std::string reason;  // for the calibration row, numbers unrounded enough to compare
};

// fresh_w_m2, current_w_m2: held-out objectives per m² of collector (area_m2
// turns them into W of the collector for the reason); no current: first
// parameters.
AcceptanceDecision DecideCalibration(double fresh_w_m2, std::optional<double> current_w_m2,
                                     const std::vector<std::string>& at_bounds, double area_m2);

}  // namespace pvtwin::cli
