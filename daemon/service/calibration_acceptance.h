// Whether the daemon takes a new calibration: on the held-out days, by the
// paper's objective (MAE of P_el + MAE of Q_u per m²), against the current
// parameters. The fresh fit is taken unless it is worse than the current
// parameters beyond the noise of the comparison (the standard error of the
// hourly differences, HeldOutDifferenceSe): the evidence of the held-out
// days decides, whatever the fit's bounds. Parameters at the bounds of their
// search range (e.g. a front loss at 1000 W/(m²K)) are named in the reason
// (and in parameter_history's status) as a sign of a structural gap for the
// diagnosis; they are no reason to keep stale parameters, which would sit at
// the same bounds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/model/variant.h"

namespace pvtwin::cli {

struct AcceptanceDecision {
  bool accept = false;
  std::string reason;  // for the calibration row, numbers unrounded enough to compare
};

// fresh_w_m2, current_w_m2: held-out objectives per m² of collector (area_m2
// turns them into W of the collector for the reason); no current: first
// parameters. tolerance_w_m2: how much worse the fresh fit may be and still
// be taken, the spread of the held-out comparison (HeldOutDifferenceSe).
// at_bounds: named in the reason, not a criterion.
AcceptanceDecision DecideCalibration(double fresh_w_m2, std::optional<double> current_w_m2,
                                     const std::vector<std::string>& at_bounds, double area_m2,
                                     double tolerance_w_m2 = 0.0);

// A held-out row that can judge a fit: valid, the pump running, the sun on
// the collector (in-plane irradiance, or GHI without it, at least 200 W/m²),
// P_el and Q_u (or both fluid temperatures) measured. An overcast day with
// the pump off has none: both fits "predict" it perfectly.
bool IsInformativeRow(const Series& s, std::size_t i);

struct HeldOutChoice {
  int days = 1;                      // the window's last days held out of the fit
  std::size_t informative_rows = 0;  // in them
};

// The fewest of the window's last days (1 … max_days) that hold min_rows
// informative rows, while at least min_train_days stay before them for the
// fit; the most that may be held out when none does. window ends at end_s.
HeldOutChoice ChooseHeldOutDays(const Series& window, std::int64_t end_s, int max_days = 3,
                                std::size_t min_rows = 120, int min_train_days = 1);

// The standard error (W/m²) of the mean over the held-out hours of the
// difference of the objective (MAE of P_el + MAE of Q_u per m²) between the
// fresh and the current parameters: how far apart the two may lie by the
// hour-to-hour spread alone. 0 with fewer than 3 hours that have informative
// rows.
double HeldOutDifferenceSe(const Series& test, const Plant& plant, const ModelSpec& spec,
                           const ParamVector& fresh, const ParamVector& current);

}  // namespace pvtwin::cli
