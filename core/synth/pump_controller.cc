#include "core/synth/pump_controller.h"

namespace pvtwin {

DifferentialControlState StepDifferentialControl(const DifferentialControlParams& params,
                                                 const DifferentialControlState& state,
                                                 const DifferentialControlInput& in) {
  DifferentialControlState next = state;
  next.since_switch_s += in.dt_s;
  if (next.since_switch_s < params.min_dwell_s) return next;
  const double difference_k = in.t_coll_c - in.t_ref_c;
  const bool want_on = state.pump_on ? (in.enabled && difference_k >= params.dt_off_k)
                                     : (in.enabled && difference_k > params.dt_on_k);
  if (want_on != state.pump_on) {
    next.pump_on = want_on;
    next.since_switch_s = 0.0;
  }
  return next;
}

}  // namespace pvtwin
