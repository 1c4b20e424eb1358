// Sim-to-real gap diagnosis: where a calibrated model's error lies, which
// unmodelled effect of the catalogue (doc/contracts.md's vocabulary) causes it, and
// how far the error shrinks once that effect is added.
//
// Protocol (all on local mean solar days, core/forecast/backtest.h):
//  1. Split: the first train_days days of the data are the training days,
//     the next heldout_days days the held-out days. Each part gets its own
//     drivers; states start at the steady state of each part's first row.
//     Against the plant before a change with neither given, each day is held
//     out in turn instead: the base model is not fitted, and each candidate
//     is fitted once per day on the other days and scored on that day.
//  2. Base: identify the base variant on the training days (Identify from
//     StartParams; against the plant before a change, keep
//     DiagnosisOptions::reference_params instead) and simulate the held-out
//     days: the gap (held-out MAE of P_el and Q_u) and its residuals
//     r = predicted − measured.
//  3. Where: the held-out residuals of each output are localised over the
//     standard regime drivers (core/diagnosis/gap_localisation.h).
//  4. Which: for each effect the model can take (core/diagnosis/effect_candidates.h),
//     the evidence is the partial correlation of the base residuals (P_el,
//     Q_u; the stronger is reported) with the effect's signature after
//     removing the in-plane irradiance, T_in − T_amb, flow and the base
//     prediction; the decisive test adds the effect, re-identifies on the
//     training days from the base fit's parameters, and scores the held-out
//     days with the paper's objective MAE(P_el)/A + MAE(Q_u)/A per unit.
//     Units are held-out days; with fewer than min_test_units days they are
//     one-hour blocks (reported as low confidence: hours of one day are not
//     independent weather). The candidates are compared by model selection:
//     the units are resampled with replacement (DiagnosisOptions::
//     bootstrap_resamples), and a candidate's confidence is the share of
//     resamples in which it has the lowest pooled held-out objective and
//     beats the current model by min_shrink_pct. Signatures, the output
//     split, bounds and extrapolated days are reported as cautions next to
//     the candidate, none discards it. A sensor fault is judged by its
//     sensor test instead (EffectTrial; alpha and min_sensor_error).
//  5. Ladder (forward selection): the candidate whose confidence reaches
//     min_confidence is accepted, and step 4 is repeated from the extended
//     model, until none does (then `undecided` between the top two when
//     together they beat the model) or max_ladder_steps are accepted.
//  6. Noise floor: the MAE that sensor noise alone gives, from the second
//     differences of the final model's held-out residuals
//     (NoiseMaeFromSecondDifferences), per output.
//  7. Verdict: the first accepted effect; else "unknown" when the final
//     held-out objective exceeds unknown_noise_ratio × the noise floor (a
//     gap no catalogued effect removes; `where` locates it); else "none".
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/common/text.h"
#include "core/diagnosis/diagnosis_stats.h"
#include "core/diagnosis/effect_candidates.h"
#include "core/diagnosis/gap_localisation.h"
#include "core/fit/identification.h"
#include "core/model/variant.h"
#include "core/monitor/monitoring.h"

namespace pvtwin {

// Identification settings of the diagnosis: IdentOptions' defaults with a
// relative cost tolerance of 1e-4 instead of 1e-3. The test compares fits
// that differ by one effect; a base fit stopped 3–5 % above its optimum lets
// any extended fit (started from it) "improve" by converging further, which
// is not an effect. `pvtwin-bench ident`: 1e-4 reaches the noise floor.
IdentOptions DiagnosisIdentOptions();

// The outputs whose held-out error the model selection compares
// (DiagnosisOptions::selection_outputs).
enum class SelectionOutputs { kBoth, kPEl, kQTh };

// "both", "p_el", "q_th"; ParseSelectionOutputs: false for another text.
std::string_view SelectionOutputsName(SelectionOutputs o);
bool ParseSelectionOutputs(std::string_view text, SelectionOutputs* out);

struct DiagnosisOptions {
  // Training days from the first day of data; 0 = two thirds of the days
  // (rounded, at least 1, leaving at least 1 held-out day). With
  // reference_params and both 0, every day is held out in turn (the
  // candidates' own parameters fitted on the other days).
  int train_days = 0;
  // Held-out days after the training days; 0 = all remaining days.
  int heldout_days = 0;
  // Data step used, s; 0 = the data's own step, else whole seconds, a
  // multiple of the data step, dividing 86400 (the data are averaged).
  double step_s = 0.0;
  // Identification of every model (must be valid). Default: the project's
  // defaults with ftol_rel 1e-4 (DiagnosisIdentOptions).
  IdentOptions ident = DiagnosisIdentOptions();
  // One-sided p of the held-out loss test at or below which an improvement
  // counts (and at which an output made worse counts against an effect).
  double alpha = 0.05;
  // Bandwidth of the loss test's autocorrelation correction, s: residuals
  // of a thermal model carry the weather's hours-long memory.
  double loss_test_bandwidth_s = 3600.0;
  // Share of held-out rows outside the training range above which a driver
  // is reported as extrapolated.
  double extrapolation_share = 0.3;
  // Smallest reduction of the pooled held-out objective, %, that counts.
  // Above what re-identification alone moves it on data without the effect
  // (≤ 0.3 % on the self-test's null cases at ftol 1e-4).
  double min_shrink_pct = 1.0;
  // Fewer held-out days than this: test over one-hour blocks instead.
  int min_test_units = 5;
  // Smallest size |estimate| of a sensor fault that counts
  // (EffectModule::sensor_estimate, e.g. a pyranometer scale error k).
  double min_sensor_error = 0.02;
  // Most effects accepted on the ladder.
  int max_ladder_steps = 3;
  // The model selection of each ladder step: the held-out test units (days)
  // are resampled with replacement bootstrap_resamples times; in each
  // resample the candidate with the lowest pooled held-out objective
  // (MAE P_el + MAE Q_u) wins if it beats the current model by
  // min_shrink_pct. A candidate is accepted when it wins in at least
  // min_confidence of the resamples, the only threshold of the selection.
  // When no single candidate reaches it but some candidate beats the current
  // model in that share, the step is undecided between the two most
  // confident ones. 0.8, set on the development seeds 1–3 (doc/validation.md):
  // there every null and fault case stays at 0 (no candidate beats the base
  // in any resample), and a present effect whose gain rests on most of the
  // 7 held-out days reaches 0.86–1.
  double min_confidence = 0.8;
  // Resamples: 2000 put the Monte-Carlo error of a share near 0.9 at ±0.7 %.
  int bootstrap_resamples = 2000;
  // Seed of the resampling (the verdict is reproducible).
  std::uint64_t bootstrap_seed = 1;
  // "unknown" when nothing is significant and the held-out objective is
  // more than this multiple of the noise floor.
  double unknown_noise_ratio = 2.0;
  // The inlet offset step (sensor_steps.cc): days with fewer rows with flow
  // than this give no daily median (half an hour of pumping at 1 min).
  int sensor_step_min_rows = 30;
  // Smallest step that is a sensor fault, K: twice the tolerance of a
  // class-A Pt100 at 25 °C (IEC 60751: ±(0.15 + 0.002·|T|) K).
  double min_temperature_offset_k = 0.4;
  // The pair check at night (sensor_pair_night.cc) reads rows with flow and
  // in-plane irradiance at most this, W/m²: 5 W/m² absorbed at η0 ≈ 0.5
  // warms the fluid by under 0.1 K even at 30 % of a nominal 0.02 kg/(s·m²),
  // a quarter of min_temperature_offset_k, and the model's optics (whose
  // errors dominate daytime residuals) are out of the residual.
  double sensor_night_g_w_m2 = 5.0;
  // Smallest step of measured / modelled Q_u, |k − 1|, that is a flow meter
  // scale error (sensor_flow_scale.cc): the maximum permissible error of an
  // EN 1434 class-2 heat meter near its nominal flow (flow sensor 2–4 %,
  // temperature pair and calculator ≈ 1 %) is under 5 %.
  double min_flow_scale_error = 0.05;
  // A free parameter that ends a fit (the base model's, a candidate's) at a
  // bound of Table 3's range is re-fitted within the hull of that range and
  // its physical range (core/common/physical_ranges.h), from the first fit;
  // the re-fit is used when it lowers the training cost. Table 3's ranges are
  // start values ±50 % for ε_PVT and η_PVref: a plant outside them is a real
  // plant (issue 52, item 3). A model whose start values lie outside Table
  // 3's range (built on such a re-fit) keeps the physical range for them.
  bool refit_in_physical_ranges = true;
  // The model of the plant before a change, held fixed: the base model is
  // not fitted on the training days but keeps these parameters, and each
  // candidate fits only the parameters its effect adds to the model it is
  // added to. The question is then which effect explains what changed, not
  // which structure the plant has and the model lacks: that structure is in
  // both states, and a base re-fitted on the few days since a change lets it
  // compete with the change (doc/validation.md, the weeks after an alarm).
  // For the same reason only the effects that can begin while the plant runs
  // are tried (EffectModule::begins_in_operation: clipping, shading,
  // soiling, a sensor's or a clock's fault); a property of the collector's
  // build (an IAM, a transport delay) is in both states and goes to
  // `skipped`. The daemon sets it to its accepted calibration of the window
  // before a performance alarm's change (`pvtwin diagnose
  // --against-calibration`).
  // Empty: the base is fitted on the training days.
  std::optional<ParamVector> reference_params;
  // Where reference_params come from, for the notes ("calibration 12, window
  // 2025-05-26 to 2025-06-09").
  std::string reference_name;
  // The days reference_params were fitted on (the calibration's window),
  // only with reference_params. With them each candidate's own parameters
  // are also fitted on those days (the rest held at reference_params): the
  // effect as the plant had it before the change. The model selection then
  // counts a candidate's gain on the held-out days beyond the better of the
  // model without it and the model with it as it was before: an effect the
  // plant has all along (an IAM the model lacks) gains as much with its
  // parameters of before as with those of the days since, so it explains
  // the structure, not the change; an effect that changed (an inverter that
  // clips from the change on) gains nothing with its parameters of before.
  // A form without parameters of its own cannot change and never counts.
  // Empty: every candidate is judged against the model without it.
  std::shared_ptr<const Series> reference_days;
  // The outputs the model selection compares on the held-out days: both
  // (the paper's objective, MAE P_el + MAE Q_u), or the one a performance
  // alarm found changed. On the days since a change the question is which
  // effect explains what changed: an effect that leaves that output as it
  // was (a transport delay when the electricity fell) explains none of it,
  // however much of the other output's error it takes. The daemon sets it
  // to the outputs whose alarms dated the change (`pvtwin diagnose
  // --objective p_el`). min_shrink_pct applies to it; shrink_pct and the
  // report's errors stay those of both outputs. It holds for the first
  // ladder step, whose effect explains the change; a later step explains
  // the rest of the gap, which no alarm dated, and is judged on both.
  SelectionOutputs selection_outputs = SelectionOutputs::kBoth;
  // Effects to try (names of the vocabulary); empty = every candidate.
  std::vector<std::string> effects;
  LocaliseOptions where;
  // Worker threads for the candidate fits; 0 = hardware concurrency.
  int threads = 0;

  // False if a field is out of range; *why lists "field = value: rule"
  // separated by "; ".
  bool IsValid(std::string* why) const;
};

// A sensor finding of the data (the sensor checks of core/monitor/
// monitoring.h, FindSensorFaults, over all days), one per channel and kind.
struct SensorFinding {
  std::string channel;         // canonical name, "time" for a clock shift
  std::string kind;  // sky_warmer_than_air, frozen, missing, above_clear_sky, offset_step,
                     // pair_offset (channel "t_in_c,t_out_c"), scale (flow_kg_s), …
  std::size_t rows = 0;        // rows in the flagged intervals
  double share = 0.0;          // of all rows
  double size = std::nan("");  // sky_warmer_than_air: median sky − air on those rows, K;
                               // offset_step: the step, K; pair_offset: the step of
                               // (T_out − T_in) logged − model at night, K, signed;
                               // scale: measured / true flow (measured / modelled Q_u)
  std::string size_unit = "K";  // of size: "K", or "" for a ratio (scale)
  std::string from;  // offset_step, pair_offset, scale: the solar day it starts (YYYY-MM-DD)
  std::int64_t from_s = 0;  // … its start, unix s (0: no onset)
  std::string detail;          // the first interval's sentence, and how many there are
};

// The finding's size with its unit: "1.4 K", "× 1.100" (sensors.cc).
std::string SensorSizeText(const SensorFinding& f);

// A driver of the model whose held-out values lie outside what the training
// days showed (share_outside of the held-out objective rows beyond the
// training rows' 1st–99th percentile).
struct Extrapolation {
  std::string driver;  // "t_in_minus_t_amb_k", "g_poa_w_m2", "wind_m_s", "flow_kg_s"
  double train_low = 0.0, train_high = 0.0;      // 1st, 99th percentile
  double heldout_low = 0.0, heldout_high = 0.0;  // 1st, 99th percentile
  double share_outside = 0.0;
};

// A parameter that ended a fit at a bound of Table 3's range, re-fitted
// within the hull of that range and its physical range
// (DiagnosisOptions::refit_in_physical_ranges).
struct RefittedParam {
  Param param = Param::kCount;
  double table_bound = 0.0;         // the Table 3 bound the first fit ended at
  double lower = 0.0, upper = 0.0;  // the range of the re-fit
  double value = 0.0;               // where the re-fit ended
  bool used = false;                // the re-fit lowered the training cost: its parameters count
};

// "ε_PVT at its Table 3 bound 0.225, re-fitted in 0–0.95: 0.41" (", not used:
// no lower training cost" when the first fit stayed).
std::string RefittedSentence(const RefittedParam& r);

// The decisive test of one effect against the model it was added to.
struct EffectTrial {
  std::string name;
  std::string variant;         // the model with the effect
  // The form judged (EffectModule::form or a diagnosis_forms name): the one
  // with the lowest held-out objective of the model selection.
  std::string form;
  // Every form fitted, the judged one among them, with its held-out
  // MAE P_el + MAE Q_u, W (scored = false: its fit failed).
  struct FormResult {
    std::string form, variant;
    bool scored = false;
    double heldout_mae_after_w = std::nan("");
  };
  std::vector<FormResult> forms;
  std::string tested_against;  // the model it was added to
  std::string explanation;
  std::string signature;
  std::string advice;  // one sentence for the site (EffectModule::advice)
  bool fit_ok = false;
  std::string failure;  // when !fit_ok
  bool significant = false;
  int accepted_at_step = 0;           // ladder step (1, 2, …) that accepted it; 0 = not accepted
  double shrink_pct = 0.0;            // reduction of the held-out MAE(P_el) + MAE(Q_u)
  // With DiagnosisOptions::reference_days: the reduction the effect gives
  // with its own parameters as fitted on those days (the plant before the
  // change), %; NaN without them. The model selection counts the gain
  // beyond it.
  double shrink_before_change_pct = std::nan("");
  // … and the whole model's parameters it was scored with (its own as
  // fitted on those days); empty without them.
  std::optional<ParamVector> params_before_change;
  double heldout_mae_before_w = 0.0;  // MAE P_el + MAE Q_u, W, of tested_against
  double heldout_mae_after_w = 0.0;   // … with the effect
  PairedTest test;                    // over test units (per-unit objective), reported
  // The decisive test: held-out loss |e_P_el| + |e_Q_u| per row before and
  // after (OneSidedLossDifferenceTest, bandwidth loss_test_bandwidth_s).
  LossDifferenceTest heldout_test;
  // Held-out MAE per output after the effect, W (before: tested_against's).
  double mae_p_el_after_w = 0.0, mae_q_th_after_w = 0.0;
  double mae_p_el_before_w = 0.0, mae_q_th_before_w = 0.0;
  // Held-out days on which the effect lowered the loss (it acts where it
  // acts: an effect need not help on every day, but on more than one).
  int days_improved = 0;
  // The model selection (ladder.cc): share of the bootstrap resamples of
  // the held-out test units in which this effect is the best candidate and
  // beats the model it was added to by min_shrink_pct (`confidence`), and in
  // which it beats that model by min_shrink_pct at all (`confidence_beats`).
  double confidence = 0.0;
  double confidence_beats = 0.0;
  // A sensor fault whose sensor test passed (sensor_p ≤ alpha and
  // |sensor_estimate| ≥ min_sensor_error).
  bool sensor_fault = false;
  // Evidence against the effect, reported beside it and never a veto: an
  // output made worse (the effect is judged on the sum), parameters at a
  // bound or not determined, better on one held-out day only, a gain that
  // is a shift of the bias on extrapolated days, its signature not shown.
  std::vector<std::string> cautions;
  // Why the effect is not the verdict although its held-out error fell
  // ("" = accepted or no gain): its confidence below min_confidence.
  std::string rejected;
  // The module's signature check (EffectModule::shows_signature), "" if none.
  std::string signature_check;
  // Effect parameters that ended at a bound or that the data do not
  // determine: "P_limit at its upper bound 300", "n_flow = 0.079 ± 0.247 (not determined)".
  std::vector<std::string> at_bounds;
  // Parameters (of the whole model) re-fitted in their physical range
  // because the fit left them at a Table 3 bound; also named in `evidence`.
  std::vector<RefittedParam> refitted;
  PartialCorrelation evidence_corr;  // residual evidence (stronger output)
  std::string evidence_output;       // "p_el" or "q_th"
  std::string evidence;              // one sentence
  double fit_runtime_s = 0.0;
  ParamVector params{};
  std::vector<ParamEstimate> estimates;  // of the effect's own parameters
  // A sensor fault (an effect with EffectModule::sensor_estimate, the
  // pyranometer scale error k) is not a prediction error: the fit absorbs it
  // and the held-out MAE does not move. It is significant when its per-day
  // estimates have one sign consistently (two-sided Wilcoxon p ≤ alpha) and
  // |median| ≥ min_sensor_error. report.json writes them as
  // irradiance_bias_k and irradiance_bias_p (the one sensor effect so far).
  double sensor_estimate = std::nan("");  // median of the per-day estimates
  double sensor_p = std::nan("");         // two-sided p of estimate ≠ 0 over days
  int sensor_days = 0;                    // days with an estimate
};

struct LadderStep {
  std::string variant;
  std::string added;  // effect added at this step ("" for the base)
  ErrorMetrics heldout;
  double heldout_mae_w = 0.0;   // MAE P_el + MAE Q_u, W
  double objective_w_m2 = 0.0;  // paper objective, W/m²
  double shrink_pct = 0.0;      // against the previous step
  double p_value = 1.0;         // Wilcoxon p against the previous step
  double loss_test_p = 1.0;     // held-out loss test p against the previous step
  ParamVector params{};
};

struct NoiseFloor {
  double mae_p_el_w = 0.0;  // MAE that sensor noise alone gives
  double mae_q_th_w = 0.0;
  double objective_w_m2 = 0.0;  // (mae_p_el_w + mae_q_th_w) / A
  double ratio = 0.0;           // final held-out objective / objective_w_m2
};

struct DiagnosisDay {
  std::int64_t start_s = 0;
  std::string date;
  bool heldout = false;
  std::size_t rows = 0;              // objective rows
  double base_objective_w_m2 = 0.0;  // held-out days only
  double final_objective_w_m2 = 0.0;
};

// Held-out rows for plots: measured and predicted (base, final model).
struct DiagnosisTrace {
  std::vector<std::int64_t> time_s;
  std::vector<double> p_el_meas_w, q_th_meas_w;
  std::vector<double> p_el_base_w, q_th_base_w;
  std::vector<double> p_el_final_w, q_th_final_w;
  std::vector<double> hour_of_day, aoi_deg, sun_azimuth_deg, sun_elevation_deg;
};

struct DiagnosisResult {
  std::string base_variant;
  std::string final_variant;
  double step_s = 0.0;
  ErrorMetrics gap;                    // held-out errors of the base model
  std::vector<GapRegion> where;        // flagged regions, both outputs, most excess first
  std::vector<GapRegion> where_bins;   // every bin (for plots)
  std::vector<EffectTrial> effects;    // ranked, most likely first
  std::vector<SkippedEffect> skipped;  // effects not tried, with the reason
  std::vector<LadderStep> ladder;      // base, + effect 1, …
  std::string verdict;                 // an effect name, "none", "unknown" or "undecided"
  // With "undecided" (or a later ladder step that stopped on a tie): the
  // effects whose held-out errors the data cannot tell apart.
  std::vector<std::string> candidates;
  // With candidates: how the two differ and what data would separate them.
  std::string separation;
  // Drivers whose held-out range leaves the training range (see
  // FindExtrapolation): parameters not determined by the training data.
  std::vector<Extrapolation> extrapolation;
  std::vector<SensorFinding> sensors;
  std::string verdict_sentence;
  NoiseFloor noise;
  std::vector<DiagnosisDay> days;
  std::string test_unit;        // "day" or "hour"
  bool low_confidence = false;  // fewer held-out days than min_test_units
  std::vector<std::string> notes;
  // The base model's parameters re-fitted in their physical range (also in notes).
  std::vector<RefittedParam> base_refitted;
  // Which sky the models ran on (SkyTemperaturesC; notes say why an
  // estimate replaced the long-wave channel).
  SkyUsed sky_used = SkyUsed::kMeasured;
  DiagnosisTrace trace;
  int identifications = 0;
  double wall_time_s = 0.0;
};

// The base model's bias on the held-out rows (the trace): mean predicted −
// measured, and the share of the MAE it explains (|bias| / MAE: 1 when every
// error has the same sign, as when a loss coefficient sits at its bound and
// the held-out days run at another temperature). NaN without rows.
struct GapBias {
  double p_el_w = 0.0, q_th_w = 0.0;
  double share_p_el = 0.0, share_q_th = 0.0;
};
GapBias BaseModelBias(const DiagnosisResult& result);

// The findings of the residual sensor checks (those with an onset) as
// qc_event rows from their onset to end_s (sensors.cc); the monitor's own
// checks are recorded by the daemon's daily run.
std::vector<SensorFault> DiagnosedSensorFaults(const DiagnosisResult& result, std::int64_t end_s);

// Runs the diagnosis of `base` on `data`. Returns false with *error when it
// cannot run: invalid options, a step the data cannot be averaged to, missing
// columns for the base variant, too few days or rows, or a failed base fit.
// progress (may be empty) receives one line per finished stage or fit.
bool Diagnose(const Series& data, const Plant& plant, const ModelSpec& base,
              const DiagnosisOptions& options, DiagnosisResult* result, std::string* error,
              const std::function<void(const std::string&)>& progress = {});

}  // namespace pvtwin
