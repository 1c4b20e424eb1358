// core/effects/: one module per effect of doc/contracts.md's effect vocabulary
// (capacitance, second_node, …, irradiance_bias; the one list of them is
// core/common/effect_list.h), the registry expanded from that list
// (registry.cc) and the generic library functions that ask the modules
// (effects.h).
//
// May depend on core/common/ and core/physics/ only. The model
// (core/model/), the fit, the synthetic plant and the diagnosis depend on
// it and ask a module what differs between effects; none of them names an
// effect. Adding an effect = one new module (a .h/.cc pair here, its tests
// in tests/unit/) plus its line in the list of effects
// (core/common/effect_list.h) and its parameters' rows
// (core/common/param_list.inc); the registry expands the list.
//
// An effect module holds everything about its effect: the name and a
// paragraph of physics with its source; its parameters (rows of the
// parameter table, core/common/params.h: name, unit, symbol, start, bounds,
// scale; the slots param_list.inc assigns to the effect, EffectParams()); the channels it needs; its equations as pure functions in its
// header; how it enters the model (ModelExtension's hooks, or the paper's
// letters of a variant); its residual signature for evidence; its truth form
// for synthetic data (and a second truth form, different from the
// candidate's, for a self-test that does not flatter itself); and its advice
// sentence for the report.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/common/channels.h"
#include "core/common/model_data.h"
#include "core/common/model_spec.h"
#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/series.h"

namespace pvtwin {

// What start_from_residuals reads: the base model's fit on the training days.
struct EffectResiduals {
  const Drivers* drivers = nullptr;                  // base model's training drivers
  const SimOutputs* base = nullptr;                  // base model's outputs on them
  const std::vector<std::uint32_t>* rows = nullptr;  // objective rows
  const std::vector<double>* p_el_meas_w = nullptr;  // measured P_el per row
};

// What a signature check reads: the held-out days, the model without the
// effect and the re-identified model with it.
struct SignatureData {
  const Drivers* drivers = nullptr;                  // held-out, model with the effect
  const std::vector<std::uint32_t>* rows = nullptr;  // objective rows
  const std::vector<double>* p_el_meas_w = nullptr;  // measured, per row
  const std::vector<double>* q_th_meas_w = nullptr;
  const SimOutputs* before = nullptr;   // without the effect
  const SimOutputs* after = nullptr;    // with it
  const ParamVector* params = nullptr;  // fitted, with the effect
};

// Whether the data show the effect's own signature, in one sentence with
// the numbers ("measured P_el sits at the fitted limit …").
struct SignatureCheck {
  bool shown = true;
  std::string sentence;
};

// What an other-form truth hook reads (OtherFormTruth).
struct OtherTruthContext {
  const Plant* plant = nullptr;
  const ParamVector* truth = nullptr;  // the truth plant's parameters
  // Seed of the form's own draws (days with the obstacle, rain days), so that
  // a case and seed always give the same data.
  std::uint64_t seed = 1;
  // The plant's true weather and operation (after the weather hooks); set for
  // the drivers, run, outputs and measured hooks.
  const Series* physics = nullptr;
  // The previous pass's outputs (run hook of a form with passes > 1); null on
  // the first pass.
  const SimOutputs* previous = nullptr;
};

// The effect in another functional form than its candidate (issue 11, item
// 2): synthetic truth that the candidate meant to find it cannot fit exactly,
// the way real physics always differs from a catalogue formula. The truth
// plant runs without the effect's same form (remove_same_form) and the hooks
// below make it show instead, in this order; every hook may be null. The
// physics are pure functions in the module's header, with their source.
struct OtherFormTruth {
  std::string_view form;    // the truth's equations and constants, one paragraph
  std::string_view source;  // where they come from
  // Removes the same form from the truth's spec; null: spec->Remove(*extension)
  // for an effect with an extension, nothing otherwise.
  void (*remove_same_form)(ModelSpec* spec) = nullptr;
  // 1. The plant's true weather before its drivers are prepared (the
  //    measured weather channels keep what the sensors logged).
  void (*weather)(const OtherTruthContext& ctx, Series* physics) = nullptr;
  // 2. The truth's drivers after PrepareDrivers (e.g. the absorbed irradiance).
  void (*drivers)(const OtherTruthContext& ctx, Drivers* drivers) = nullptr;
  // 3. Per-row inputs of the truth run after the spec's extensions
  //    (SimOptions::after_extensions); run `passes` times, each pass seeing
  //    the previous pass's outputs in ctx.previous (a fixed point for forms
  //    that depend on the outputs, e.g. an inverter curve of P_dc).
  void (*run)(const OtherTruthContext& ctx, const Drivers& drivers, RunInputs* run) = nullptr;
  int passes = 1;
  // 4. The truth's outputs after the run (e.g. what a sensor behind a pipe sees).
  void (*outputs)(const OtherTruthContext& ctx, const Drivers& drivers, SimOutputs* out) = nullptr;
  // 5. The measured series after noise: a sensor error (instead of
  //    EffectModule::apply_sensor_error).
  void (*measured)(const OtherTruthContext& ctx, const Drivers& drivers,
                   Series* measured) = nullptr;
};

// A uniform draw in [0, 1) from (seed, key), e.g. key = a day number: the
// other-form truths' per-day events (splitmix64).
double UnitDraw(std::uint64_t seed, std::int64_t key);

// One form of an effect that the diagnosis fits (EffectModule::diagnosis_forms).
struct EffectForm {
  std::string_view name;                   // effects[].form in report.json
  void (*add)(ModelSpec* spec) = nullptr;  // adds the effect to spec in this form
};

struct EffectModule {
  std::string_view name;     // doc/contracts.md vocabulary, e.g. "pv_clipping"
  std::string_view physics;  // one paragraph of physics, for the report
  std::string_view source;   // where the equations come from (paper section, reference)
  // Parameters the effect adds (their rows: Info(Param)): the slots
  // core/common/param_list.inc assigns to it, EffectParams(its Effect).
  std::vector<Param> params;
  // Extra input channels the effect needs beyond the base variant's.
  std::vector<Channel> needs;
  // What the residual evidence correlates with (signature_values' quantity).
  std::string_view signature;
  // One sentence for the site when the diagnosis finds the effect.
  std::string_view advice;
  // The same with the fitted parameters in physical units ("Inverter limit ≈
  // 260 W: …"); spec is the fitted form's (an effect with several forms
  // reads its own parameters); null: `advice` as it is.
  std::string (*advice_for)(const ModelSpec& spec, const ParamVector& fitted,
                            const Plant& plant) = nullptr;
  // A realistic magnitude for synthetic truth data (applied on top of
  // ReferenceTruthParams, core/synth/synthetic_plant.h).
  std::vector<std::pair<Param, double>> typical_truth;
  // The parameter whose fitted value against its truth tells best whether a
  // fit found the effect (pvtwin-bench effects); unset: the first of params.
  std::optional<Param> compared_param;

  // --- How it shows in a variant ---
  // "+name" in the model, with its hooks; null for an effect that the
  // paper's letters express (nodes, capacitances, w, r, I).
  const ModelExtension* extension = nullptr;
  // Whether spec has the effect; null: spec.Has(*extension).
  bool (*in_spec)(const ModelSpec& spec) = nullptr;
  // Adds the effect to spec (WithEffect); null: spec->Add(*extension).
  void (*add_to_spec)(ModelSpec* spec) = nullptr;
  // The name of add_to_spec's form in the report (effects[].form), e.g.
  // "paper" for wind's 'w'; "standard" for an effect with one form.
  std::string_view form = "standard";
  // Further forms of the effect that the diagnosis fits besides
  // add_to_spec's, each adding the effect to spec in its own form (wind: the
  // physical "+wind" besides the paper's 'w'; iam: on the thermal absorption
  // only besides both outputs). Each is fitted on the training days and
  // scored on the held-out days; the effect counts with the form that has
  // the lower held-out objective, chosen again in every resample of the
  // model selection (ladder.cc), so that the choice is inside the confidence.
  std::vector<EffectForm> diagnosis_forms;
  // The extensions those forms add besides `extension` ("+pipe_volume" of
  // transport_delay), so that a variant naming one parses.
  std::vector<const ModelExtension*> form_extensions;
  // Why it cannot be added to spec ("" = it can); null: present = cannot.
  std::string (*cannot_add)(const ModelSpec& spec) = nullptr;
  // Why the data cannot show it, e.g. a missing channel ("" = they can).
  std::string (*data_lacks)(const Series& data) = nullptr;

  // --- Evidence ---
  // Per-row value of the signature, NaN where undefined. drivers may belong
  // to a model without the effect; base are the base model's outputs.
  std::vector<double> (*signature_values)(const Drivers& drivers, const SimOutputs& base) = nullptr;

  // --- Diagnosis ---
  // Whether the effect can begin from one day to the next while the plant
  // runs (an inverter limit set, an obstacle put up, dust after a dry spell,
  // a sensor or logger clock that fails), and so be what a performance
  // alarm dated. False for a property of the collector's build (its
  // capacities, nodes, heat-loss and optical coefficients, pipe volume):
  // it is in the plant before a change as after, so the diagnosis of a
  // change (DiagnosisOptions::reference_params) does not try it.
  bool begins_in_operation = false;
  // Fewest training days on which the effect can be seen, and why.
  int min_train_days = 0;
  std::string_view min_train_days_why;
  // A start for the effect's parameters from the base model's residuals
  // (false: none found, *start unchanged).
  bool (*start_from_residuals)(const EffectResiduals& residuals, ParamVector* start) = nullptr;
  // A sensor fault that the fit absorbs (the held-out error does not move):
  // judged by its size estimated on each day of data instead. NaN = no
  // estimate on that day.
  double (*sensor_estimate)(const Drivers& day) = nullptr;
  // The evidence sentence of a sensor estimate (median over days, two-sided
  // p of ≠ 0, days), ending in "; ".
  std::string (*sensor_evidence)(double median, double p, int days) = nullptr;
  // The physics check of a fit that lowered the held-out error: does the
  // data show what the effect does (a plateau at the fitted limit for
  // clipping, the improvement recurring at the fitted sun positions on
  // several days for shading, …)? Null: no check beyond the generic ones
  // (no output made worse, parameters inside their bounds, better on more
  // than one day).
  SignatureCheck (*shows_signature)(const SignatureData& data) = nullptr;

  // --- Synthetic truth ---
  // A sensor error: the truth plant runs without the effect and this turns
  // the true measurements into what the faulty sensor reads.
  void (*apply_sensor_error)(const ParamVector& truth, Series* measured) = nullptr;
  // The truth in another functional form than the candidate (null: none).
  const OtherFormTruth* other_truth = nullptr;
};

// Central difference per minute of a per-row value, NaN across restarts and
// gaps (a signature helper).
std::vector<double> RatePerMinute(const Drivers& d, const std::vector<double>& v);

// The lag k in rows (min_lag ≤ k ≤ max_lag) at which the changes of `meas`
// follow those of `pred` best: the correlation of meas(i) − meas(i−1) with
// pred(i−k) − pred(i−k−1) over the objective rows whose rows i−k−1 … i are
// one unbroken stretch (no restart, equal steps). Differences, not levels,
// so that a bias does not pick the lag. A signature helper (transport
// delay, clock offset).
struct LagFit {
  int lag_rows = 0;
  double corr_at_lag = 0.0;
  double corr_at_zero = 0.0;
  std::size_t pairs = 0;  // at lag 0; 0 = too few rows (< 30) to say
};
LagFit BestLag(const Drivers& d, const std::vector<std::uint32_t>& rows,
               const std::vector<double>& meas, const std::vector<double>& pred, int min_lag,
               int max_lag);

// The data's row step, s (the median of the steps; 60 when there are none).
double RowStepS(const Drivers& d);

}  // namespace pvtwin
