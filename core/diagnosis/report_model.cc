#include <cmath>

#include "core/common/calendar.h"
#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

namespace {

// The held-out rows as the report plots them: measured, base and final
// model, and the regime drivers of their x axes.
void BuildTrace(const Split& split, const BaseFit& base, const BaseResiduals& residuals,
                const LadderModel& final_model, DiagnosisTrace* trace) {
  const Series& heldout_series = split.heldout_series;
  const Part& base_heldout = base.heldout;
  const Score& base_score = base.score;
  const Score& current_score = final_model.score;
  DiagnosisTrace& tr = *trace;
  const std::vector<RegimeDriver>& rg = residuals.regimes;
  auto driver_values = [&rg](const std::string& name, bool second) -> const std::vector<double>* {
    for (const RegimeDriver& d : rg) {
      if (d.name == name) return second ? &d.values2 : &d.values;
    }
    return nullptr;
  };
  const std::vector<double>* hour = driver_values("hour_of_day", false);
  const std::vector<double>* aoi = driver_values("aoi_deg", false);
  const std::vector<double>* az = driver_values("sun_azimuth_deg", false);
  const std::vector<double>* el = driver_values("sun_azimuth_deg", true);
  for (std::uint32_t i : base_heldout.meas.rows) {
    tr.time_s.push_back(heldout_series.time_s[i]);
    tr.p_el_meas_w.push_back(base_heldout.meas.p_el_w[i]);
    tr.q_th_meas_w.push_back(base_heldout.meas.q_th_w[i]);
    tr.p_el_base_w.push_back(base_score.sim.p_el_w[i]);
    tr.q_th_base_w.push_back(base_score.sim.q_th_w[i]);
    tr.p_el_final_w.push_back(current_score.sim.p_el_w[i]);
    tr.q_th_final_w.push_back(current_score.sim.q_th_w[i]);
    tr.hour_of_day.push_back(hour ? (*hour)[i] : kNaN);
    tr.aoi_deg.push_back(aoi ? (*aoi)[i] : kNaN);
    tr.sun_azimuth_deg.push_back(az ? (*az)[i] : kNaN);
    tr.sun_elevation_deg.push_back(el ? (*el)[i] : kNaN);
  }
}

// Per day of data: its date, rows, and the base and final model's held-out
// objective.
void BuildDays(const Split& split, const BaseFit& base, const LadderModel& final_model,
               double area_m2, std::vector<DiagnosisDay>* days) {
  const Series& train_series = split.train_series;
  const Series& heldout_series = split.heldout_series;
  const int first_heldout = split.FirstHeldoutDay();
  const int heldout_days = split.heldout_days;
  const std::vector<std::int64_t>& day_starts = split.day_starts;
  const std::int64_t offset_s = split.offset_s;
  const Part& base_train = base.train;
  const Part& base_heldout = base.heldout;
  const Score& base_score = base.score;
  const Score& current_score = final_model.score;
  for (int k = 0; k < first_heldout + heldout_days; ++k) {
    DiagnosisDay day;
    day.start_s = day_starts[static_cast<std::size_t>(k)];
    day.date = SolarDate(day.start_s, offset_s);
    day.heldout = k >= first_heldout;
    const Measurements& m = day.heldout ? base_heldout.meas : base_train.meas;
    const Series& s = day.heldout ? heldout_series : train_series;
    double base_sum = 0.0, final_sum = 0.0;
    for (std::uint32_t i : m.rows) {
      if (SolarDayStartS(s.time_s[i], offset_s) != day.start_s) continue;
      ++day.rows;
      if (day.heldout) {
        base_sum += std::fabs(base_score.sim.p_el_w[i] - m.p_el_w[i]) +
                    std::fabs(base_score.sim.q_th_w[i] - m.q_th_w[i]);
        final_sum += std::fabs(current_score.sim.p_el_w[i] - m.p_el_w[i]) +
                     std::fabs(current_score.sim.q_th_w[i] - m.q_th_w[i]);
      }
    }
    if (day.heldout) {
      day.base_objective_w_m2 =
          day.rows ? base_sum / static_cast<double>(day.rows) / area_m2 : kNaN;
      day.final_objective_w_m2 =
          day.rows ? final_sum / static_cast<double>(day.rows) / area_m2 : kNaN;
    }
    days->push_back(day);
  }
}

}  // namespace

void BuildReportModel(const Split& split, const BaseFit& base, const BaseResiduals& residuals,
                      const LadderModel& final_model, double area_m2, DiagnosisResult* r) {
  BuildTrace(split, base, residuals, final_model, &r->trace);
  BuildDays(split, base, final_model, area_m2, &r->days);
}

}  // namespace pvtwin::diagnosis_stages
