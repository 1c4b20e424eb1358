#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <utility>

#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

namespace {

// The model selection of one ladder step over the held-out test units
// (DiagnosisOptions::min_confidence): each trial's confidence and
// confidence_beats, and the share of resamples in which any trial beats the
// current model by min_shrink_pct. The objective of a resample is the pooled
// held-out objective of its units (sum of |e_P_el| + |e_Q_u| over their rows
// / their rows), so with every unit once it is the paper's objective; with
// DiagnosisOptions::selection_outputs one output's |e| instead.
double Confidences(const TrialInputs& in, int step, const Score& current, StepTrials* st) {
  const DiagnosisOptions& o = *in.options;
  const Units& unit_of = in.base->units;
  const auto units = static_cast<std::size_t>(unit_of.count);
  // Where the held-out drivers leave the training range, the base model's
  // parameters that act there are not determined by the training days and
  // any extra freedom can shift its bias: the selection then scores the
  // held-out rows inside the training range only (all rows otherwise).
  std::vector<std::uint8_t> inside;
  if (in.extrapolation != nullptr && !in.extrapolation->empty()) {
    inside = RowsInsideTrainingRange(in.base->heldout.drivers, *in.extrapolation);
  }
  // Per model (the current one last) and unit: loss sum and rows.
  struct UnitLoss {
    std::vector<double> loss, rows;
  };
  const Loss which = SelectionLoss(o);
  auto per_unit = [&](const Score& s) {
    UnitLoss u{std::vector<double>(units, 0.0), std::vector<double>(units, 0.0)};
    const std::vector<double>& loss = LossOf(s, which);
    for (std::size_t i = 0; i < loss.size() && i < unit_of.unit_of_row.size(); ++i) {
      const int k = unit_of.unit_of_row[i];
      if (k < 0 || !std::isfinite(loss[i]) || (!inside.empty() && inside[i] == 0)) continue;
      u.loss[static_cast<std::size_t>(k)] += loss[i];
      u.rows[static_cast<std::size_t>(k)] += 1.0;
    }
    return u;
  };
  // Per trial, every form that was scored: the form is chosen again in each
  // resample (the lowest objective of its forms), so that the confidence
  // holds the choice of the form as well as that of the effect.
  // With reference days, beside each form: the form with its own parameters
  // as the plant before the change had them (an empty UnitLoss: none). The
  // form's objective in a resample then counts only its gain beyond the
  // better of that and the current model (DiagnosisOptions::reference_days).
  std::vector<std::size_t> pool;
  std::vector<std::vector<UnitLoss>> losses(st->trials.size());
  std::vector<std::vector<UnitLoss>> before_change(st->trials.size());
  for (std::size_t k = 0; k < st->trials.size(); ++k) {
    st->trials[k].confidence = 0.0;
    st->trials[k].confidence_beats = 0.0;
    if (!st->trials[k].fit_ok) continue;
    std::vector<const Score*> forms = {&st->scores[k]};
    std::vector<const Score*> forms_before(1, nullptr);
    if (k < st->form_scores.size() && !st->form_scores[k].empty()) {
      forms.clear();
      forms_before.clear();
      for (std::size_t j = 0; j < st->form_scores[k].size(); ++j) {
        forms.push_back(&st->form_scores[k][j]);
        forms_before.push_back(
            j < st->before_change_scores[k].size() ? &st->before_change_scores[k][j] : nullptr);
      }
    }
    for (std::size_t j = 0; j < forms.size(); ++j) {
      if (forms[j]->loss_w.size() != current.loss_w.size()) continue;
      losses[k].push_back(per_unit(*forms[j]));
      const Score* b = forms_before[j];
      before_change[k].push_back(
          b != nullptr && b->loss_w.size() == current.loss_w.size() ? per_unit(*b) : UnitLoss{});
    }
    if (!losses[k].empty()) pool.push_back(k);
  }
  const UnitLoss before_loss = per_unit(current);
  if (units == 0 || pool.empty()) return 0.0;
  std::mt19937_64 rng(o.bootstrap_seed + static_cast<std::uint64_t>(step));
  std::uniform_int_distribution<std::size_t> draw(0, units - 1);
  std::vector<double> weight(units);
  std::vector<int> wins(st->trials.size(), 0), beats(st->trials.size(), 0);
  int any = 0;
  const double keep = 1.0 - o.min_shrink_pct / 100.0;
  auto objective = [&weight, units](const UnitLoss& s) {
    double loss = 0.0, rows = 0.0;
    for (std::size_t u = 0; u < units; ++u) {
      if (weight[u] == 0.0 || s.rows[u] == 0.0) continue;
      loss += weight[u] * s.loss[u];
      rows += weight[u] * s.rows[u];
    }
    return rows > 0.0 ? loss / rows : std::nan("");
  };
  for (int b = 0; b < o.bootstrap_resamples; ++b) {
    std::fill(weight.begin(), weight.end(), 0.0);
    for (std::size_t u = 0; u < units; ++u) weight[draw(rng)] += 1.0;
    const double before = objective(before_loss);
    if (!(before > 0.0)) continue;
    std::size_t best = st->trials.size();
    double best_objective = 0.0;
    for (const std::size_t k : pool) {
      double after = std::nan("");
      for (std::size_t j = 0; j < losses[k].size(); ++j) {
        double o = objective(losses[k][j]);
        if (!before_change[k][j].loss.empty()) {
          o = CountedObjective(o, before, objective(before_change[k][j]));
        }
        if (!std::isnan(o) && !(o >= after)) after = o;  // the lowest finite
      }
      if (!(after <= keep * before)) continue;
      ++beats[k];
      if (best == st->trials.size() || after < best_objective) {
        best = k;
        best_objective = after;
      }
    }
    if (best == st->trials.size()) continue;
    ++wins[best];
    ++any;
  }
  const double n = static_cast<double>(o.bootstrap_resamples);
  for (const std::size_t k : pool) {
    st->trials[k].confidence = wins[k] / n;
    st->trials[k].confidence_beats = beats[k] / n;
  }
  return any / n;
}

// The decision of one step: a sensor fault its sensor test found; else the
// candidate the resampling names with min_confidence; else, when the
// candidates together beat the current model with min_confidence, the two
// most confident (undecided); else none.
struct StepDecision {
  std::size_t chosen;                  // st.trials.size() = none
  std::vector<std::size_t> undecided;  // the two most confident, when undecided
};
StepDecision Decide(const DiagnosisOptions& o, double any_share, StepTrials* st) {
  const std::size_t none = st->trials.size();
  StepDecision d{none, {}};
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < st->trials.size(); ++k) {
    EffectTrial& t = st->trials[k];
    t.significant = t.sensor_fault || (t.fit_ok && t.confidence_beats >= o.min_confidence);
    order.push_back(k);
  }
  std::stable_sort(order.begin(), order.end(), [st](std::size_t a, std::size_t b) {
    return st->trials[a].confidence > st->trials[b].confidence;
  });
  // A sensor fault its own test found comes first: every candidate is
  // fitted to the faulty reading, and one that bends to it (a modifier that
  // absorbs a pyranometer's cosine error) is no evidence of its effect.
  for (std::size_t k = 0; k < st->trials.size(); ++k) {
    const EffectTrial& t = st->trials[k];
    if (t.sensor_fault && (d.chosen == none || t.sensor_p < st->trials[d.chosen].sensor_p)) {
      d.chosen = k;
    }
  }
  if (d.chosen == none && !order.empty() && st->trials[order[0]].confidence >= o.min_confidence) {
    d.chosen = order[0];
  } else if (d.chosen == none && any_share >= o.min_confidence && order.size() >= 2) {
    d.undecided = {order[0], order[1]};
  }
  for (std::size_t k = 0; k < st->trials.size(); ++k) {
    EffectTrial& t = st->trials[k];
    if (k == d.chosen || !t.fit_ok || t.confidence_beats == 0.0) continue;
    t.rejected =
        "best in " + FixedDecimals(100.0 * t.confidence, 1) +
        " % of the resamples of the held-out units (better than the model by min_shrink_pct in " +
        FixedDecimals(100.0 * t.confidence_beats, 1) + " %), below " +
        FixedDecimals(100.0 * o.min_confidence, 0) + " %";
  }
  return d;
}

// What would separate two candidates the data cannot tell apart: how each
// splits its gain over the outputs, and on how many held-out units the
// first is better.
std::string Separation(const StepTrials& st, std::size_t a, std::size_t b) {
  const EffectTrial& ta = st.trials[a];
  const EffectTrial& tb = st.trials[b];
  const Score& sa = st.scores[a];
  const Score& sb = st.scores[b];
  int better = 0, units = 0;
  for (std::size_t u = 0; u < sa.unit_loss_w.size() && u < sb.unit_loss_w.size(); ++u) {
    if (sa.unit_rows[u] == 0.0) continue;
    ++units;
    better += sa.unit_loss_w[u] < sb.unit_loss_w[u] ? 1 : 0;
  }
  auto split = [](const EffectTrial& t) {
    return t.name + " changes MAE P_el by " +
           FixedDecimals(t.mae_p_el_after_w - t.mae_p_el_before_w, 2) + " W and Q_u by " +
           FixedDecimals(t.mae_q_th_after_w - t.mae_q_th_before_w, 2) + " W (confidence " +
           FixedDecimals(100.0 * t.confidence, 0) + " %)";
  };
  return split(ta) + ", " + split(tb) + "; " + ta.name + " is better on " + std::to_string(better) +
         " of " + std::to_string(units) +
         " held-out units: more held-out days, above all of the kind where they differ, would "
         "separate them";
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
  current.fold_params.assign(static_cast<std::size_t>(in.split->folds), in.base->params);
  if (in.extrapolation != nullptr && !in.extrapolation->empty()) {
    const std::vector<std::uint8_t> inside =
        RowsInsideTrainingRange(in.base->heldout.drivers, *in.extrapolation);
    std::size_t n_inside = 0;
    for (std::uint32_t i : in.base->heldout.meas.rows) n_inside += inside[i];
    r.notes.push_back("the model selection scores the " + std::to_string(n_inside) + " of " +
                      std::to_string(in.base->heldout.meas.rows.size()) +
                      " held-out rows inside the training range only: outside it the base "
                      "model's parameters that act there are not determined by the training "
                      "days");
  }
  // The forms' fits on the reference days at the first step, for the later ones.
  std::map<std::string, ParamVector> before_change;
  TrialInputs step_in = in;
  // DiagnosisOptions::selection_outputs names the output a change showed
  // on: the first step's effect is what explains it. What a later step adds
  // explains the rest of the gap, which no alarm dated: it is judged as any
  // diagnosis is, on the paper's objective of both outputs.
  DiagnosisOptions later_steps = *in.options;
  later_steps.selection_outputs = SelectionOutputs::kBoth;
  for (int step = 1; step <= in.options->max_ladder_steps; ++step) {
    StepTrials st = TryCandidates(step_in, step, current);
    if (step == 1 && in.reference != nullptr) {
      for (const auto& fits : st.before_change_fits) {
        before_change.insert(fits.begin(), fits.end());
        r.identifications += static_cast<int>(fits.size());
      }
      step_in.before_change = &before_change;
    }
    if (step == 1) r.skipped = st.skipped;
    if (st.candidates.empty()) break;
    r.identifications += static_cast<int>(st.candidates.size());
    const double any_share = Confidences(step_in, step, current.score, &st);
    const StepDecision decision = Decide(*in.options, any_share, &st);
    for (EffectTrial& t : st.trials) {
      if (t.fit_ok) {
        t.evidence += "; model selection over resampled held-out " + in.test_unit + "s: best and " +
                      FixedDecimals(in.options->min_shrink_pct, 1) + " % better than " +
                      t.tested_against + " in " + FixedDecimals(100.0 * t.confidence, 1) +
                      " %, better by that in " + FixedDecimals(100.0 * t.confidence_beats, 1) +
                      " %";
      }
    }
    if (step == 1) r.effects = st.trials;
    const std::size_t best = decision.chosen;
    if (!decision.undecided.empty()) {
      const std::size_t a = decision.undecided[0], b = decision.undecided[1];
      r.candidates.push_back(st.trials[a].name);
      r.candidates.push_back(st.trials[b].name);
      r.separation = Separation(st, a, b);
      in.progress("undecided at step " + std::to_string(step) + " between " + st.trials[a].name +
                  " and " + st.trials[b].name);
      break;
    }
    if (best == st.trials.size()) break;
    step_in.options = &later_steps;
    EffectTrial& chosen = st.trials[best];
    chosen.accepted_at_step = step;
    Accept(step, chosen, st.scores[best], &r);
    current.spec = st.candidates[best].spec;
    current.params = chosen.params;
    current.score = std::move(st.scores[best]);
    current.fold_params = std::move(st.fold_params[best]);
    in.progress("accepted +" + chosen.name + ": " + chosen.variant);
  }
  r.final_variant = current.spec.Name();
  RankEffects(&r.effects);
  return current;
}

}  // namespace pvtwin::diagnosis_stages
