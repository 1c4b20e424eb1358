// The machine-readable report of `pvtwin backtest` (core/backtest.h).
//
//   { "format": "pvtwin-backtest-1",
//     "runs": [ {                                one per time step run
//       "step_s": 60, "wall_time_s": 95.2, "test_days": 29,
//       "solar_offset_s": 3871,                  local mean solar time − UTC
//       "averages": [ { "variant": "2N1Ccolwr", "train_days": 14,
//                       "days_ok": 29, "days_failed": 0,
//                       "mae_p_el_w_m2": 2.0, "mae_q_th_w_m2": 17.2,
//                       "nmae_p_el": 0.033, "nmae_q_th": 0.185,   (fractions)
//                       "runtime_s": 0.8 }, ... ],
//       "days": [ { "day": "2024-06-15",          local mean solar date
//                   "day_start": "2024-06-14T22:55:29Z", "day_start_s": 1718405729,
//                   "variant": "2N1Ccolwr", "train_days": 14,
//                   "ok": true, "failure": "none", "failure_reason": "",
//                   "test": { "rows": 1440, "mae_p_el_w": …, "mae_q_th_w": …,
//                             "mae_p_el_w_m2": …, "mae_q_th_w_m2": …,
//                             "nmae_p_el": …, "nmae_q_th": … },
//                   "runtime_s": 0.8, "evaluations": 812,
//                   "params": { "u_front_w_m2k": 14.1, ... } }, ... ] } ] }
//
// "days" are in the order of BacktestResult::days; "params" holds the
// parameters the variant uses (params.json names), present when the
// identification ran. A number that is not finite is written as null.
#pragma once

#include <span>
#include <string>

#include "core/forecast/backtest.h"

namespace pvtwin {

// One run as a JSON object (an element of "runs").
std::string BacktestJson(const BacktestResult& result);

// The whole report: the format tag and every run.
std::string BacktestReportJson(std::span<const BacktestResult> runs);

}  // namespace pvtwin
