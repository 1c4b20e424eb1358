#include "io/report/backtest_report.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/model/variant.h"
#include "io/platform/time_format.h"

namespace pvtwin {

namespace {

nlohmann::ordered_json Number(double x) {
  return std::isfinite(x) ? nlohmann::ordered_json(x) : nlohmann::ordered_json(nullptr);
}

nlohmann::ordered_json RunObject(const BacktestResult& r) {
  nlohmann::ordered_json run;
  run["step_s"] = Number(r.step_s);
  run["wall_time_s"] = Number(r.wall_time_s);
  run["test_days"] = r.test_days;
  run["solar_offset_s"] = r.solar_offset_s;
  run["warm_start"] = r.warm_start;
  nlohmann::ordered_json averages = nlohmann::ordered_json::array();
  for (const BacktestAverage& a : r.averages) {
    averages.push_back({{"variant", a.variant},
                        {"train_days", a.train_days},
                        {"days_ok", a.days_ok},
                        {"days_failed", a.days_failed},
                        {"mae_p_el_w_m2", Number(a.mae_p_el_w_m2)},
                        {"mae_q_th_w_m2", Number(a.mae_q_th_w_m2)},
                        {"nmae_p_el", Number(a.nmae_p_el)},
                        {"nmae_q_th", Number(a.nmae_q_th)},
                        {"runtime_s", Number(a.runtime_s)}});
  }
  run["averages"] = std::move(averages);
  nlohmann::ordered_json days = nlohmann::ordered_json::array();
  for (const BacktestDay& d : r.days) {
    nlohmann::ordered_json day;
    day["day"] = SolarDate(d.day_start_s, r.solar_offset_s);
    day["day_start"] = FormatIsoUtc(d.day_start_s);
    day["day_start_s"] = d.day_start_s;
    day["variant"] = d.variant;
    day["train_days"] = d.train_days;
    day["ok"] = d.ok;
    day["failure"] = std::string(ToString(d.failure));
    day["failure_reason"] = d.failure_reason;
    day["test"] = {{"rows", d.test.rows},
                   {"mae_p_el_w", Number(d.test.mae_p_el_w)},
                   {"mae_q_th_w", Number(d.test.mae_q_th_w)},
                   {"mae_p_el_w_m2", Number(d.test.mae_p_el_w_m2)},
                   {"mae_q_th_w_m2", Number(d.test.mae_q_th_w_m2)},
                   {"nmae_p_el", Number(d.test.nmae_p_el)},
                   {"nmae_q_th", Number(d.test.nmae_q_th)}};
    day["runtime_s"] = Number(d.runtime_s);
    day["evaluations"] = d.evaluations;
    const bool identified = d.ok || d.failure == BacktestFailure::kIdentification ||
                            d.failure == BacktestFailure::kNonFiniteErrors;
    ModelSpec spec;
    std::string error;
    if (identified && ParseVariant(d.variant, &spec, &error)) {
      const auto used = UsedParams(spec);
      nlohmann::ordered_json params = nlohmann::ordered_json::object();
      for (const ParamInfo& info : kParamTable) {
        const auto i = static_cast<std::size_t>(info.param);
        if (used.test(i)) params[std::string(info.name)] = Number(d.params[i]);
      }
      day["params"] = std::move(params);
    }
    days.push_back(std::move(day));
  }
  run["days"] = std::move(days);
  return run;
}

}  // namespace

std::string BacktestJson(const BacktestResult& result) { return RunObject(result).dump(2); }

std::string BacktestReportJson(std::span<const BacktestResult> runs) {
  nlohmann::ordered_json doc;
  doc["format"] = "pvtwin-backtest-1";
  doc["runs"] = nlohmann::ordered_json::array();
  for (const BacktestResult& r : runs) doc["runs"].push_back(RunObject(r));
  return doc.dump(2) + "\n";
}

}  // namespace pvtwin
