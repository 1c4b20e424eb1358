// scale: a flow meter whose reading is k × the true flow from one day on
// (sensor_residuals.h). The heat meter multiplies that reading by the
// (right) temperature difference, so Q_u,meas = k·Q_u,true while the pump
// runs, and the model, driven by the same reading, predicts nearly the true
// Q_u (at the collector's usual flows its heat removal factor barely moves
// with flow). The measured-to-modelled ratio then steps to k and stays k at
// every irradiance, temperature and flow, where a thermal-model gap moves
// the ratio with irradiance (optics) or with T − T_amb (losses), and an
// inlet offset moves Q_u by ṁ·c_p·δ, not in proportion.
//
// The test: per solar day the least-squares ratio Σ Q_meas·Q_model /
// Σ Q_model² over the rows with flow (at least sensor_step_min_rows), its
// logarithm as the day series, the day-step test (TestDayStep) with alpha,
// and a ratio step exp(after − before) at least min_flow_scale_error from 1.
// The finding competes with offset_step for the Q_u residual (both move it
// from a day on): the fault model that fits the rows from its onset better,
// on a model fitted before it, stays (FindResidualSensorFaults).
#include <cmath>

#include "core/common/calendar.h"
#include "core/diagnosis/sensor_residuals.h"

namespace pvtwin::diagnosis_stages {

std::optional<ResidualFinding> CheckFlowScale(const SensorResiduals& r, const Progress& progress) {
  const DiagnosisOptions& o = *r.options;
  const DaySeries s = DailyLogRatios(
      r, r.q_meas_w, r.q_model_w, [&r](std::uint32_t i) { return r.capacity_flow_w_k[i] > 0.0; },
      o.sensor_step_min_rows);
  const std::optional<DayStep> d = TestDayStep(s, o.alpha);
  if (!d) return std::nullopt;
  const double k = std::exp(d->after - d->before);
  const std::string from = SolarDate(s.days[d->split], r.offset_s);
  progress("sensor scale test: measured / modelled Q_u steps by × " + FixedDecimals(k, 3) + " on " +
           from + " (" + (d->separated ? "separated" : "not separated") + ", p = " + PValue(d->p) +
           (d->beats_line ? ", better than a drift)" : ", a drift fits as well)"));
  if (!d->found || std::fabs(k - 1.0) < o.min_flow_scale_error) return std::nullopt;
  ResidualFinding out;
  SensorFinding& f = out.finding;
  f = FindingFrom(*r.data, "flow_kg_s", "scale", s.days[d->split], from, k);
  f.size_unit = "";  // a ratio
  f.detail = "from " + f.from + " on the measured Q_u is " + FixedDecimals(k, 3) +
             " × what it was against the model before, on every day after and on none before "
             "(p = " +
             PValue(d->p) + " over " + std::to_string(s.y.size()) +
             " days), in proportion while the pump runs: the flow meter reads about " +
             FixedDecimals(100.0 * (k - 1.0), 1) +
             " % off (a clogged or re-mounted meter, a changed pulse value or glycol share)";
  // Its fault model from the onset: Q_meas = k · Q_model.
  out.explains = "q_th_w";
  out.fault_x = [](const SensorResiduals& m, std::uint32_t i) { return m.q_model_w[i]; };
  out.fault_y = [](const SensorResiduals& m, std::uint32_t i) { return m.q_meas_w[i]; };
  return out;
}

}  // namespace pvtwin::diagnosis_stages
