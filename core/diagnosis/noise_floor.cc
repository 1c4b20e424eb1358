#include <cmath>

#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

// The MAE that sensor noise alone gives, from the second differences of the
// final model's held-out residuals (NoiseMaeFromSecondDifferences), per
// output; rows of one gap-free segment share a segment key.
bool EstimateNoiseFloor(const Split& split, const Plant& plant, const LadderModel& final_model,
                        DiagnosisResult* result, std::string* error) {
  DiagnosisResult& r = *result;
  const Series& heldout_series = split.heldout_series;
  const Score& current_score = final_model.score;
  const double area_m2 = plant.area_m2;
  Part final_heldout;
  std::string why;
  if (!PreparePart(heldout_series, plant, final_model.spec, split.data_start_s, split.cleanings,
                   &final_heldout, &why)) {
    *error = "internal: final model " + r.final_variant + ": " + why;
    return false;
  }
  const std::vector<double> fp =
      Residual(final_heldout.meas, current_score.sim.p_el_w, final_heldout.meas.p_el_w);
  const std::vector<double> fq =
      Residual(final_heldout.meas, current_score.sim.q_th_w, final_heldout.meas.q_th_w);
  std::vector<std::int64_t> segment(heldout_series.size());
  const double step = heldout_series.step_s > 0.0 ? heldout_series.step_s : 1.0;
  for (std::size_t i = 0; i < segment.size(); ++i) {
    segment[i] = heldout_series.time_s[i] -
                 static_cast<std::int64_t>(std::llround(static_cast<double>(i) * step));
  }
  r.noise.mae_p_el_w = NoiseMaeFromSecondDifferences(fp, segment);
  r.noise.mae_q_th_w = NoiseMaeFromSecondDifferences(fq, segment);
  r.noise.objective_w_m2 = (r.noise.mae_p_el_w + r.noise.mae_q_th_w) / area_m2;
  r.noise.ratio = current_score.errors.objective_w_m2() / r.noise.objective_w_m2;
  return true;
}

}  // namespace pvtwin::diagnosis_stages
