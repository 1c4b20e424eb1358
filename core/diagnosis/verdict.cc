#include <sstream>

#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

// The first accepted effect; else "unknown" when the final held-out
// objective exceeds unknown_noise_ratio × the noise floor (a gap no
// catalogued effect removes; `where` locates it); else "none". Each with
// its sentence.
void DecideVerdict(const DiagnosisOptions& options, DiagnosisResult* result) {
  DiagnosisResult& r = *result;
  const LadderStep& last = r.ladder.back();
  const LadderStep& first = r.ladder.front();
  if (r.ladder.size() > 1) {
    r.verdict = r.ladder[1].added;
    const EffectTrial* top = nullptr;
    for (const EffectTrial& t : r.effects) {
      if (t.name == r.verdict) top = &t;
    }
    std::ostringstream s;
    s << "The model " << r.base_variant << " misses " << r.verdict
      << ": adding it and re-identifying "
      << "cuts the held-out error (MAE P_el + Q_u) by " << FixedDecimals(r.ladder[1].shrink_pct, 1)
      << " %, from " << FixedDecimals(first.heldout_mae_w, 1) << " W to "
      << FixedDecimals(r.ladder[1].heldout_mae_w, 1) << " W";
    if (top != nullptr) {
      s << ", lower on " << top->test.positives << " of " << top->test.pairs << " held-out "
        << r.test_unit << "s (Wilcoxon p = " << PValue(top->test.wilcoxon_p) << ")";
    }
    s << ".";
    if (r.ladder.size() > 2) {
      s << " Then";
      for (std::size_t k = 2; k < r.ladder.size(); ++k) {
        s << (k > 2 ? "," : "") << " +" << r.ladder[k].added << " (−"
          << FixedDecimals(r.ladder[k].shrink_pct, 1) << " %)";
      }
      s << ", ending at " << FixedDecimals(last.heldout_mae_w, 1) << " W with " << r.final_variant
        << ".";
    }
    if (r.low_confidence) s << " Low confidence: too few held-out days.";
    r.verdict_sentence = s.str();
  } else if (r.noise.ratio > options.unknown_noise_ratio) {
    r.verdict = "unknown";
    std::ostringstream s;
    s << "The held-out error of " << r.base_variant << " (" << FixedDecimals(first.heldout_mae_w, 1)
      << " W, MAE P_el + Q_u) is " << FixedDecimals(r.noise.ratio, 1)
      << "× what sensor noise explains, but no catalogued effect removes it consistently";
    if (!r.where.empty()) {
      const GapRegion& w = r.where.front();
      s << "; it concentrates where " << w.driver << " is in [" << FixedDecimals(w.lower, 1) << ", "
        << FixedDecimals(w.upper, 1) << ")";
      if (!w.label.empty()) s << " (" << w.label << ")";
      if (!w.driver2.empty()) {
        s << " and " << w.driver2 << " in [" << FixedDecimals(w.lower2, 1) << ", "
          << FixedDecimals(w.upper2, 1) << ")";
      }
      s << ": " << FixedDecimals(100.0 * w.share_of_abs_error, 0) << " % of the "
        << (w.output == "q_th" ? "Q_u" : "P_el") << " error in "
        << FixedDecimals(100.0 * w.share_of_rows, 0) << " % of the rows";
    }
    s << ".";
    r.verdict_sentence = s.str();
  } else {
    r.verdict = "none";
    r.verdict_sentence = "No catalogued effect lowers the held-out error of " + r.base_variant +
                         " consistently; its held-out error (" +
                         FixedDecimals(first.heldout_mae_w, 1) + " W, MAE P_el + Q_u) is " +
                         FixedDecimals(r.noise.ratio, 1) + "× the sensor-noise floor.";
  }
}

}  // namespace pvtwin::diagnosis_stages
