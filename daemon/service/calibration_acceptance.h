// Whether the daemon takes a new calibration: on the held-out day, by the
// paper's objective (MAE of P_el + MAE of Q_u per m²), against the current
// parameters. A fit whose parameters sit at the bounds of their search
// range is less trustworthy (the data or the model could not hold them in
// their physical range, e.g. a front loss at 1000 W/(m²K)); it replaces
// working parameters only when it is clearly better.
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

// A fit with parameters at bounds must beat the current one by this fraction.
inline constexpr double kAtBoundsMargin = 0.02;

struct AcceptanceDecision {
  bool accept = false;
  std::string reason;  // for the calibration row, numbers unrounded enough to compare
};

// fresh_w_m2, current_w_m2: held-out objectives per m² of collector (area_m2
// turns them into W of the collector for the reason); no current: first
// parameters. tolerance_w_m2: how much worse the fresh fit may be and still
// be taken, the spread of the held-out comparison (HeldOutDifferenceSe); it
// does not apply to a fit with parameters at bounds.
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
