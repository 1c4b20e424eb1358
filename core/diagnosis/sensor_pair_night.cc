// pair_offset: the logged inlet and outlet temperatures disagree with the
// pump on and no sun (sensor_residuals.h).
//
// With the pump on and no irradiance the collector is a heat exchanger with
// the air and the sky: the fluid's temperature change, T_out − T_in, is the
// model's small loss-driven difference, ≈ −U·A·(T_m − T_amb)/(ṁ·c_p) plus the
// sky's long-wave term, with no optical part whose errors dominate the day.
// The model's residual of that difference, (T_out − T_in)_logged −
// (T_out − T_in)_model = T_out,logged − T_out,model, is then the sensors'
// disagreement plus the sensor noise. A constant offset of either sensor of
// the pair from one day on steps it by the offset (an outlet offset fully;
// an inlet offset, which also moves the model's own outlet, by the share
// exp(−U·A/(ṁ·c_p)) the collector does not take back); the heat meter may
// have its own sensors, so this reads the logged channels, not q_th_w.
// Night data cannot tell which sensor of the pair moved: the pair is named.
//
// The test: per solar day the median of that residual over the night rows
// with flow (in-plane irradiance at most sensor_night_g_w_m2, at least
// sensor_step_min_rows of them), then the day-step test (TestDayStep) with
// alpha, and a step of at least min_temperature_offset_k.
#include <cmath>

#include "core/common/calendar.h"
#include "core/diagnosis/sensor_residuals.h"

namespace pvtwin::diagnosis_stages {

std::optional<ResidualFinding> CheckNightPairOffset(const SensorResiduals& r,
                                                    const Progress& progress) {
  const DiagnosisOptions& o = *r.options;
  auto night_with_flow = [&r, &o](std::uint32_t i) {
    return r.capacity_flow_w_k[i] > 0.0 && r.g_poa_w_m2[i] <= o.sensor_night_g_w_m2;
  };
  auto residual_k = [&r](std::uint32_t i) { return r.t_out_meas_c[i] - r.t_out_model_c[i]; };
  const DaySeries s = DailyMedians(r, night_with_flow, residual_k, o.sensor_step_min_rows);
  const std::optional<DayStep> d = TestDayStep(s, o.alpha);
  if (!d) return std::nullopt;  // fewer than 5 days with pumping at night
  const double step_k = d->after - d->before;
  const std::string from = SolarDate(s.days[d->split], r.offset_s);
  progress("sensor pair test at night: (T_out − T_in) logged − model steps by " +
           FixedDecimals(step_k, 2) + " K on " + from + " over " + std::to_string(s.y.size()) +
           " days with night flow (" + (d->separated ? "separated" : "not separated") +
           ", p = " + PValue(d->p) + ")");
  if (!d->found || std::fabs(step_k) < o.min_temperature_offset_k) return std::nullopt;
  ResidualFinding out;
  SensorFinding& f = out.finding;
  f = FindingFrom(*r.data, "t_in_c,t_out_c", "pair_offset", s.days[d->split], from, step_k);
  f.detail = "from " + f.from + " on, with the pump on and no sun, the logged T_out − T_in is " +
             FixedDecimals(std::fabs(step_k), 2) + " K " + (step_k > 0.0 ? "above" : "below") +
             " the model's (which at night is only the small exchange with air and sky), on "
             "every night after and on none before (p = " +
             PValue(d->p) + " over " + std::to_string(s.y.size()) + " nights): the " +
             (step_k > 0.0 ? "outlet reads high or the inlet low" :
                             "outlet reads low or the inlet high") +
             "; check the pair against each other in a bath or with the pump running at night";
  out.explains = "t_out_c - t_in_c";
  return out;
}

}  // namespace pvtwin::diagnosis_stages
