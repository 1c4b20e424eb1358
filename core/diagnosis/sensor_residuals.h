// The sensor checks that read the model's residuals (issue 52, item 5):
// faults plausible on every row that the monitor's row checks cannot see, but
// that the calibrated model shows from one day on. Each check is one module
// (its own .cc) registered in one line of ResidualSensorChecks
// (sensor_steps.cc); FindResidualSensorFaults fits the final model once on
// all the days and asks every check, then once more on the days before a
// Q_u fault's onset to size it (ResidualFinding).
//
//   offset_step  (sensor_steps.cc)      t_in_c / t_out_c: Q_u low by ṁ·c_p·δ,
//                                       less what the model loses from δ
//   pair_offset  (sensor_pair_night.cc) t_in_c,t_out_c: the logged pair
//                disagrees with the model at night with the pump on
//   scale        (sensor_flow_scale.cc) flow_kg_s: Q_u = k × the model's
//                while the flow is on
//
// Every check reduces its rows to one number per solar day and asks the same
// question of the day series (TestDayStep): is there a step that stays from
// one day on? Day values are the units because residuals of a thermal model
// carry the weather's hours-long memory: the minutes of one day are not
// independent.
//
// A fault of the heat meter's channels (a finding that explains "q_th_w")
// leaves P_el alone: the inverter's reading does not change, and the model,
// driven by the faulty reading, predicts a cell temperature off by a
// fraction of a kelvin. A loss of light does not: soiling, snow or shading
// lowers both outputs from the same day. So a Q_u finding is dropped when
// P_el's measured-to-modelled ratio (DailyLogRatios) separates on the same
// day in the same direction with a one-sided probability n1!·n2!/(n1+n2)! of
// at most alpha (the chance of that separation when P_el does not step,
// whatever its days' distribution): the step is in the light both outputs
// share, not in the meter.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

// What every residual check reads: the final model fitted on all the days
// (no held-out split: a sensor fault is a property of the data), per row.
struct SensorResiduals {
  const Series* data = nullptr;  // the diagnosed rows (row i of every vector below)
  const Plant* plant = nullptr;
  const DiagnosisOptions* options = nullptr;
  std::int64_t offset_s = 0;              // SolarDayOffsetS
  std::vector<std::uint32_t> rows;        // objective rows of the fit
  std::vector<std::int64_t> day_s;        // per row: its solar day's start
  std::vector<double> capacity_flow_w_k;  // ṁ·c_p from the measured flow
  // What the measured-minus-modelled Q_u changes per K of inlet offset,
  // W/K: the heat meter's ṁ·c_p plus the model's own ∂Q_u/∂T_in (the model
  // is driven by the same logged inlet and predicts more loss from it:
  // re-run with T_in + 1 K, about −F_R·U_L·A).
  std::vector<double> inlet_offset_w_k;
  std::vector<double> g_poa_w_m2;
  std::vector<double> q_meas_w, q_model_w;                  // heat meter, model
  std::vector<double> p_meas_w, p_model_w;                  // inverter, model
  std::vector<double> t_in_c, t_out_meas_c, t_out_model_c;  // logged, logged, model
};

// The day series a check builds: one value per solar day with enough rows.
struct DaySeries {
  std::vector<std::int64_t> days;
  std::vector<double> y;
};

// The step test over a day series (the test of sensor_steps.cc's comment):
// the split day that fits best as two means; a step when the days on the two
// sides separate perfectly (it stays), the step fits better than a straight
// line (a drift is not a step) and 2·n1!·n2!/(n1+n2)! times the number of
// split days tried is at most alpha (the probability of that separation in
// a series without a step, whatever the days' distribution).
struct DayStep {
  bool found = false;                // separated, better than a line, p ≤ alpha (size not judged)
  std::size_t split = 0;             // first day of the step (index into DaySeries)
  double before = 0.0, after = 0.0;  // mean of the days before / from the split
  double p = 1.0;
  bool separated = false, beats_line = false;
};
std::optional<DayStep> TestDayStep(const DaySeries& s, double alpha);

// Median of the values of `x` per solar day (rows where keep(i) and x finite),
// days with at least min_rows values.
DaySeries DailyMedians(const SensorResiduals& r, const std::function<bool(std::uint32_t)>& keep,
                       const std::function<double(std::uint32_t)>& x, int min_rows);

// log(Σ meas·model / Σ model²) per solar day over the rows where keep(i),
// days with at least min_rows such rows and a positive ratio: the day's
// least-squares ratio of the measured to the modelled output.
DaySeries DailyLogRatios(const SensorResiduals& r, const std::vector<double>& meas,
                         const std::vector<double>& model,
                         const std::function<bool(std::uint32_t)>& keep, int min_rows);

// A fault model y(i) = g·x(i) over a residual set (FitFault).
using RowValue = std::function<double(const SensorResiduals&, std::uint32_t)>;

// A finding of a residual check. A finding with a fault model (fault_x,
// fault_y) is sized on a model fitted on the days before its onset: its size
// becomes |g| of that fit (a model fitted on the faulty days too has taken up
// part of the fault). Checks that explain the same residual (`explains`,
// e.g. "q_th_w") compete on the model fitted before the earliest of their
// onsets: of those found, the one whose fault model leaves the smaller mean
// square on the rows from its onset is kept (FindResidualSensorFaults).
struct ResidualFinding {
  SensorFinding finding;
  std::string explains;
  RowValue fault_x, fault_y;
};

using ResidualSensorCheck =
    std::function<std::optional<ResidualFinding>(const SensorResiduals&, const Progress&)>;

// The checks (sensor_steps.cc), one line each.
const std::vector<ResidualSensorCheck>& ResidualSensorChecks();

// The checks' modules.
std::optional<ResidualFinding> CheckOffsetStep(const SensorResiduals& r, const Progress& progress);
std::optional<ResidualFinding> CheckNightPairOffset(const SensorResiduals& r,
                                                    const Progress& progress);
std::optional<ResidualFinding> CheckFlowScale(const SensorResiduals& r, const Progress& progress);

// A fault model y(i) = g·x(i) fitted by least squares over the rows with
// flow from the solar day from_s on: g = Σ x·y / Σ x² and the mean of
// (y − g·x)² (both NaN without any row). Every fault model is compared at
// its own best size, so that the competition between two of them is fair.
struct FaultFit {
  double g = std::nan("");
  double mse = std::nan("");
};
FaultFit FitFault(const SensorResiduals& r, std::int64_t from_s,
                  const std::function<double(std::uint32_t)>& x,
                  const std::function<double(std::uint32_t)>& y);

// A finding of `channel` and `kind` from the solar day `from_s` (written
// `from`) on, of `size` in K, with the rows from that day on and their share
// of the data.
SensorFinding FindingFrom(const Series& data, std::string channel, std::string kind,
                          std::int64_t from_s, std::string from, double size);

}  // namespace pvtwin::diagnosis_stages
