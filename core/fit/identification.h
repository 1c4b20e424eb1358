// Parameter identification (paper 3.2): fit the free parameters of a variant
// to measured electrical and thermal power by minimising the paper's mean
// absolute error, with NLopt behind core/fit/optimizer.h.
//
// Objective (paper 3.2.2), per m² of nameplate area A:
//   MAE = mean_i |P_el,calc − P_el,meas| / A + mean_i |Q_u,calc − Q_u,meas| / A
// over the rows i that are in the objective (see Measurements). Optionally
// (IdentOptions::use_t_pv) + w_T · mean_i |T_PV,calc − T_PV,meas|.
// A weak quadratic prior in the optimiser's unit coordinates pulls
// directions the data do not determine towards the reference values (see
// IdentOptions::prior_weight_w_m2). Its default weight, 0.01 W/m² per unit²,
// is small against the MAE that moving any determined parameter across its
// range costs, so it decides only where the data are indifferent.
#pragma once

#include <bitset>
#include <cstdint>
#include <string>
#include <vector>

#include "core/common/params.h"
#include "core/common/series.h"
#include "core/effects/effect_module.h"
#include "core/fit/optimizer.h"
#include "core/model/thermal_model.h"

namespace pvtwin {

// Calibration targets of each row, aligned with the drivers built from the
// same series.
struct Measurements {
  std::vector<double> p_el_w;
  std::vector<double> q_th_w;  // q_th_w column, else ṁ·c_p·(T_out − T_in)
  std::vector<double> t_pv_c;  // empty when not measured
  // Rows in the objective and the error metrics: valid ≠ 0, model inputs
  // usable (flow, irradiance, temperatures present) and P_el, Q_u present.
  std::vector<std::uint32_t> rows;
  std::size_t size() const { return p_el_w.size(); }
};

Measurements MakeMeasurements(const Series& series, const Drivers& drivers);

// What an effect's start_from_residuals reads (EffectResiduals): the
// model's outputs `base` without the effect on `drivers`, the measurements'
// objective rows and measured P_el. Points into its arguments.
EffectResiduals ResidualsForStart(const Drivers& drivers, const SimOutputs& base,
                                  const Measurements& meas);

// Errors of a simulation against measurements (paper 3.2.2).
struct ErrorMetrics {
  std::size_t rows = 0;
  double mae_p_el_w = 0.0;  // whole field, W
  double mae_q_th_w = 0.0;
  double mae_p_el_w_m2 = 0.0;  // per m² of nameplate area
  double mae_q_th_w_m2 = 0.0;
  double nmae_p_el = 0.0;  // MAE / mean |measured|
  double nmae_q_th = 0.0;
  double mae_t_pv_k = 0.0;  // NaN unless T_PV is measured
  double objective_w_m2() const { return mae_p_el_w_m2 + mae_q_th_w_m2; }
};

// Errors over the objective rows. area_m2 is the nameplate area used for the
// per-m² figures. NaN predictions in objective rows make the metrics NaN.
ErrorMetrics ComputeErrors(const Measurements& meas, const SimOutputs& sim, double area_m2);

enum class IdentMethod {
  // Levenberg–Marquardt on IRLS for the MAE (core/fit/lad_fit.h): uses the
  // residual structure, one Jacobian per iteration (see analytic_jacobian).
  kLadLm,
  // A method of NLopt (core/fit/optimizer.h), IdentOptions::optimizer.algorithm.
  kNlopt,
};

struct IdentOptions {
  // Search method. The default is the one that reached the lowest held-out
  // MAE for the least time in `pvtwin-bench ident` (doc/performance.md).
  IdentMethod method = IdentMethod::kLadLm;
  // Budget and tolerances (both methods: max_evaluations, ftol_rel,
  // xtol_rel); algorithm and its settings for kNlopt.
  OptimizerOptions optimizer = DefaultOptimizerOptions();
  // Parameters to identify; empty = DefaultFreeParams(variant). Parameters
  // the variant does not use are never freed.
  std::bitset<kNumParams> free;
  // Add mean |T_PV,calc − T_PV,meas| (weighted) to the objective when the
  // data has t_pv_c.
  bool use_t_pv = false;
  // Weight of the T_PV term, W/(m²K): a temperature error of 1 K costs as
  // much as this flux error.
  double t_pv_weight_w_m2k = 5.0;
  // Prior: prior_weight_w_m2 · Σ (z_j − z_ref,j)² in unit coordinates. 0 = off.
  double prior_weight_w_m2 = 0.01;
  // Fix parameters the data do not determine at their start values (see
  // IdentSummary::estimates) and re-fit.
  bool fix_unidentifiable = true;
  // A free parameter counts as not determined by the data when its standard
  // error (from the sensitivity matrix at the fit, the residual spread and
  // the residuals' autocorrelation) exceeds this fraction of its search range
  // in unit coordinates (log range for log-scaled parameters).
  double undetermined_se = 0.25;
  // Such a parameter is fixed only if the re-fit without it raises the data
  // objective by at most this fraction; otherwise it stays free and is
  // reported as weakly determined.
  double fix_cost_tolerance = 0.01;
  // Fit first on the data averaged to this step (s), then on the data as
  // given from that result; 0 or a step not at least twice the data step
  // disables the coarse stage.
  double coarse_step_s = 300.0;
  // The coarsest rung first fits on every k-th solar day of its data (four
  // or five days; data covering at least 8 days only) to a loose tolerance,
  // and the fit on all the days starts from that optimum when it at least
  // halved its cost, then stops at 0.3 times the coarse tolerance: the far
  // descent from a poor start runs on a third of the rows
  // (core/fit/README.md). With both capacitances free (2N2Cwr), whose
  // network has a second basin that a subset's descent can land in (the
  // nodes merged, U_coll at its upper bound), a fit on all the days from the
  // start follows when the subset's path ends there. False: the fit on all
  // the days from the start.
  bool day_subset_stage = true;
  // lad_lm corrects its trial steps for the bend of the residuals along
  // them (LadFitOptions::max_correction, geodesic acceleration). The coarse
  // stage sets it for its rungs: they walk the curved valley from the
  // start; the fit on the data as given polishes without it (core/fit/README.md).
  bool correct_bends = false;
  // lad_lm's stop before a step in the fit on the data as given after a
  // coarse stage (LadFitOptions::stop_prediction_factor): that fit polishes
  // the coarse optimum, and ends before a step predicted to gain less than
  // this fraction of ftol_rel·O. A fit from the start asks 0.3 of it, a
  // margin the polish does not need: at 1 the fine stage's own fits in the
  // Table 6 protocol take a fifth less time, and its mean MAEs move by at
  // most 0.07 W/m², 0.3 % (core/fit/README.md). The stop on a small decrease
  // keeps its margin (LadFitOptions::stop_promise_factor), and the fixing
  // rounds' fits and the polish after them keep 0.3.
  double polish_stop_prediction_factor = 1.0;
  // Fewest objective rows accepted.
  int min_rows = 30;
  // Search ranges that replace Table 3's (ResolvedInfo) for some
  // parameters: param, lower and upper of each entry count, the rest of the
  // entry is ignored. The gap diagnosis re-fits a parameter that ended at a
  // Table 3 bound in its physical range this way
  // (core/common/physical_ranges.h). Empty: Table 3's for every parameter.
  std::vector<ParamInfo> search_ranges;
  // Take lad_lm's Jacobian, the gradient of NLopt's gradient methods (kLbfgs,
  // kMma) and the identifiability analysis's sensitivity matrix from the
  // model run with sensitivities (core/model/sensitivities.h) where it
  // supports the variant, instead of forward differences of one simulation
  // per free parameter.
  bool analytic_jacobian = true;
  // lad_lm: price the fine stage's start (the coarse optimum after a coarse
  // fit that at least halved its cost, or the start without a coarse stage)
  // with a run with sensitivities, whose Jacobian the fit then takes first,
  // instead of a plain run before it: one plain run less per such start,
  // and the same fit, counts and budget to the bit (its values are
  // Simulate's, core/model/sensitivities.h). False prices it with the plain
  // run, for the test that proves the sameness.
  bool jacobian_ahead = true;
  // Threads one run with sensitivities splits its columns over
  // (SimSensitivities::threads; 1 or 2); with 2 the start's cost on the data
  // as given also runs beside the coarse stage, and the normal equations of
  // large fits are summed as two halves side by side (LadFitOptions::threads,
  // WeightedNormalEquations). The fit is the same to the bit on either;
  // callers that run identifications side by side keep 1.
  int threads = 1;

  static OptimizerOptions DefaultOptimizerOptions();
  // False if a field is out of range; *why names field, value and rule.
  bool IsValid(std::string* why) const;
};

// The search range of p in a fit with these options: Table 3's at the
// plant (ResolvedInfo), or the entry of options.search_ranges for p.
ParamInfo SearchInfo(Param p, const Plant& plant, const IdentOptions& options);

struct ParamEstimate {
  Param param;
  double value = 0.0;
  double start = 0.0;
  double lower = 0.0;
  double upper = 0.0;
  bool free = false;          // identified (false: fixed by the caller or the variant)
  bool at_bound = false;      // within 0.1 % of the search range from a bound
  bool undetermined = false;  // the data do not determine it (fixed at start when asked)
  bool weak = false;          // free, but its standard error exceeds undetermined_se
  double se_unit = 0.0;       // standard error in unit coordinates (0 when not free)
};

// The standard error in the parameter's own unit, from the one in the
// optimiser's unit coordinates (first order: linear scale x = lo + z·(hi −
// lo), log scale x = lo·(hi/lo)^z, dx/dz = x·ln(hi/lo)). NaN when fixed or
// not estimated.
double StdErrorInUnit(const ParamEstimate& e);

// Name used on the command line: "lad_lm" or an NLopt algorithm name.
std::string IdentAlgorithmName(const IdentOptions& options);
// Sets method (and optimizer.algorithm) from such a name; false if unknown.
bool SetIdentAlgorithm(std::string_view name, IdentOptions* options);

struct IdentSummary {
  bool ok = false;
  std::string failure_reason;  // why the fit is rejected, when !ok
  std::string variant;
  std::string algorithm;  // "lad_lm" or the NLopt algorithm's name
  Termination termination = Termination::kFailure;
  double initial_cost_w_m2 = 0.0;  // objective at the start values
  double final_cost_w_m2 = 0.0;    // objective at the result (without the prior)
  // Model simulations charged, all stages (an evaluation at the parameters
  // of the run before it reuses that run's outputs, and is charged too).
  int evaluations = 0;
  // Runs with sensitivities among them (analytic_jacobian), each counted in
  // `evaluations` as kSensitivityRunCost simulations.
  int sensitivity_runs = 0;
  // Charged simulations among `evaluations` that were served from an
  // earlier run's outputs without a model run: repeats of the last run's
  // parameters, and the Jacobian computed ahead (jacobian_ahead).
  int served_runs = 0;
  double runtime_s = 0.0;
  // Time split: the coarse stage's share of runtime_s and of evaluations
  // (its fits; 0 without a coarse stage); the fine stage (the check of the
  // coarse optima on the data as given, fit, identifiability, polish) is
  // the rest.
  double coarse_runtime_s = 0.0;
  int coarse_evaluations = 0;
  // The days of the coarsest rung's first fit when the fit on all the days
  // started from its optimum (IdentOptions::day_subset_stage); 0 otherwise.
  int coarse_subset_days = 0;
  // Of coarse_runtime_s, the fits on a day subset (IdentOptions::
  // day_subset_stage), whether the fit on all the days started from their
  // optimum or not; 0 when there were none.
  double coarse_subset_runtime_s = 0.0;
  // The fine stage's share in the identifiability analysis (the standard
  // errors and the rounds that decide which undetermined parameters to fix,
  // with their predicted costs and trial fits: FixUnidentifiable), its
  // evaluations, and of them those on the coarse stage's data (where the
  // trial fits run when the fit had a coarse stage).
  double fixing_runtime_s = 0.0;
  int fixing_evaluations = 0;
  int fixing_coarse_evaluations = 0;
  // Of fixing_runtime_s, the trial fits (re-fits without the parameter when
  // the predicted cost of fixing it does not decide, with the short fit on
  // the data as given that may follow one).
  double trial_runtime_s = 0.0;
  ParamVector params{};
  std::vector<ParamEstimate> estimates;  // the parameters the variant uses
  std::vector<std::string> notes;        // identifiability findings, in words
  ErrorMetrics train;                    // errors on the training data

  // Names of the free parameters that ended at a bound of their search range.
  std::vector<std::string> AtBounds() const;
  // One line: variant, ok/FAILED, termination, cost start → end, evaluations,
  // runtime; "ok, but N parameters at bounds (names)" when any are.
  std::string BriefReport() const;
  // The time-split printouts' words for the day subset's fit: "first on N
  // of the days, T ms" when the fit on all the days started from its
  // optimum (coarse_subset_days), "a fit on a day subset not taken, T ms"
  // when it ran but did not halve its cost, else empty.
  std::string CoarseSubsetText() const;
};

// What one model run with sensitivities is charged against the simulation
// budget (IdentOptions::optimizer.max_evaluations), in simulations: its
// cost in time for the bench variant's 11 free parameters when it was set
// (`bench sim`: 2N1Ccolwr 4.7–4.8 plain runs). Since the plain run's φ
// functions left expm1 it measures 5.5–5.7; the charge stays 5, since any
// change of the budget moves where the budget-limited fits end.
inline constexpr int kSensitivityRunCost = 5;

// Identifies the parameters of drivers.spec from the measurements, starting
// at `start` (typically StartParams(plant), or yesterday's parameters).
IdentSummary Identify(const Drivers& drivers, const Measurements& meas, const ParamVector& start,
                      const IdentOptions& options);

}  // namespace pvtwin
