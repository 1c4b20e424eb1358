#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <utility>

#include "core/common/calendar.h"
#include "core/common/threads.h"
#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

namespace {

// Start values for `spec`: the reference values, overwritten by `fitted`
// for every parameter the fitted model used.
ParamVector MergedStart(const Plant& plant, const ModelSpec& fitted_spec,
                        const ParamVector& fitted) {
  ParamVector start = StartParams(plant);
  const std::bitset<kNumParams> used = UsedParams(fitted_spec);
  for (std::size_t p = 0; p < kNumParams; ++p) {
    if (used.test(p)) start[p] = fitted[p];
  }
  return start;
}

// The sensor test of a sensor fault (EffectModule::sensor_estimate, see
// EffectTrial): its size estimated on each day of data.
void SensorTest(const Series& data, const std::vector<std::int64_t>& day_starts, const Plant& plant,
                const ModelSpec& spec, const EffectModule& effect, EffectTrial* t) {
  std::vector<double> k;
  for (std::int64_t day : day_starts) {
    const std::size_t lo = data.RowAtOrAfter(day);
    const std::size_t hi = data.RowAtOrAfter(day + kSecondsPerDay);
    Drivers d;
    std::string why;
    if (hi <= lo || !PrepareDrivers(data.Slice(lo, hi), plant, spec, &d, &why)) continue;
    const double kd = effect.sensor_estimate(d);
    if (std::isfinite(kd)) k.push_back(kd);
  }
  if (k.size() < 3) return;
  std::vector<double> sorted = k;
  std::sort(sorted.begin(), sorted.end());
  t->sensor_estimate = sorted[sorted.size() / 2];
  const std::vector<double> zeros(k.size(), 0.0);
  const PairedTest up = OneSidedPairedTest(k, zeros);
  const PairedTest down = OneSidedPairedTest(zeros, k);
  t->sensor_p = std::min(1.0, 2.0 * std::min(up.wilcoxon_p, down.wilcoxon_p));
  t->sensor_days = static_cast<int>(k.size());
}

// "ε_PVT at its lower bound 0.075" for each of the effect's parameters that
// ended at a bound, "n_flow = 0.079 ± 0.25 (not determined)" for each whose
// standard error is as large as its value (or that the fit found
// undetermined); *all set when every one of them is either (the data did
// not determine the effect). Only the parameters of the fitted form (spec)
// count: wind's "+wind" leaves the paper form's r_refwind untouched.
std::vector<std::string> AtBounds(const EffectModule& effect, const ModelSpec& spec,
                                  const EffectTrial& t, const Plant& plant, bool* all) {
  std::vector<std::string> out;
  std::size_t unsupported = 0, used_params = 0;
  const std::bitset<kNumParams> used = UsedParams(spec);
  for (const Param param : effect.params) {
    if (!used.test(static_cast<std::size_t>(param))) continue;
    ++used_params;
    // The range the fit searched: Table 3's, or the physical range of a re-fit.
    ParamInfo info = ResolvedInfo(param, plant);
    for (const ParamEstimate& e : t.estimates) {
      if (e.param != param) continue;
      info.lower = e.lower;
      info.upper = e.upper;
    }
    const double v = ParamOf(t.params, param);
    const double tol = 1e-3 * (info.upper - info.lower);
    if (v <= info.lower + tol) {
      out.push_back(std::string(info.symbol) + " at its lower bound " +
                    FixedDecimals(info.lower, 3));
      ++unsupported;
      continue;
    }
    if (v >= info.upper - tol) {
      out.push_back(std::string(info.symbol) + " at its upper bound " +
                    FixedDecimals(info.upper, 3));
      ++unsupported;
      continue;
    }
    for (const ParamEstimate& e : t.estimates) {
      if (e.param != param) continue;
      const double se = StdErrorInUnit(e);
      if (e.undetermined || e.weak || (std::isfinite(se) && se >= std::fabs(v))) {
        out.push_back(std::string(info.symbol) + " = " + FixedDecimals(v, 3) +
                      (std::isfinite(se) ? " ± " + FixedDecimals(se, 3) : "") +
                      " (not determined)");
        ++unsupported;
      }
    }
  }
  *all = used_params > 0 && unsupported == used_params;
  return out;
}

// Held-out solar days on which `after`'s loss is lower than `before`'s, of
// the days with rows in both.
int DaysImproved(const Score& before, const Score& after, const Part& heldout,
                 std::int64_t offset_s, int* days) {
  std::map<std::int64_t, double> gain;
  for (std::size_t i = 0; i < before.loss_w.size() && i < after.loss_w.size(); ++i) {
    const double g = before.loss_w[i] - after.loss_w[i];
    if (std::isfinite(g)) gain[SolarDayStartS(heldout.drivers.time_s[i], offset_s)] += g;
  }
  int better = 0;
  for (const auto& [day, g] : gain) better += g > 0.0 ? 1 : 0;
  *days = static_cast<int>(gain.size());
  return better;
}

// The evidence on a trial whose fit succeeded, next to its held-out score:
// the loss test, the split by output, the days it helps, parameters at a
// bound, a gain that is only a shift of the bias on extrapolated days, and
// the module's own signature. None of it decides: the ladder's model
// selection (ladder.cc) judges every candidate on the held-out objective
// (the sum of both outputs) resampled over the test units; what speaks
// against a candidate is listed in t.cautions beside its confidence.
void Judge(const TrialInputs& in, const EffectCandidate& c, const Part& ho, const Score& before,
           const Score& after, EffectTrial* trial) {
  EffectTrial& t = *trial;
  const DiagnosisOptions& o = *in.options;
  const double bw = o.loss_test_bandwidth_s;
  t.heldout_test = CompareLosses(before, after, ho, bw);
  t.mae_p_el_before_w = before.errors.mae_p_el_w;
  t.mae_q_th_before_w = before.errors.mae_q_th_w;
  t.mae_p_el_after_w = after.errors.mae_p_el_w;
  t.mae_q_th_after_w = after.errors.mae_q_th_w;
  int days = 0;
  t.days_improved = DaysImproved(before, after, ho, in.split->offset_s, &days);
  bool all_at_bounds = false;
  t.at_bounds = AtBounds(*c.module, c.spec, t, *in.plant, &all_at_bounds);
  std::vector<std::string> why;
  const struct {
    const char* name;
    Loss loss;
    double before_w, after_w;
  } outputs[] = {{"P_el", Loss::kPEl, t.mae_p_el_before_w, t.mae_p_el_after_w},
                 {"Q_u", Loss::kQTh, t.mae_q_th_before_w, t.mae_q_th_after_w}};
  for (const auto& out : outputs) {
    const LossDifferenceTest worse = CompareLosses(after, before, ho, bw, out.loss);
    if (worse.p <= o.alpha && out.after_w > out.before_w) {
      why.push_back("it makes " + std::string(out.name) + " worse (" +
                    FixedDecimals(out.before_w, 2) + " → " + FixedDecimals(out.after_w, 2) +
                    " W, p = " + PValue(worse.p) + "; judged on the sum)");
    }
  }
  // On held-out days outside the training range the base model's error is
  // mostly a bias that any extra freedom can shift; a gain that is nothing
  // but that shift is not the effect. An effect gains where the drivers stay
  // inside the training range too (where the base model is determined): a
  // gain there of at least half the gain outside, per row, clears it.
  if (in.extrapolation != nullptr && !in.extrapolation->empty()) {
    const double mae_drop =
        (t.mae_p_el_before_w - t.mae_p_el_after_w) + (t.mae_q_th_before_w - t.mae_q_th_after_w);
    const double bias_drop = (std::fabs(before.bias_p_el_w) - std::fabs(after.bias_p_el_w)) +
                             (std::fabs(before.bias_q_th_w) - std::fabs(after.bias_q_th_w));
    const std::vector<std::uint8_t> inside = RowsInsideTrainingRange(ho.drivers, *in.extrapolation);
    double gain_w[2] = {0.0, 0.0};  // outside, inside
    double rows[2] = {0.0, 0.0};
    for (std::uint32_t i : ho.meas.rows) {
      const double g = before.loss_w[i] - after.loss_w[i];
      if (!std::isfinite(g)) continue;
      gain_w[inside[i]] += g;
      rows[inside[i]] += 1.0;
    }
    const double gain_out = rows[0] > 0.0 ? gain_w[0] / rows[0] : 0.0;
    const double gain_in = rows[1] > 0.0 ? gain_w[1] / rows[1] : 0.0;
    const bool gains_inside =
        rows[1] >= 0.1 * (rows[0] + rows[1]) && gain_in > 0.0 && gain_in >= 0.5 * gain_out;
    if (mae_drop > 0.0 && bias_drop >= 0.8 * mae_drop && !gains_inside) {
      why.push_back(
          "its gain is a shift of the bias on held-out days outside the training "
          "range (bias P_el " +
          FixedDecimals(before.bias_p_el_w, 2) + " → " + FixedDecimals(after.bias_p_el_w, 2) +
          " W, Q_u " + FixedDecimals(before.bias_q_th_w, 2) + " → " +
          FixedDecimals(after.bias_q_th_w, 2) + " W; " + FixedDecimals(gain_out, 2) +
          " W per row outside the range, " +
          (rows[1] > 0.0 ? FixedDecimals(gain_in, 2) + " W inside)" : "no row inside)"));
    }
  }
  if (all_at_bounds) {
    std::string list;
    for (const std::string& b : t.at_bounds) list += (list.empty() ? "" : ", ") + b;
    why.push_back("the data do not determine it: " + list);
  }
  if (days >= 2 && t.days_improved < 2) {
    why.push_back("it is better on " + std::to_string(t.days_improved) + " of " +
                  std::to_string(days) + " held-out days only");
  }
  if (c.module->shows_signature != nullptr) {
    SignatureData sd;
    sd.drivers = &ho.drivers;
    sd.rows = &ho.meas.rows;
    sd.p_el_meas_w = &ho.meas.p_el_w;
    sd.q_th_meas_w = &ho.meas.q_th_w;
    sd.before = &before.sim;
    sd.after = &after.sim;
    sd.params = &t.params;
    const SignatureCheck check = c.module->shows_signature(sd);
    t.signature_check = check.sentence;
    if (!check.shown) why.push_back("its signature is missing: " + check.sentence);
  }
  t.cautions = std::move(why);
}

// The candidates of this step: every effect the current model can take with
// the data's channels, those the options select, given enough training days.
std::vector<EffectCandidate> SelectCandidates(const TrialInputs& in, const ModelSpec& current_spec,
                                              std::vector<SkippedEffect>* skipped_out) {
  const DiagnosisOptions& options = *in.options;
  const Series& data = *in.data;
  const int train_days = in.split->train_days;
  std::vector<SkippedEffect>& skipped = *skipped_out;
  std::vector<EffectCandidate> candidates = CandidateEffects(current_spec, data, &skipped);
  if (!options.effects.empty()) {
    std::erase_if(candidates, [&options](const EffectCandidate& c) {
      return std::find(options.effects.begin(), options.effects.end(), c.name) ==
             options.effects.end();
    });
  }
  // Against the plant before a change: only what can begin while the plant
  // runs can be what changed.
  if (options.reference_params) {
    std::erase_if(candidates, [&skipped](const EffectCandidate& c) {
      if (c.module->begins_in_operation) return false;
      skipped.push_back({c.name,
                         "a property of the collector's build, in the plant before the change "
                         "as after it: it cannot be what changed"});
      return true;
    });
  }
  // An effect that needs more training days than there are (a drift over days).
  std::erase_if(candidates, [&skipped, train_days](const EffectCandidate& c) {
    if (train_days >= c.module->min_train_days) return false;
    skipped.push_back({c.name, "needs at least " + std::to_string(c.module->min_train_days) +
                                   " training days " + std::string(c.module->min_train_days_why)});
    return true;
  });
  return candidates;
}

// The parameters a form adds to the model it is added to: those its fit
// against the plant before a change frees (FitForm).
std::bitset<kNumParams> OwnParams(const ModelSpec& spec, const LadderModel& current) {
  return DefaultFreeParams(spec) & ~UsedParams(current.spec);
}

// The fit of one form of a candidate on the training days.
struct FormFit {
  Part train;
  IdentSummary fit;
  std::vector<RefittedParam> refitted;  // parameters re-fitted in their physical range
  std::string failure;  // the part could not be prepared
  // With Split::folds: per fold, the parameters fitted without its day.
  std::vector<ParamVector> fold_params;
};

// `to` with the parameters in `own` taken from `from`.
ParamVector WithOwn(ParamVector to, const ParamVector& from, const std::bitset<kNumParams>& own) {
  for (std::size_t p = 0; p < kNumParams; ++p) {
    if (own.test(p)) to[p] = from[p];
  }
  return to;
}

// Per fold of the ladder's current model: `params` (a form's whole model)
// with the rest of the model as that fold's, its own parameters as given.
std::vector<ParamVector> PerFold(const Plant& plant, const LadderModel& current,
                                 const ModelSpec& spec, const ParamVector& params) {
  std::vector<ParamVector> out;
  const std::bitset<kNumParams> own = OwnParams(spec, current);
  for (const ParamVector& fold : current.fold_params) {
    out.push_back(WithOwn(MergedStart(plant, current.spec, fold), params, own));
  }
  return out;
}

// Re-identifies `spec` on the training days from the current model's
// parameters (and the module's start from the base model's residuals).
// With `before` (the form's parameters of the plant before a change), the
// fit also starts from them and keeps the lower training cost: the effect
// as it was is one state the days since may show, and a fit from the
// residuals alone can end in another local minimum (an obstacle's box).
// With each day held out in turn (Split::folds), the same fit is also made
// once per fold on the other days, from that fold's current model and from
// the base model's residuals there (FormFit::fold_params).
FormFit FitForm(const TrialInputs& in, const LadderModel& current, const EffectModule& effect,
                const ModelSpec& spec, const std::optional<ParamVector>& before) {
  FormFit f;
  const Plant& plant = *in.plant;
  if (!PreparePart(in.split->train_series, plant, spec, in.split->data_start_s, in.split->cleanings,
                   &f.train, &f.failure)) {
    if (f.failure.empty()) f.failure = "the training days cannot be prepared";
    return f;
  }
  // The start: the current model, the effect's own from the base model's
  // residuals on the rows fitted (`base_meas`).
  auto start_from = [&](const ParamVector& current_params, const Measurements& base_meas) {
    ParamVector start = MergedStart(plant, current.spec, current_params);
    if (effect.start_from_residuals != nullptr) {
      effect.start_from_residuals(
          ResidualsForStart(in.base->train.drivers, in.base->train_sim, base_meas), &start);
    }
    return start;
  };
  const ParamVector start = start_from(current.params, in.base->train.meas);
  if (!in.options->reference_params) {
    RangedFit ranged = IdentifyInRanges(f.train.drivers, f.train.meas, start, *in.options);
    f.fit = std::move(ranged.fit);
    f.refitted = std::move(ranged.refitted);
    return f;
  }
  // Against the plant before a change: only what the effect adds is fitted.
  DiagnosisOptions own = *in.options;
  own.ident.free = OwnParams(spec, current);
  const std::vector<ParamVector> before_folds =
      before ? PerFold(plant, current, spec, *before) : std::vector<ParamVector>{};
  if (own.ident.free.none()) {  // a form without parameters of its own
    f.fit.ok = true;
    f.fit.variant = spec.Name();
    f.fit.params = start;
    f.fold_params = PerFold(plant, current, spec, start);
    return f;
  }
  auto fit = [&](const Measurements& meas, const ParamVector& from,
                 const ParamVector* from_before) {
    RangedFit ranged = IdentifyInRanges(f.train.drivers, meas, from, own);
    if (from_before != nullptr) {
      RangedFit other = IdentifyInRanges(f.train.drivers, meas, *from_before, own);
      if (other.fit.ok &&
          (!ranged.fit.ok || other.fit.final_cost_w_m2 < ranged.fit.final_cost_w_m2)) {
        other.fit.runtime_s += ranged.fit.runtime_s;
        ranged = std::move(other);
      }
    }
    return ranged;
  };
  RangedFit ranged = fit(f.train.meas, start, before ? &*before : nullptr);
  // Each day held out in turn: the fit of each fold reads the other days.
  for (std::size_t d = 0; ranged.fit.ok && d < current.fold_params.size(); ++d) {
    const int fold = static_cast<int>(d);
    const RangedFit without =
        fit(WithoutFold(f.train.meas, *in.split, fold),
            start_from(current.fold_params[d], WithoutFold(in.base->train.meas, *in.split, fold)),
            before ? &before_folds[d] : nullptr);
    ranged.fit.runtime_s += without.fit.runtime_s;
    if (!without.fit.ok) {
      ranged.fit.ok = false;
      ranged.fit.failure_reason = "the fit without the day " +
                                  SolarDate(in.split->day_starts[d], in.split->offset_s) +
                                  " failed: " + without.fit.failure_reason;
      break;
    }
    f.fold_params.push_back(without.fit.params);
  }
  f.fit = std::move(ranged.fit);
  f.refitted = std::move(ranged.refitted);
  return f;
}

// One form of a candidate fitted on the training days and scored on the
// held-out days.
struct ScoredForm {
  NamedForm form;
  FormFit fit;
  Part heldout;
  Score score;
  double objective_w = kNaN;  // SelectionObjectiveW of score; NaN: not scored
  // What the model selection compares (ladder.cc): objective_w, plus with
  // reference days what the form gains with its parameters of before.
  double selection_w = kNaN;
  // With reference days: the held-out score with the form's own parameters
  // as the plant before the change had them (empty: no such fit), and at
  // the first step that fit (BeforeChangeKey, parameters; key "" = none).
  Score before_change;
  std::optional<ParamVector> before_change_params;  // what before_change was scored with
  std::pair<std::string, ParamVector> before_change_fit;
};

// The form's own parameters fitted on the reference days with the rest of
// the model held at the current one (the plant before the change), started
// as the fit on the training days is: from the base model's residuals there.
bool FitOnReferenceDays(const TrialInputs& in, const LadderModel& current,
                        const EffectModule& effect, const ModelSpec& spec, ParamVector* out) {
  const ReferenceDays& ref = *in.reference;
  Part part;
  std::string why;
  if (!PreparePart(ref.series, *in.plant, spec, ref.series.time_s.front(), {}, &part, &why)) {
    return false;
  }
  ParamVector start = MergedStart(*in.plant, current.spec, current.params);
  if (effect.start_from_residuals != nullptr) {
    effect.start_from_residuals(ResidualsForStart(ref.base.drivers, ref.base_sim, ref.base.meas),
                                &start);
  }
  DiagnosisOptions own = *in.options;
  own.ident.free = OwnParams(spec, current);
  const RangedFit ranged = IdentifyInRanges(part.drivers, part.meas, start, own);
  if (!ranged.fit.ok) return false;
  *out = ranged.fit.params;
  return true;
}

// The form's parameters as the plant before the change had them
// (DiagnosisOptions::reference_days): its own fitted on the reference days
// at the first ladder step (*fit_out: that fit, for the later steps), taken
// from that fit at later steps (the plant before had none of the effects
// accepted since), the rest the current model's. Empty when the form has
// no parameters of its own (it is itself as it was before) or no such fit.
std::optional<ParamVector> ParamsBeforeChange(const TrialInputs& in, const LadderModel& current,
                                              const EffectCandidate& c, const NamedForm& form,
                                              std::pair<std::string, ParamVector>* fit_out) {
  const std::bitset<kNumParams> own = OwnParams(form.spec, current);
  if (own.none()) return std::nullopt;
  const std::string key = BeforeChangeKey(c.name, form.form);
  ParamVector before{};
  if (in.before_change != nullptr) {
    const auto it = in.before_change->find(key);
    if (it == in.before_change->end()) return std::nullopt;
    before = it->second;
  } else {
    if (!FitOnReferenceDays(in, current, *c.module, form.spec, &before)) return std::nullopt;
    *fit_out = {key, before};
  }
  return WithOwn(MergedStart(*in.plant, current.spec, current.params), before, own);
}

// f's held-out score as the plant before the change had the form: with
// `before` (ParamsBeforeChange), else, for a form without parameters of its
// own, the form itself.
void ScoreBeforeChange(const TrialInputs& in, const LadderModel& current,
                       const std::optional<ParamVector>& before, ScoredForm* f) {
  if (OwnParams(f->form.spec, current).none()) {
    f->before_change = f->score;
    f->before_change_params = f->fit.fit.params;
  } else if (before) {
    f->before_change = ScoreModel(*in.split, f->heldout, *before,
                                  PerFold(*in.plant, current, f->form.spec, *before),
                                  in.base->units, in.plant->area_m2);
    f->before_change_params = *before;
  }
}

// Fits and scores every form of the candidate; *best is the form with the
// lowest held-out objective of the model selection (ScoredForm::selection_w;
// the first form when none was scored, so that its failure is reported).
std::vector<ScoredForm> FitAndScoreForms(const TrialInputs& in, const LadderModel& current,
                                         const EffectCandidate& c, std::size_t* best) {
  const std::vector<NamedForm> forms =
      c.forms.empty() ? std::vector<NamedForm>{{c.form, c.spec}} : c.forms;
  std::vector<std::uint8_t> inside;
  if (in.extrapolation != nullptr && !in.extrapolation->empty()) {
    inside = RowsInsideTrainingRange(in.base->heldout.drivers, *in.extrapolation);
  }
  std::vector<ScoredForm> out(forms.size());
  const Loss loss = SelectionLoss(*in.options);
  const double current_w = SelectionObjectiveW(current.score, inside, loss);
  *best = 0;
  for (std::size_t k = 0; k < forms.size(); ++k) {
    ScoredForm& f = out[k];
    f.form = forms[k];
    std::optional<ParamVector> before;
    if (in.reference != nullptr) {
      before = ParamsBeforeChange(in, current, c, f.form, &f.before_change_fit);
    }
    f.fit = FitForm(in, current, *c.module, f.form.spec, before);
    std::string why;
    if (!f.fit.failure.empty()) continue;
    if (!PreparePart(in.split->heldout_series, *in.plant, f.form.spec, in.split->data_start_s,
                     in.split->cleanings, &f.heldout, &why)) {
      f.fit.failure = why.empty() ? "the held-out days cannot be prepared" : why;
      continue;
    }
    if (!f.fit.fit.ok) continue;
    f.score = ScoreModel(*in.split, f.heldout, f.fit.fit.params, f.fit.fold_params, in.base->units,
                         in.plant->area_m2);
    f.objective_w = SelectionObjectiveW(f.score, inside, loss);
    f.selection_w = f.objective_w;
    if (in.reference != nullptr) {
      ScoreBeforeChange(in, current, before, &f);
      f.selection_w = CountedObjective(f.objective_w, current_w,
                                       SelectionObjectiveW(f.before_change, inside, loss));
    }
    if (!std::isfinite(out[*best].selection_w) || f.selection_w < out[*best].selection_w) {
      *best = k;
    }
  }
  return out;
}

// The decisive test of one candidate: evidence on the base model's residuals
// (step 1), re-identification of each of its forms on the training days and
// their held-out scores (the form with the lower held-out objective becomes
// the candidate's spec; every form's score goes to *form_scores for the
// model selection, which chooses the form again in each resample), the
// held-out tests of that form.
void TryCandidate(const TrialInputs& in, int step, const LadderModel& current,
                  EffectCandidate* candidate, EffectTrial* trial, Score* score,
                  std::vector<Score>* form_scores, std::vector<Score>* before_change_scores,
                  std::vector<std::pair<std::string, ParamVector>>* before_change_fits,
                  std::vector<ParamVector>* fold_params) {
  EffectCandidate& c = *candidate;
  EffectTrial& t = *trial;
  const Plant& plant = *in.plant;
  const DiagnosisOptions& options = *in.options;
  const ModelSpec& current_spec = current.spec;
  const Score& current_score = current.score;
  const Score& base_score = in.base->score;
  t.name = c.name;
  t.tested_against = current_spec.Name();
  t.explanation = c.explanation;
  t.signature = c.signature;
  t.advice = std::string(c.module->advice);
  t.heldout_mae_before_w = MaeSumW(current_score.errors);
  std::size_t chosen = 0;
  std::vector<ScoredForm> forms = FitAndScoreForms(in, current, c, &chosen);
  double fit_runtime_s = 0.0;
  for (ScoredForm& f : forms) {
    fit_runtime_s += f.fit.fit.runtime_s;
    t.forms.push_back({f.form.form, f.form.spec.Name(), std::isfinite(f.objective_w),
                       std::isfinite(f.objective_w) ? MaeSumW(f.score.errors) : kNaN});
    if (!f.before_change_fit.first.empty()) before_change_fits->push_back(f.before_change_fit);
  }
  ScoredForm& best_form = forms[chosen];
  if (best_form.before_change.loss_w.size() == current_score.loss_w.size()) {
    t.shrink_before_change_pct = 100.0 * (1.0 - best_form.before_change.errors.objective_w_m2() /
                                                    current_score.errors.objective_w_m2());
    t.params_before_change = best_form.before_change_params;
  }
  // The chosen form's held-out score, kept before the forms' scores move on.
  Score chosen_score = best_form.score;
  for (ScoredForm& f : forms) {
    if (!std::isfinite(f.objective_w)) continue;
    form_scores->push_back(std::move(f.score));
    before_change_scores->push_back(std::move(f.before_change));
  }
  c.spec = best_form.form.spec;
  c.form = best_form.form.form;
  t.form = c.form;
  t.variant = c.spec.Name();
  t.fit_runtime_s = fit_runtime_s;
  const FormFit& best = best_form.fit;
  const Part& ho = best_form.heldout;
  if (!best.failure.empty()) {
    t.failure = best.failure;
    form_scores->clear();
    before_change_scores->clear();
    return;
  }
  // Evidence on the base model's residuals (the gap being explained).
  if (step == 1) {
    const std::vector<double> sig = CandidateSignature(c, ho.drivers, base_score.sim);
    std::vector<std::vector<double>> ctl = in.controls;
    const PartialCorrelation cp = [&] {
      ctl.push_back(base_score.sim.p_el_w);
      return PartialCorrelate(in.residuals->p_el_w, sig, ctl);
    }();
    ctl.back() = base_score.sim.q_th_w;
    const PartialCorrelation cq = PartialCorrelate(in.residuals->q_th_w, sig, ctl);
    const bool use_q = std::fabs(cq.z) >= std::fabs(cp.z);
    t.evidence_corr = use_q ? cq : cp;
    t.evidence_output = use_q ? "q_th" : "p_el";
  }
  const IdentSummary& fit = best.fit;
  t.params = fit.params;
  t.refitted = best.refitted;
  if (c.module->advice_for != nullptr) t.advice = c.module->advice_for(c.spec, fit.params, plant);
  for (const ParamEstimate& e : fit.estimates) {
    if (std::find(c.module->params.begin(), c.module->params.end(), e.param) !=
        c.module->params.end()) {
      t.estimates.push_back(e);
    }
  }
  if (!fit.ok) {
    t.failure = "identification failed: " + fit.failure_reason;
    return;
  }
  *score = std::move(chosen_score);
  *fold_params = best.fold_params;
  if (!std::isfinite((*score).errors.objective_w_m2())) {
    t.failure = "non-finite held-out outputs";
    form_scores->clear();
    before_change_scores->clear();
    return;
  }
  t.fit_ok = true;
  t.heldout_mae_after_w = MaeSumW((*score).errors);
  t.shrink_pct =
      100.0 * (1.0 - (*score).errors.objective_w_m2() / current_score.errors.objective_w_m2());
  t.test = CompareUnits(current_score, (*score));
  Judge(in, c, ho, current_score, *score, &t);
  if (c.module->sensor_estimate != nullptr) {
    SensorTest(*in.data, in.split->day_starts, plant, c.spec, *c.module, &t);
    t.sensor_fault =
        t.sensor_p <= options.alpha && std::fabs(t.sensor_estimate) >= options.min_sensor_error;
  }
}

std::string ProgressLine(int step, int finished, std::size_t candidates, const EffectTrial& t,
                         const std::string& test_unit) {
  return "[step " + std::to_string(step) + ", " + std::to_string(finished) + "/" +
         std::to_string(candidates) + "] +" + t.name + ": " +
         (t.fit_ok
              ? "shrink " + FixedDecimals(t.shrink_pct, 1) + " %, better on " +
                    std::to_string(t.test.positives) + " of " + std::to_string(t.test.pairs) + " " +
                    test_unit + "s, loss test p = " + PValue(t.heldout_test.p) +
                    (t.sensor_fault ? " (sensor fault)" : "") +
                    (t.cautions.empty() ? ""
                                        : " (" + std::to_string(t.cautions.size()) + " caution(s))")
              : "FAILED: " + t.failure) +
         " (" + FixedDecimals(t.fit_runtime_s, 2) + " s)";
}

// The trial's evidence in one sentence: residual correlation (step 1), the
// module's sensor evidence, the held-out test.
std::string EvidenceSentence(const EffectTrial& t, const EffectModule& effect, int step,
                             const std::string& test_unit) {
  std::ostringstream ev;
  if (step == 1 && t.evidence_corr.rows > 0) {
    ev << "partial correlation of the " << (t.evidence_output == "q_th" ? "Q_u" : "P_el")
       << " residual with " << t.signature << " r = " << FixedDecimals(t.evidence_corr.r, 2)
       << " (z = " << FixedDecimals(t.evidence_corr.z, 1)
       << ", n_eff = " << FixedDecimals(t.evidence_corr.n_eff, 0) << "); ";
  }
  if (effect.sensor_evidence != nullptr && std::isfinite(t.sensor_estimate)) {
    ev << effect.sensor_evidence(t.sensor_estimate, t.sensor_p, t.sensor_days);
  }
  if (t.fit_ok) {
    if (t.forms.size() > 1) {
      ev << "form " << t.form << " (the lowest held-out objective of its forms; MAE P_el + Q_u:";
      for (const EffectTrial::FormResult& f : t.forms) {
        ev << " " << f.form << " "
           << (f.scored ? FixedDecimals(f.heldout_mae_after_w, 2) + " W" : "not scored");
        ev << (&f == &t.forms.back() ? "" : ",");
      }
      ev << "); ";
    }
    ev << "re-identified " << t.variant << " lowers the held-out loss by "
       << FixedDecimals(t.heldout_test.mean_difference, 2)
       << " W per row (loss test z = " << FixedDecimals(t.heldout_test.z, 1)
       << ", p = " << PValue(t.heldout_test.p) << ", " << t.heldout_test.rows
       << " rows), better on " << t.days_improved << " held-out day(s); "
       << "per " << test_unit << ": lower on " << t.test.positives << " of " << t.test.pairs
       << " (Wilcoxon p = " << PValue(t.test.wilcoxon_p) << ")";
    if (!t.signature_check.empty()) ev << "; " << t.signature_check;
    if (std::isfinite(t.shrink_before_change_pct)) {
      ev << "; with its own parameters as fitted on the days before the change";
      if (t.params_before_change) {
        std::string values;
        for (const ParamEstimate& e : t.estimates) {
          if (!e.free) continue;
          const ParamInfo& info = Info(e.param);
          values += std::string(values.empty() ? "" : ", ") + std::string(info.name) + " " +
                    FixedDecimals(e.value, 3) + " since, " +
                    FixedDecimals((*t.params_before_change)[static_cast<std::size_t>(e.param)], 3) +
                    " before";
        }
        if (!values.empty()) ev << " (" << values << ")";
      }
      ev << " it " << (t.shrink_before_change_pct > 0.0 ? "lowers" : "changes")
         << " the held-out error by " << FixedDecimals(t.shrink_before_change_pct, 1)
         << " %: the model selection counts its gain beyond that";
    }
    for (const RefittedParam& r : t.refitted) ev << "; " << RefittedSentence(r);
    for (const std::string& c : t.cautions) ev << "; against it: " << c;
  } else {
    ev << "not tested: " << t.failure;
  }
  return ev.str();
}

}  // namespace

std::string BeforeChangeKey(const std::string& effect, const std::string& form) {
  return effect + "/" + form;
}

// Controls of the evidence regression, per held-out row.
std::vector<std::vector<double>> EvidenceControls(const Drivers& d) {
  const std::size_t n = d.size();
  std::vector<double> g(n), dt(n), flow(n);
  for (std::size_t i = 0; i < n; ++i) {
    g[i] = d.g_poa_w_m2[i];
    dt[i] = d.t_in_c[i] - d.t_amb_c[i];
    flow[i] = d.mdot_kg_s[i];
  }
  return {g, dt, flow};
}

StepTrials TryCandidates(const TrialInputs& in, int step, const LadderModel& current) {
  StepTrials out;
  out.candidates = SelectCandidates(in, current.spec, &out.skipped);
  std::vector<EffectCandidate>& candidates = out.candidates;
  if (candidates.empty()) return out;
  out.trials.resize(candidates.size());
  out.scores.resize(candidates.size());
  out.form_scores.resize(candidates.size());
  out.before_change_scores.resize(candidates.size());
  out.before_change_fits.resize(candidates.size());
  out.fold_params.resize(candidates.size());
  std::atomic<std::size_t> next{0};
  std::atomic<int> done{0};
  auto worker = [&] {
    for (std::size_t k = next++; k < candidates.size(); k = next++) {
      TryCandidate(in, step, current, &candidates[k], &out.trials[k], &out.scores[k],
                   &out.form_scores[k], &out.before_change_scores[k], &out.before_change_fits[k],
                   &out.fold_params[k]);
      const int finished = ++done;
      in.progress(ProgressLine(step, finished, candidates.size(), out.trials[k], in.test_unit));
    }
  };
  RunOnThreads(
      static_cast<unsigned>(std::clamp<int>(in.threads, 1, static_cast<int>(candidates.size()))),
      worker);
  for (std::size_t k = 0; k < out.trials.size(); ++k) {
    out.trials[k].evidence =
        EvidenceSentence(out.trials[k], *candidates[k].module, step, in.test_unit);
  }
  return out;
}

}  // namespace pvtwin::diagnosis_stages
