// The stages of the gap diagnosis (Diagnose, diagnosis.h), each a function
// in its own file with its own inputs and outputs:
//   1. split.cc             days and the training / held-out split
//   2. base_fit.cc          the base model's fit, its held-out score, test units
//   3. localisation.cc      where the base model's held-out error lies
//   4. candidate_trials.cc  every candidate effect added, re-identified, scored
//   5. ladder.cc            forward selection over the candidate trials
//   6. noise_floor.cc       the MAE that sensor noise alone gives
//   7. verdict.cc           the verdict and its sentence
//   8. report_model.cc      the days table and the trace the report plots
// Helpers shared by the stages are in stage_common.cc; every fit of the
// stages runs through IdentifyInRanges (physical_refit.cc). No stage knows an
// effect by name: what differs between effects is asked of the candidate's
// module (EffectCandidate::module).
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnosis/diagnosis.h"
#include "core/model/thermal_model.h"

namespace pvtwin::diagnosis_stages {

using Progress = std::function<void(const std::string&)>;

inline const double kNaN = std::nan("");

// --- Shared helpers (stage_common.cc) ---

// p with two significant digits, as the sentences print p-values.
std::string PValue(double p);

// MAE P_el + MAE Q_u, W.
double MaeSumW(const ErrorMetrics& e);

// One part of the data (training or held-out) prepared for one model.
struct Part {
  Drivers drivers;
  Measurements meas;
};

// data_start_s: the first row of the whole data set. The days-since-cleaning
// clock counts, with no cleaning known, from the start of the data, not from
// the start of each part (SetCleaningTimes ignores cleanings before a part's
// first row, so the count is set here); the recoveries are those of the
// cleanings the whole data show (Split::cleanings), not the part alone.
bool PreparePart(const Series& s, const Plant& plant, const ModelSpec& spec,
                 std::int64_t data_start_s, const std::vector<Cleaning>& cleanings, Part* part,
                 std::string* error);

// The test units (held-out days, or hours) of the held-out rows.
struct Units {
  std::vector<int> unit_of_row;  // per held-out row, −1 = none
  int count = 0;
};

// Held-out scores of one model.
struct Score {
  SimOutputs sim;
  ErrorMetrics errors;
  std::vector<double> unit_objective_w_m2;  // per test unit, NaN if the unit has no rows
  // Per test unit: the sum over its objective rows of |e_P_el| + |e_Q_u|, W
  // (0 if the unit has no rows). Summed over a resample of units and divided
  // by its rows, this is the pooled held-out objective of the resample.
  std::vector<double> unit_loss_w, unit_loss_p_el_w, unit_loss_q_th_w;
  std::vector<double> unit_rows;
  // Per held-out row: |e_P_el|, |e_Q_u| and their sum, W; NaN off the
  // objective rows.
  std::vector<double> loss_p_el_w, loss_q_th_w, loss_w;
  double bias_p_el_w = 0.0, bias_q_th_w = 0.0;  // mean predicted − measured
};

Score ScoreHeldout(const Part& heldout, const ParamVector& params, const Units& units,
                   double area_m2);
// The held-out scores of the outputs `sim` of a model on `heldout`.
Score ScoreSim(const Part& heldout, SimOutputs sim, const Units& units, double area_m2);

// A per-row held-out loss of a Score: the sum |e_P_el| + |e_Q_u|, P_el's or Q_u's.
enum class Loss { kSum, kPEl, kQTh };
const std::vector<double>& LossOf(const Score& score, Loss which);
// The loss the model selection compares (DiagnosisOptions::selection_outputs).
Loss SelectionLoss(const DiagnosisOptions& options);

// The pooled held-out objective of the model selection, W per row: the mean
// of the loss `which` (|e_P_el| + |e_Q_u| for kSum) over the scored rows,
// only those with inside[i] ≠ 0 when `inside` is not empty
// (RowsInsideTrainingRange). NaN without rows.
double SelectionObjectiveW(const Score& score, const std::vector<std::uint8_t>& inside, Loss which);
// What the model selection counts of a candidate with its parameters of
// before a change (DiagnosisOptions::reference_days): its objective plus
// what it gains there over the current model, so that only its gain beyond
// the better of the two counts; the objective itself when the form of
// before is no better than the current model or was not scored (NaN).
inline double CountedObjective(double objective, double current, double before_change) {
  return before_change < current ? objective + (current - before_change) : objective;
}

// One-sided paired test of the per-unit objectives: is `after` lower?
PairedTest CompareUnits(const Score& before, const Score& after);

// One-sided held-out loss test (OneSidedLossDifferenceTest): is `after`'s
// loss lower than `before`'s? `which`: the sum, P_el's or Q_u's loss.
LossDifferenceTest CompareLosses(const Score& before, const Score& after, const Part& heldout,
                                 double bandwidth_s, Loss which = Loss::kSum);

// Residual (predicted − measured) of one output over the objective rows, NaN elsewhere.
std::vector<double> Residual(const Measurements& m, const std::vector<double>& pred,
                             const std::vector<double>& meas);

// Identify with the diagnosis's ranges (physical_refit.cc): Table 3's, the
// physical range for a parameter whose start lies outside Table 3's, and,
// with options.refit_in_physical_ranges, a re-fit in the physical range of
// every free parameter the first fit left at a Table 3 bound that the
// physical range extends (used when it lowers the training cost).
struct RangedFit {
  IdentSummary fit;
  std::vector<RefittedParam> refitted;
};
RangedFit IdentifyInRanges(const Drivers& drivers, const Measurements& meas,
                           const ParamVector& start, const DiagnosisOptions& options);

// --- 1. Split ---
struct Split {
  std::int64_t offset_s = 0;             // SolarDayOffsetS of the plant
  std::vector<std::int64_t> day_starts;  // every local solar day with data
  int train_days = 0;
  int heldout_days = 0;
  std::int64_t data_start_s = 0;  // first row of the data
  Series train_series, heldout_series;
  // Cleanings the whole data show (DetectCleanings), for both parts.
  std::vector<Cleaning> cleanings;
  // Each day held out in turn (against the plant before a change with the
  // split left automatic, CrossFitted): both parts are all the data, a
  // candidate is fitted once per fold, on every day but the fold's, and
  // scored on the fold's day. folds = the days; fold_of_row[i] = row i's
  // day (0, 1, …). folds = 0 and fold_of_row empty for one split.
  int folds = 0;
  std::vector<int> fold_of_row;
  // The first held-out day of day_starts.
  int FirstHeldoutDay() const { return folds > 0 ? 0 : train_days; }
};
// Whether every day is held out in turn: against the plant before a change
// (DiagnosisOptions::reference_params), whose base model is not fitted, when
// neither train_days nor heldout_days is given. Only a candidate's own
// parameters are fitted there, on the other days since the change, so that
// every day since is a held-out day: one day that cannot show the change (an
// overcast day when an inverter clips) is then one of several units, not
// the whole test.
bool CrossFitted(const DiagnosisOptions& options);
// m with the objective rows of fold `fold` removed (Split::fold_of_row).
Measurements WithoutFold(const Measurements& m, const Split& split, int fold);
bool SplitDays(const Series& data, const Plant& plant, const DiagnosisOptions& options,
               Split* split, std::string* error);

// --- 2. Base fit ---
struct BaseFit {
  Part train, heldout;
  Units units;
  ParamVector params{};
  SimOutputs train_sim;  // on the training days
  Score score;           // on the held-out days
};
// Also fills r's gap, test unit, low-confidence note and the ladder's base step.
bool FitBase(const Split& split, const Plant& plant, const ModelSpec& base,
             const DiagnosisOptions& options, const Progress& progress, BaseFit* fit,
             DiagnosisResult* r, std::string* error);

// --- 3. Localisation ---
struct BaseResiduals {
  std::vector<RegimeDriver> regimes;   // of the held-out rows
  std::vector<double> p_el_w, q_th_w;  // predicted − measured, NaN off the objective rows
};
// Fills r->where and r->where_bins.
BaseResiduals LocaliseBaseGap(const Split& split, const BaseFit& base, const Plant& plant,
                              const DiagnosisOptions& options, DiagnosisResult* r);

// Drivers (T_in − T_amb, in-plane irradiance, wind, flow) whose held-out
// range leaves the training range on more than options.extrapolation_share
// of the held-out objective rows.
std::vector<Extrapolation> FindExtrapolation(const BaseFit& base, const DiagnosisOptions& options);
// Per row of d: whether every driver of `extrapolation` lies inside its
// training range there (with FindExtrapolation's margin); NaN counts as
// inside.
std::vector<std::uint8_t> RowsInsideTrainingRange(const Drivers& d,
                                                  const std::vector<Extrapolation>& extrapolation);

// The sensor checks of the monitor (FindSensorFaults) over the whole data,
// one finding per channel and kind, most rows first (sensors.cc).
std::vector<SensorFinding> CheckSensors(const Series& data, const Plant& plant);

// The residual sensor checks (sensor_residuals.h: an inlet / outlet offset
// step, the pair at night, a flow meter scale) in the residuals of `base`
// (the ladder's final model) fitted on all the data from `start`, a Q_u
// fault sized on `base` fitted on the days before its onset; one finding per
// fault found, none when the model cannot be fitted. *identifications
// counts the fits.
std::vector<SensorFinding> FindResidualSensorFaults(const Series& data, const Split& split,
                                                    const Plant& plant, const ModelSpec& base,
                                                    const ParamVector& start,
                                                    const DiagnosisOptions& options,
                                                    const Progress& progress, int* identifications);

// --- 4. Candidate trials ---
// Controls of the evidence regression, per held-out row: in-plane
// irradiance, T_in − T_amb, flow.
std::vector<std::vector<double>> EvidenceControls(const Drivers& d);

// The days the reference parameters were fitted on (DiagnosisOptions::
// reference_days) at the data's step, with the base model's outputs there:
// a candidate's fit on them starts from the base model's residuals, as its
// fit on the training days does.
struct ReferenceDays {
  Series series;
  Part base;
  SimOutputs base_sim;
};
// Prepares *out from options.reference_days (resampled to step_s) and the
// reference parameters; false with *error when they cannot be prepared.
bool PrepareReferenceDays(const DiagnosisOptions& options, double step_s, const Plant& plant,
                          const ModelSpec& base, ReferenceDays* out, std::string* error);

// What every ladder step's trials read.
struct TrialInputs {
  const Series* data = nullptr;
  const Split* split = nullptr;
  const Plant* plant = nullptr;
  const DiagnosisOptions* options = nullptr;
  const BaseFit* base = nullptr;
  const BaseResiduals* residuals = nullptr;
  std::vector<std::vector<double>> controls;  // of the evidence regression, per held-out row
  int threads = 1;
  std::string test_unit;  // "day" or "hour"
  Progress progress;
  const std::vector<Extrapolation>* extrapolation = nullptr;  // FindExtrapolation's
  // DiagnosisOptions::reference_days prepared for the base model; nullptr
  // without them.
  const ReferenceDays* reference = nullptr;
  // The fits of each candidate form on reference_days at the first ladder
  // step (BeforeChangeKey → the whole model's parameters), which later steps
  // reuse: the plant before the change had none of the effects accepted since.
  const std::map<std::string, ParamVector>* before_change = nullptr;
};
// The key of a candidate form's fit on the reference days: "effect/form".
std::string BeforeChangeKey(const std::string& effect, const std::string& form);
// A model on the ladder.
struct LadderModel {
  ModelSpec spec;
  ParamVector params{};  // with Split::folds, the fit on all days (reported)
  Score score;           // with Split::folds, each day scored with its fold's parameters
  // With Split::folds: per fold, the parameters fitted without its day.
  std::vector<ParamVector> fold_params;
};
// The held-out score of `params` on `heldout`; with fold_params (Split::
// folds), each row scored with the parameters of its fold.
Score ScoreModel(const Split& split, const Part& heldout, const ParamVector& params,
                 const std::vector<ParamVector>& fold_params, const Units& units, double area_m2);
struct StepTrials {
  std::vector<EffectCandidate> candidates;
  std::vector<SkippedEffect> skipped;
  std::vector<EffectTrial> trials;  // per candidate
  std::vector<Score> scores;        // per candidate: its chosen form's
  // Per candidate, with Split::folds: its chosen form's parameters per fold.
  std::vector<std::vector<ParamVector>> fold_params;
  // Per candidate: every form's held-out score (the chosen one among them);
  // the model selection takes the best form of each resample.
  std::vector<std::vector<Score>> form_scores;
  // Per candidate, beside form_scores (with DiagnosisOptions::reference_days):
  // each form's held-out score with its own parameters as fitted on the
  // reference days, the rest as fitted since (an empty Score: no such fit).
  std::vector<std::vector<Score>> before_change_scores;
  // Per candidate, at the first step: each form's fit on the reference days
  // (BeforeChangeKey, parameters), for TrialInputs::before_change.
  std::vector<std::vector<std::pair<std::string, ParamVector>>> before_change_fits;
};
// Step `step` of the ladder: every candidate effect added to `current`,
// re-identified on the training days and scored on the held-out days, with
// its residual evidence (step 1) and evidence sentence.
StepTrials TryCandidates(const TrialInputs& in, int step, const LadderModel& current);

// --- 5. Ladder ---
// Forward selection: fills r's effects (ranked), ladder, skipped effects,
// identifications and final variant; returns the final model.
LadderModel RunLadder(const TrialInputs& in, const ModelSpec& base, DiagnosisResult* r);

// --- 6. Noise floor ---
bool EstimateNoiseFloor(const Split& split, const Plant& plant, const LadderModel& final_model,
                        DiagnosisResult* r, std::string* error);

// --- 7. Verdict ---
void DecideVerdict(const DiagnosisOptions& options, DiagnosisResult* r);

// --- 8. Report model ---
// The trace of the held-out rows and the days table.
void BuildReportModel(const Split& split, const BaseFit& base, const BaseResiduals& residuals,
                      const LadderModel& final_model, double area_m2, DiagnosisResult* r);

}  // namespace pvtwin::diagnosis_stages
