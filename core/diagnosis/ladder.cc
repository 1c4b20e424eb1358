#include <algorithm>
#include <tuple>
#include <utility>

#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

namespace {

// The significant trial with the largest shrink; trials.size() if none.
std::size_t BestSignificant(const std::vector<EffectTrial>& trials) {
  std::size_t best = trials.size();
  for (std::size_t k = 0; k < trials.size(); ++k) {
    if (!trials[k].significant) continue;
    if (best == trials.size() || trials[k].shrink_pct > trials[best].shrink_pct) best = k;
  }
  return best;
}

// The significant trials whose held-out loss the loss test cannot tell
// from the best one's (p > alpha that the best is better): the data cannot
// separate them.
std::vector<std::size_t> Ties(const TrialInputs& in, const StepTrials& st, std::size_t best) {
  std::vector<std::size_t> tied;
  for (std::size_t k = 0; k < st.trials.size(); ++k) {
    if (k == best || !st.trials[k].significant) continue;
    const LossDifferenceTest t = CompareLosses(st.scores[k], st.scores[best], in.base->heldout,
                                               in.options->loss_test_bandwidth_s);
    if (t.p > in.options->alpha) tied.push_back(k);
  }
  return tied;
}

// Records the accepted trial: in the effects list (which keeps, for an
// effect accepted after step 1, its first evidence and its trial at that
// step) and as a ladder step.
void Accept(int step, const EffectTrial& chosen, const Score& score, DiagnosisResult* result) {
  DiagnosisResult& r = *result;
  bool replaced = false;
  for (EffectTrial& e : r.effects) {
    if (e.name == chosen.name) {
      const PartialCorrelation ev_corr = e.evidence_corr;
      const std::string ev_out = e.evidence_output;
      const std::string first_evidence = e.evidence;
      e = chosen;
      if (step > 1) {
        e.evidence_corr = ev_corr;
        e.evidence_output = ev_out;
        e.evidence = first_evidence.substr(0, first_evidence.find("; ") + 2) + chosen.evidence;
      }
      replaced = true;
    }
  }
  if (!replaced) r.effects.push_back(chosen);
  LadderStep ls;
  ls.variant = chosen.variant;
  ls.added = chosen.name;
  ls.heldout = score.errors;
  ls.heldout_mae_w = MaeSumW(score.errors);
  ls.objective_w_m2 = score.errors.objective_w_m2();
  ls.shrink_pct = chosen.shrink_pct;
  ls.p_value = chosen.test.wilcoxon_p;
  ls.loss_test_p = chosen.heldout_test.p;
  ls.params = chosen.params;
  r.ladder.push_back(ls);
}

// Accepted effects in ladder order, then significant ones, then by shrink.
void RankEffects(std::vector<EffectTrial>* effects) {
  std::stable_sort(effects->begin(), effects->end(),
                   [](const EffectTrial& a, const EffectTrial& b) {
                     auto key = [](const EffectTrial& t) {
                       return std::tuple(t.accepted_at_step > 0 ? 0 : 1,
                                         t.accepted_at_step > 0 ? t.accepted_at_step : 0,
                                         t.significant ? 0 : 1, t.fit_ok ? -t.shrink_pct : 1e300);
                     };
                     return key(a) < key(b);
                   });
}

}  // namespace

LadderModel RunLadder(const TrialInputs& in, const ModelSpec& base, DiagnosisResult* result) {
  DiagnosisResult& r = *result;
  LadderModel current;
  current.spec = base;
  current.params = in.base->params;
  current.score = in.base->score;
  for (int step = 1; step <= in.options->max_ladder_steps; ++step) {
    StepTrials st = TryCandidates(in, step, current);
    if (step == 1) r.skipped = st.skipped;
    if (st.candidates.empty()) break;
    r.identifications += static_cast<int>(st.candidates.size());
    const std::size_t best = BestSignificant(st.trials);
    if (step == 1) r.effects = st.trials;
    if (best == st.trials.size()) break;
    const std::vector<std::size_t> tied = Ties(in, st, best);
    if (!tied.empty()) {
      r.candidates.push_back(st.trials[best].name);
      for (const std::size_t k : tied) r.candidates.push_back(st.trials[k].name);
      in.progress("undecided at step " + std::to_string(step) + ": the data cannot separate " +
                  std::to_string(r.candidates.size()) + " effects");
      break;
    }
    EffectTrial& chosen = st.trials[best];
    chosen.accepted_at_step = step;
    Accept(step, chosen, st.scores[best], &r);
    current.spec = st.candidates[best].spec;
    current.params = chosen.params;
    current.score = std::move(st.scores[best]);
    in.progress("accepted +" + chosen.name + ": " + chosen.variant);
  }
  r.final_variant = current.spec.Name();
  RankEffects(&r.effects);
  return current;
}

}  // namespace pvtwin::diagnosis_stages
