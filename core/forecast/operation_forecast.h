// The plant's operation over a forecast horizon when no operation_plan is
// given (issue 15): a controller learned from the window, beside the
// typical day of core/forecast/forecast.h.
//
// Learned rule, fitted to the measured 1-min rows of the window:
//   pump      on/off with hysteresis on the in-plane irradiance (else GHI):
//             it starts when G ≥ g_on, stops when G < g_off (g_off ≤ g_on),
//             and runs only between the first and last local solar hour at
//             which the window saw it on (the 1st and 99th percentiles of
//             its on-minutes). g_on and g_off are the pair of a 25 W/m² grid
//             (0 … 800) whose rule, run over the window's measured
//             irradiance, misclassifies the fewest minutes. A thermostat on
//             the collector-minus-tank difference acts through the
//             irradiance that heats the collector, so this form stands for
//             it as well as for an irradiance switch; its
//             accuracy on the window is part of the description.
//   flow      when on: the median measured flow of the on-minutes of the
//             same local solar hour (of all on-minutes where an hour has
//             fewer than 10); off: 0.
//   inlet     the typical day's course (median by minute of the UTC day)
//             shifted to the level of the last measured day: + (mean of the
//             last 24 h − mean of the typical day over the same minutes), so
//             a tank warmer than usual stays warmer.
// The forecast uses it when it predicted the window's replayed days better
// than the typical day (ChooseOperation, forecast_bands.h), as the daemon
// and `backtest --forecast` do.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/plant.h"
#include "core/common/series.h"

namespace pvtwin {

struct PumpRule {
  bool valid = false;                     // false: the window held too little to learn from
  double g_on_w_m2 = 0.0;                 // start at or above
  double g_off_w_m2 = 0.0;                // stop below
  double first_hour = 0.0;                // local solar hour, earliest on
  double last_hour = 24.0;                // latest on
  double accuracy = 0.0;                  // share of the window's minutes the rule classifies right
  bool on_plane = true;                   // the rule reads g_poa_w_m2 (else ghi_w_m2)
  std::vector<double> flow_by_hour_kg_s;  // 24 entries: flow when on, per solar hour
  std::string Describe() const;  // "pump on at G ≥ 150, off below 100 W/m², 6.4–18.1 h …"
};

// Learns the rule from measured rows (needs mdot_kg_s and an irradiance).
PumpRule LearnPumpRule(const Plant& plant, const Series& history);

// The pump's flow over rows of `inputs` (their irradiance, already the
// forecast's), starting from the state `on_at_start`.
std::vector<double> PumpFlow(const Plant& plant, const PumpRule& rule, const Series& inputs,
                             bool on_at_start);

// Local solar hour (0 … 24) of a unix time: UTC plus the longitude's hours
// (the equation of time, ±16 min, left out).
double SolarHour(const Plant& plant, std::int64_t time_s);

}  // namespace pvtwin
