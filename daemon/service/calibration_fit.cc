#include "daemon/service/calibration_fit.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace pvtwin {

namespace {

using ordered_json = nlohmann::ordered_json;
using json = nlohmann::json;

ordered_json MetricsJson(const ErrorMetrics& e) {
  ordered_json m;
  m["rows"] = e.rows;
  m["mae_p_el_w"] = e.mae_p_el_w;
  m["mae_q_th_w"] = e.mae_q_th_w;
  m["mae_p_el_w_m2"] = e.mae_p_el_w_m2;
  m["mae_q_th_w_m2"] = e.mae_q_th_w_m2;
  m["nmae_p_el"] = e.nmae_p_el;  // NaN is written as null
  m["nmae_q_th"] = e.nmae_q_th;
  return m;
}

// A number member, NaN for null; `fallback` when missing or not a number.
double NumberOr(const json& j, const char* key, double fallback) {
  if (!j.is_object() || !j.contains(key)) return fallback;
  const json& v = j[key];
  if (v.is_null()) return std::nan("");
  return v.is_number() ? v.get<double>() : fallback;
}

std::string TextOr(const json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : "";
}

std::vector<std::string> Names(const json& j, const char* key) {
  std::vector<std::string> names;
  if (!j.contains(key) || !j[key].is_array()) return names;
  for (const json& n : j[key]) {
    if (n.is_string()) names.push_back(n.get<std::string>());
  }
  return names;
}

ErrorMetrics MetricsOf(const json& j) {
  ErrorMetrics e;
  if (j.contains("rows") && j["rows"].is_number_unsigned()) e.rows = j["rows"].get<std::size_t>();
  e.mae_p_el_w = NumberOr(j, "mae_p_el_w", 0.0);
  e.mae_q_th_w = NumberOr(j, "mae_q_th_w", 0.0);
  e.mae_p_el_w_m2 = NumberOr(j, "mae_p_el_w_m2", 0.0);
  e.mae_q_th_w_m2 = NumberOr(j, "mae_q_th_w_m2", 0.0);
  e.nmae_p_el = NumberOr(j, "nmae_p_el", 0.0);
  e.nmae_q_th = NumberOr(j, "nmae_q_th", 0.0);
  e.mae_t_pv_k = std::nan("");
  return e;
}

CalibrationFit FitOf(const json& j) {
  CalibrationFit fit;
  fit.algorithm = TextOr(j, "algorithm");
  fit.termination = TextOr(j, "termination");
  fit.initial_cost_w_m2 = NumberOr(j, "initial_cost_w_m2", 0.0);
  fit.final_cost_w_m2 = NumberOr(j, "final_cost_w_m2", 0.0);
  if (j.contains("simulations") && j["simulations"].is_number_integer())
    fit.simulations = j["simulations"].get<int>();
  fit.runtime_s = NumberOr(j, "runtime_s", 0.0);
  if (j.contains("train") && j["train"].is_object()) fit.train = MetricsOf(j["train"]);
  if (j.contains("held_out") && j["held_out"].is_object()) fit.held_out = MetricsOf(j["held_out"]);
  fit.at_bounds = Names(j, "at_bounds");
  if (j.contains("parameters") && j["parameters"].is_array()) {
    for (const json& p : j["parameters"]) {
      if (!p.is_object() || !p.contains("name") || !p["name"].is_string() ||
          !p.contains("value") || !p["value"].is_number()) {
        continue;
      }
      FitParameter param;
      param.name = p["name"].get<std::string>();
      param.value = p["value"].get<double>();
      param.std_error = p.contains("std_error") && p["std_error"].is_number()
                            ? p["std_error"].get<double>()
                            : std::nan("");
      param.unit = TextOr(p, "unit");
      param.status = TextOr(p, "status");
      fit.parameters.push_back(std::move(param));
    }
  }
  fit.undetermined = Names(j, "undetermined");
  return fit;
}

}  // namespace

std::string CalibrationFit::ToJson() const {
  ordered_json j;
  j["algorithm"] = algorithm;
  j["termination"] = termination;
  j["initial_cost_w_m2"] = initial_cost_w_m2;
  j["final_cost_w_m2"] = final_cost_w_m2;
  j["simulations"] = simulations;
  j["runtime_s"] = runtime_s;
  j["train"] = MetricsJson(train);
  if (held_out) j["held_out"] = MetricsJson(*held_out);
  j["at_bounds"] = at_bounds;
  // Every parameter as calibrate's table prints it (the daemon stores them
  // in calibration_param).
  j["parameters"] = ordered_json::array();
  for (const FitParameter& p : parameters) {
    j["parameters"].push_back({{"name", p.name},
                               {"value", p.value},
                               {"std_error", p.std_error},  // NaN is written as null
                               {"unit", p.unit},
                               {"status", p.status}});
  }
  j["undetermined"] = undetermined;
  return j.dump();
}

bool CalibrationFit::FromJson(std::string_view fit_json, CalibrationFit* out) {
  const json j = json::parse(fit_json, nullptr, false);
  if (!j.is_object()) return false;
  *out = FitOf(j);
  return true;
}

bool CalibrationFit::FromParamsJson(std::string_view params_json, CalibrationFit* out) {
  const json j = json::parse(params_json, nullptr, false);
  if (!j.is_object()) return false;
  *out = FitOf(j.contains("fit") ? j["fit"] : json::object());
  return true;
}

}  // namespace pvtwin
