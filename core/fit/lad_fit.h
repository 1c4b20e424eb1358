// Least-absolute-deviation fit by Levenberg–Marquardt on iteratively
// reweighted least squares (IRLS).
//
// Minimises   O(z) = Σ_i |r_i(z)| / N_scale + prior_weight · Σ_j (z_j − z_ref,j)²
// over the unit box 0 ≤ z ≤ 1, for a residual function r(z) of many rows and
// few parameters — the paper's MAE objective (3.2.2) in the identification's
// unit coordinates. Each iteration replaces |r_i| by its quadratic majoriser
// r_i²/(2|r̂_i|) + |r̂_i|/2 at the current residuals r̂ (IRLS weights
// 1/max(|r̂_i|, δ)), gets the Jacobian — from the caller's JacobianFunction
// when given (identification: the model's sensitivities), else by forward
// differences, one residual evaluation per free parameter — and takes damped
// Gauss–Newton steps (Levenberg–Marquardt, projected onto the box) that must
// lower O itself.
// This uses the residual structure that a derivative-free method cannot see,
// the same idea as the paper's lsqnonlin on √|r_i|, without the singularity
// of √|r| at zero.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <string>
#include <vector>

namespace pvtwin {

struct LadFitOptions {
  int max_iterations = 500;    // Jacobian evaluations at most
  int max_evaluations = 2000;  // residual evaluations in total
  double ftol_rel = 1e-7;      // stop when an accepted step lowers O by less than this fraction
  // … and either the majoriser's undamped Gauss–Newton step of that
  // iteration promised at most this fraction of ftol_rel·O (½·gᵀH⁻¹g over the
  // parameters the box lets move), or it is the third such step in a row. A
  // step that happened to gain little (damped after a rejection) then does
  // not stop a fit still walking along a curved valley, as the
  // r0_fluid/r1_fluid one is; a promise the steps keep not keeping (a flat
  // direction) holds it two steps at most. A fit also stops before a step
  // predicted to gain less than stop_prediction_factor·ftol_rel·O (the
  // promise times the last accepted step's gain per unit of promise; at the
  // initial weight floor only), so that it ends where its last Jacobian was
  // taken. 0 = stop on the decrease alone, and never before a step.
  double stop_promise_factor = 0.3;
  // The fraction of ftol_rel·O below which a predicted gain stops the fit
  // before its step (above; only while stop_promise_factor is above 0), and
  // below which an undamped promise is a polish that is not stretched. A
  // fit that polishes an optimum found on coarser data takes 1
  // (IdentOptions::polish_stop_prediction_factor).
  double stop_prediction_factor = 0.3;
  double xtol = 1e-7;           // … or moves z by less than this (max norm)
  double jacobian_step = 1e-4;  // forward-difference step in unit coordinates
  // δ = this × mean |r|: caps the IRLS weights 1/max(|r̂|, δ). A floor near
  // the typical residual keeps the majoriser well conditioned; it shapes the
  // steps only, since every step must lower the true O(z). A floor far
  // below the residuals makes the weights, and so the steps, follow the few
  // rows that happen to sit near zero. When no step lowers O, or steps fall
  // below xtol, the floor is divided by 10 (down to 1e-6) before the fit is
  // declared converged, so the exact L1 optimum is reached.
  double weight_floor_rel = 0.3;
  double prior_weight = 0.0;  // see O(z)
  double n_scale = 1.0;       // N_scale in O(z)
  // Residual evaluations one Jacobian of the JacobianFunction is charged,
  // for the budget; ignored without one (forward differences: one per
  // parameter).
  int jacobian_cost = 1;
  // An accepted step s is stretched to the minimiser of the objective along
  // its line, z + α·s with 1 < α ≤ max_stretch, predicted from the
  // residuals at both ends and checked with one more run (kept only if
  // lower). ≤ 1: never stretched.
  double max_stretch = 4.0;
  // A trial step v from z also shows how the residuals bend away from
  // their linearisation along it: e = r(z + v) − r(z) − J·v ≈ ½·vᵀ∇²r·v.
  // The majoriser's step for that bend, c = −(H + λD)⁻¹·JᵀW·e / N_scale
  // over the parameters v moves, is the second-order correction of
  // geodesic acceleration (Transtrum & Sethna, arXiv:1201.5885) with its
  // finite-difference step at 1, so that the trial's own run provides it.
  // The corrected point z + v + c is tried with one more run when
  // min_correction ≤ |c|/|v| ≤ max_correction (max norms) and kept if
  // lower than the trial: in a curved valley (the r0_fluid/r1_fluid one)
  // plain steps leave the valley floor and are cut short by the damping.
  // max_correction ≤ 0: never corrected.
  double max_correction = 3.0;
  double min_correction = 0.1;  // a smaller correction is not worth its run
  // After an iteration that took a Jacobian (costing more than one
  // residual evaluation) and accepted a step s no longer than this (max
  // norm in z), the next iteration takes that Jacobian with Broyden's
  // rank-one secant update along s instead of a new one:
  // J + u·sᵀ, u = (r(z + s) − r(z) − J·s) / sᵀs, which the step's own runs
  // give. The iteration after takes a Jacobian again, and so does a secant
  // iteration that finds no step. Near the optimum a fit walks its valley
  // in many short steps, along which J barely changes, and a run with
  // sensitivities costs five plain ones or more; after a long step the
  // update misleads more than it saves (from Table 3's start the fits took
  // more runs). The returned Jacobian (LadFitResult::jacobian) is always
  // one that was taken, never an update. 0: never.
  double secant_max_step = 0.05;
  // Threads for the normal equations of an iteration (1 or 2; see
  // WeightedNormalEquations). The fit is the same on either.
  int threads = 1;
};

struct LadFitResult {
  Eigen::VectorXd z;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  int evaluations = 0;
  int stretched = 0;  // accepted steps whose stretch (max_stretch) was kept
  int corrected = 0;  // trials whose correction for the bend (max_correction) was kept
  bool converged = false;
  std::string message;
  // The last Jacobian computed (rows × free parameters), for the caller's
  // identifiability analysis, and how far the returned point is from where
  // it was computed (max norm in z; 0: at the returned point). A fit
  // usually ends on an accepted short step, and a run with sensitivities
  // at 5-s data costs as much as five plain runs: the caller decides
  // whether the Jacobian one short step back will do.
  Eigen::MatrixXd jacobian;
  double jacobian_distance = 0.0;
  Eigen::VectorXd weights;  // IRLS weights used with that Jacobian
};

// residuals(z, r) fills r (resized by the callee) and returns false if the
// residuals are not finite.
using ResidualFunction = std::function<bool(const Eigen::VectorXd& z, Eigen::VectorXd* r)>;

// jacobian(z, r, jac) fills jac (rows of r × parameters) at z, where the
// residuals are r; false when it cannot (LadFit then takes forward
// differences for that iteration). A column it cannot give (non-finite) it
// leaves zero: no direction.
using JacobianFunction =
    std::function<bool(const Eigen::VectorXd& z, const Eigen::VectorXd& r, Eigen::MatrixXd* jac)>;

// Rows of the Jacobian from which WeightedNormalEquations sums the two
// halves of the rows apart.
inline constexpr Eigen::Index kSplitNormalEquationsRows = Eigen::Index{1} << 17;

// H = JᵀW·J and g = JᵀW·r, W = diag(w), summed over blocks of rows; with w
// empty, H = JᵀJ alone (r unread, g left alone). From
// kSplitNormalEquationsRows rows on (65 536 rows in the objective, two
// residuals each: 14 days at 15 s, 46 days at 1 min), the first and the second
// half of the rows are summed apart and then added, the second half on a helper
// thread when threads > 1: at 5-s data one sum took 20 ms of each iteration on
// one core. The sums, and so H and g, are the same on one thread and on two.
// H is symmetric to the bit: one triangle is summed, the other mirrored.
void WeightedNormalEquations(const Eigen::MatrixXd& jac, const Eigen::VectorXd& w,
                             const Eigen::VectorXd& r, int threads, Eigen::MatrixXd* h,
                             Eigen::VectorXd* g);

// jacobian empty: forward differences of `residuals`.
LadFitResult LadFit(const ResidualFunction& residuals, const Eigen::VectorXd& z0,
                    const Eigen::VectorXd& z_ref, const LadFitOptions& options,
                    const JacobianFunction& jacobian = nullptr);

}  // namespace pvtwin
