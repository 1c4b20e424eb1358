// The "fit" object of a params.json (io/files/params_json.h): what
// `pvtwin calibrate` (daemon/commands/cmd_calibrate.cc) writes about its fit
// and the daemon (service_calibration.cc) reads back into the calibration
// and calibration_param rows. One type for both sides (issue 51):
//
//   { "algorithm": "lad_lm", "termination": "...",
//     "initial_cost_w_m2": x, "final_cost_w_m2": x, "simulations": n,
//     "runtime_s": x, "train": {metrics}, "held_out": {metrics} (optional),
//     "at_bounds": ["name", ...],
//     "parameters": [{"name", "value", "std_error", "unit", "status"}, ...],
//     "undetermined": ["name", ...] }
//
// metrics: rows, mae_p_el_w, mae_q_th_w (W, whole field), mae_p_el_w_m2,
// mae_q_th_w_m2 (W/m²), nmae_p_el, nmae_q_th. NaN (an undefined nMAE, an
// unknown standard error) is written as null and read back as NaN.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/fit/identification.h"

namespace pvtwin {

struct FitParameter {
  std::string name;    // params.h name
  double value = 0.0;  // in unit
  double std_error = 0.0;  // in unit; NaN when unknown
  std::string unit;
  std::string status;  // identified, at a bound, fixed, ... as calibrate prints it
};

struct CalibrationFit {
  std::string algorithm;    // "lad_lm" or the NLopt algorithm's name
  std::string termination;  // ToString(Termination)
  double initial_cost_w_m2 = 0.0;
  double final_cost_w_m2 = 0.0;
  int simulations = 0;
  double runtime_s = 0.0;
  ErrorMetrics train;                   // mae_t_pv_k is not part of the object
  std::optional<ErrorMetrics> held_out;  // with calibrate --test
  std::vector<std::string> at_bounds;
  std::vector<FitParameter> parameters;
  std::vector<std::string> undetermined;

  // The object's JSON text, keys in the order above.
  std::string ToJson() const;
  // From the object's JSON text. Members that are missing or of another
  // type keep their defaults; a parameter without a string name or a
  // numeric value is left out. False (and *out untouched) when the text is
  // not a JSON object.
  static bool FromJson(std::string_view fit_json, CalibrationFit* out);
  // From a whole params.json text: its "fit" object (an empty fit when it
  // has none). False when the text is not a JSON object.
  static bool FromParamsJson(std::string_view params_json, CalibrationFit* out);
};

}  // namespace pvtwin
