// The solar loop's pump controller of the simulated plant: a differential
// (ΔT) thermostat with hysteresis and a minimum dwell time, as real solar
// controllers run it. Pure computation; the caller keeps the state.
//
//   pump off → on   when T_coll − T_ref > ΔT_on   (default 5 K)
//   pump on  → off  when T_coll − T_ref < ΔT_off  (default 2 K)
//   no switching until min_dwell_s have passed since the last one
//   (an "enable" input can force the pump off, again subject to the dwell:
//   the heat pump's schedule in the heat-pump-source mode)
//
// T_coll is the collector (absorber) sensor, T_ref the tank or the brine at
// the collector inlet, both °C. Typical values: ΔT_on 4–8 K, ΔT_off 1–3 K
// (Duffie & Beckman, Solar Engineering of Thermal Processes, 4th ed., §10.5).
#pragma once

namespace pvtwin {

struct DifferentialControlParams {
  double dt_on_k = 5.0;        // switch on above this difference, > dt_off_k
  double dt_off_k = 2.0;       // switch off below this one
  double min_dwell_s = 300.0;  // minimum time between two switchings, ≥ 0
};

struct DifferentialControlState {
  bool pump_on = false;
  double since_switch_s = 1e300;  // time since the last switching (start: free to switch)
};

struct DifferentialControlInput {
  double t_coll_c = 0.0;  // collector (absorber) sensor
  double t_ref_c = 0.0;   // tank / brine at the inlet
  bool enabled = true;    // false: the pump should stop (e.g. the heat pump is idle)
  double dt_s = 0.0;      // time since the previous call, ≥ 0
};

// Advances the controller by one step: first the dwell clock by dt_s, then
// at most one switching. Returns the new state.
DifferentialControlState StepDifferentialControl(const DifferentialControlParams& params,
                                                 const DifferentialControlState& state,
                                                 const DifferentialControlInput& in);

}  // namespace pvtwin
