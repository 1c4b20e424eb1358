#include "daemon/calibration_acceptance.h"

#include "io/quantity_text.h"

namespace pvtwin::cli {

namespace {

// The collector's and the per-m² figure side by side (io/quantity_text.h).
std::string Watts(double w_m2, double area_m2) { return WattsAndPerM2(w_m2 * area_m2, area_m2); }

}  // namespace

AcceptanceDecision DecideCalibration(double fresh_w_m2, std::optional<double> current_w_m2,
                                     const std::vector<std::string>& at_bounds, double area_m2) {
  std::string bounds;
  for (const std::string& name : at_bounds) bounds += (bounds.empty() ? "" : ", ") + name;
  const std::string bounds_note = at_bounds.empty()
                                      ? ""
                                      : "; " + std::to_string(at_bounds.size()) +
                                            (at_bounds.size() == 1 ? " parameter" : " parameters") +
                                            " at bounds (" + bounds + ")";
  AcceptanceDecision d;
  if (!current_w_m2) {
    d.accept = true;
    d.reason = "first parameters of this database" + bounds_note;
    return d;
  }
  const double limit_w_m2 =
      at_bounds.empty() ? *current_w_m2 : (1.0 - kAtBoundsMargin) * *current_w_m2;
  d.accept = fresh_w_m2 <= limit_w_m2;
  const std::string comparison = "held-out MAE (P_el + Q_u) " + Watts(fresh_w_m2, area_m2) +
                                 (d.accept ? " ≤ " : " exceeds ") +
                                 (at_bounds.empty() ? "the current " : "2 % below the current ") +
                                 Watts(*current_w_m2, area_m2);
  d.reason = comparison + bounds_note + (d.accept ? "" : "; parameters kept");
  return d;
}

}  // namespace pvtwin::cli
