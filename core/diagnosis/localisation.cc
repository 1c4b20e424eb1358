#include <algorithm>
#include <utility>

#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

BaseResiduals LocaliseBaseGap(const Split& split, const BaseFit& base, const Plant& plant,
                              const DiagnosisOptions& options, DiagnosisResult* result) {
  DiagnosisResult& r = *result;
  const Series& heldout_series = split.heldout_series;
  const Part& base_heldout = base.heldout;
  const Score& base_score = base.score;
  BaseResiduals out;
  out.regimes = StandardRegimeDrivers(heldout_series, base_heldout.drivers, plant);
  out.p_el_w = Residual(base_heldout.meas, base_score.sim.p_el_w, base_heldout.meas.p_el_w);
  out.q_th_w = Residual(base_heldout.meas, base_score.sim.q_th_w, base_heldout.meas.q_th_w);
  for (const auto& [res, name] : {std::pair{&out.p_el_w, "p_el"}, std::pair{&out.q_th_w, "q_th"}}) {
    const Localisation loc =
        LocaliseGap(heldout_series.time_s, *res, name, out.regimes, options.where);
    r.where.insert(r.where.end(), loc.regions.begin(), loc.regions.end());
    r.where_bins.insert(r.where_bins.end(), loc.bins.begin(), loc.bins.end());
  }
  std::stable_sort(r.where.begin(), r.where.end(), [](const GapRegion& a, const GapRegion& b) {
    return a.share_of_abs_error - a.share_of_rows > b.share_of_abs_error - b.share_of_rows;
  });
  return out;
}

}  // namespace pvtwin::diagnosis_stages
