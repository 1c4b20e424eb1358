#include <cmath>
#include <sstream>

#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

namespace {

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t k = 0; k < names.size(); ++k) {
    out += (k == 0 ? "" : k + 1 == names.size() ? " and " : ", ") + names[k];
  }
  return out;
}

// " The held-out days lie outside …" when drivers are extrapolated, else "".
std::string ExtrapolationSentence(const DiagnosisResult& r) {
  if (r.extrapolation.empty()) return "";
  std::ostringstream s;
  s << " The held-out days lie outside the training days' range of ";
  for (std::size_t k = 0; k < r.extrapolation.size(); ++k) {
    const Extrapolation& e = r.extrapolation[k];
    s << (k == 0                            ? ""
          : k + 1 == r.extrapolation.size() ? " and "
                                            : ", ")
      << e.driver << " (" << FixedDecimals(100.0 * e.share_outside, 0) << " % of the rows outside ["
      << FixedDecimals(e.train_low, 1) << ", " << FixedDecimals(e.train_high, 1) << "], held-out ["
      << FixedDecimals(e.heldout_low, 1) << ", " << FixedDecimals(e.heldout_high, 1) << "])";
  }
  s << ": the parameters that act there are not determined by the training data, a likely "
       "cause of the gap rather than a missing effect.";
  return s.str();
}

}  // namespace

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
      if (top->sensor_fault && top->confidence < options.min_confidence) {
        s << " (a sensor fault, named by its sensor test: "
          << "p = " << PValue(top->sensor_p) << " over " << top->sensor_days << " days)";
      } else {
        s << " (confidence " << FixedDecimals(100.0 * top->confidence, 1)
          << " %: the best candidate in that share of the resampled held-out " << r.test_unit
          << "s; held-out loss test p = " << PValue(top->heldout_test.p) << ", better on "
          << top->days_improved << " held-out day(s))";
      }
      if (!top->signature_check.empty()) s << "; " << top->signature_check;
      for (const std::string& c : top->cautions) s << "; against it: " << c;
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
    if (!r.candidates.empty()) {
      s << " The next step is undecided between " << JoinNames(r.candidates) << ".";
    }
    if (r.low_confidence) s << " Low confidence: too few held-out days.";
    r.verdict_sentence = s.str();
  } else if (!r.candidates.empty()) {
    r.verdict = "undecided";
    r.verdict_sentence = "Adding " + JoinNames(r.candidates) + " to " + r.base_variant +
                         " lowers its held-out error (" + FixedDecimals(first.heldout_mae_w, 1) +
                         " W, MAE P_el + Q_u), but neither is the best with " +
                         FixedDecimals(100.0 * options.min_confidence, 0) +
                         " % confidence over the resampled held-out " + r.test_unit +
                         "s: the data do not say which effect is missing. " + r.separation + "." +
                         ExtrapolationSentence(r);
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
    s << "." << ExtrapolationSentence(r);
    r.verdict_sentence = s.str();
  } else {
    r.verdict = "none";
    r.verdict_sentence = "No catalogued effect lowers the held-out error of " + r.base_variant +
                         " consistently; its held-out error (" +
                         FixedDecimals(first.heldout_mae_w, 1) + " W, MAE P_el + Q_u) is " +
                         FixedDecimals(r.noise.ratio, 1) + "× the sensor-noise floor." +
                         ExtrapolationSentence(r);
  }
  for (const SensorFinding& f : r.sensors) {
    r.verdict_sentence +=
        " Sensor check: " + f.channel + " " + f.kind +
        (f.from.empty() ? std::string() : " from " + f.from) + " on " + std::to_string(f.rows) +
        " rows (" + FixedDecimals(100.0 * f.share, 1) + " % of the data" +
        (std::isfinite(f.size) ? (f.from.empty() ? ", median " : ", size ") + SensorSizeText(f)
                               : std::string()) +
        ").";
  }
}

}  // namespace pvtwin::diagnosis_stages
