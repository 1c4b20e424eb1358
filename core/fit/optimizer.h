// A generic bounded minimiser for identification: minimise cost(x) subject to
// lower <= x <= upper, with a choice of local, gradient and global methods.
//
// The search runs in a unit box. Each variable is mapped to z in [0, 1]:
//   linear:  x = lower + z · (upper − lower)
//   log:     x = lower · (upper / lower)^z        (Bounds::log_scale, lower > 0)
// so a relative step means the same in every direction, whether the variable
// is an efficiency near 0.15 or a capacitance spanning 1e3…1e7 J/(m²K).
// Tolerances and OptimizerOptions::initial_step are in these unit coordinates.
// A variable with lower == upper is held fixed and not searched.
//
// The backend (NLopt) is hidden in optimizer_nlopt.cc; no NLopt type appears
// here. Minimize() never throws on bad input or a failed search: the result
// carries a Termination and a message.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pvtwin {

enum class OptAlgorithm {
  kBobyqa,      // NLopt LN_BOBYQA: bounded quadratic-model trust region (Powell)
  kSbplx,       // NLopt LN_SBPLX: Nelder–Mead on subspaces (Rowan's Subplex)
  kNelderMead,  // NLopt LN_NELDERMEAD
  kCobyla,      // NLopt LN_COBYLA: linear approximations (Powell)
  kLbfgs,       // NLopt LD_LBFGS: needs a gradient
  kMma,         // NLopt LD_MMA: method of moving asymptotes, needs a gradient
  // Global stage NLopt GN_CRS2_LM (controlled random search with local
  // mutation) for OptimizerOptions::global_evaluations, then a BOBYQA polish
  // from the best point with the rest of the budget.
  kCrs2Bobyqa,
  // BOBYQA from the start point, then from multistart_count quasi-random
  // points (seeded R_d sequence, see Minimize); the best result is kept.
  kMultiStartBobyqa,
  // NLopt G_MLSL_LDS (multi-level single linkage on a Sobol sequence) with
  // BOBYQA as the local method, for OptimizerOptions::global_evaluations,
  // then a BOBYQA polish from the best point with the rest of the budget.
  kMlslBobyqa,
};

inline constexpr std::array<OptAlgorithm, 9> kAllOptAlgorithms = {
    OptAlgorithm::kBobyqa,     OptAlgorithm::kSbplx,
    OptAlgorithm::kNelderMead, OptAlgorithm::kCobyla,
    OptAlgorithm::kLbfgs,      OptAlgorithm::kMma,
    OptAlgorithm::kCrs2Bobyqa, OptAlgorithm::kMultiStartBobyqa,
    OptAlgorithm::kMlslBobyqa,
};

// Config names: "bobyqa", "sbplx", "nelder_mead", "cobyla", "lbfgs", "mma",
// "crs2_bobyqa", "multistart_bobyqa", "mlsl_bobyqa".
std::string_view ToString(OptAlgorithm algorithm);
std::optional<OptAlgorithm> OptAlgorithmFromString(std::string_view name);

// True for the methods that need the cost function to fill its gradient.
bool NeedsGradient(OptAlgorithm algorithm);

enum class Termination {
  kConverged,        // ftol_rel or xtol_rel reached
  kMaxEvaluations,   // the evaluation budget ran out
  kMaxTime,          // max_time_s ran out
  kRoundoffLimited,  // no further progress possible in floating point
  kInvalidArgs,      // bad options, bounds or start point (see message)
  kOutOfMemory,      // the backend could not allocate
  kFailure,          // the backend failed for another reason (see message)
  kForcedStop,       // stopped from inside the backend without a budget reason
  kNonFiniteCost,    // the cost was never finite
};

// "converged", "max_evaluations", "max_time", "roundoff_limited",
// "invalid_args", "out_of_memory", "failure", "forced_stop", "non_finite_cost".
std::string_view ToString(Termination termination);

struct OptimizerOptions {
  OptAlgorithm algorithm = OptAlgorithm::kBobyqa;
  // Stop when one step changes the cost by less than ftol_rel·|cost|. >= 0.
  double ftol_rel = 1e-10;
  // Stop when one step moves every unit coordinate by less than xtol_rel·|z|
  // (BOBYQA: when its trust radius falls below xtol_rel·initial_step). >= 0.
  double xtol_rel = 1e-8;
  // Cost evaluations allowed in total, over all stages and starts, including
  // the evaluation of the start point. >= 1.
  int max_evaluations = 2000;
  // Wall-clock limit for the whole search in seconds; 0 = no limit.
  double max_time_s = 0;
  // kMultiStartBobyqa: quasi-random starts besides the start point. >= 0.
  int multistart_count = 8;
  // kCrs2Bobyqa, kMlslBobyqa: evaluations given to the global stage (capped
  // by what is left of max_evaluations); the BOBYQA polish gets the rest.
  // >= 1.
  int global_evaluations = 400;
  // Local runs (every local method, each multi-start start, the polish) that
  // stop on their tolerances are restarted from their answer with a fresh
  // initial_step while a restart lowers the cost by more than
  // ftol_rel·|cost|, at most this many times. A non-smooth cost (a mean
  // absolute error) can make a trust region or simplex collapse onto a kink
  // far from the minimum; a restart gets it moving again. 0 = no restarts.
  // >= 0.
  int max_restarts = 10;
  // First step of the derivative-free local methods, in unit coordinates.
  // In (0, 0.5]: BOBYQA needs the box to be at least two steps wide.
  double initial_step = 0.1;
  // Seed for the stochastic and quasi-random parts; the same seed gives the
  // same sequence of evaluations.
  std::uint64_t seed = 1;

  // False if a field is out of range; *why (if given) then names the field,
  // its value and the rule, e.g. "max_evaluations = 0: must be >= 1".
  bool IsValid(std::string* why) const;
};

struct Bounds {
  std::vector<double> lower;  // finite, one per variable
  std::vector<double> upper;  // finite, >= lower
  // Empty (all linear) or one per variable; true searches log10(x), which
  // needs lower > 0.
  std::vector<bool> log_scale;

  // False if the bounds do not fit `dimension` variables or break a rule
  // above; *why (if given) names the entry, its value and the rule.
  bool IsValid(std::size_t dimension, std::string* why) const;
};

struct OptimizerResult {
  OptAlgorithm algorithm = OptAlgorithm::kBobyqa;
  Termination termination = Termination::kFailure;
  std::string message;             // what stopped the search, for the log
  std::vector<double> x;           // best point found, in the caller's coordinates
  double initial_cost = 0;         // cost at the (clamped) start point
  double final_cost = 0;           // cost at x; NaN if no evaluation was finite
  int evaluations = 0;             // calls of the cost function
  int non_finite_evaluations = 0;  // of those, how many returned NaN or ±inf
  double runtime_s = 0;

  // The search stopped normally (converged, budget, time, or round-off
  // limited) and x has a finite cost no worse than the start point's.
  bool ok() const;
  // One line: algorithm, termination, initial → final cost, evaluations,
  // runtime.
  std::string BriefReport() const;
};

// Cost at x, in the caller's coordinates (x lies within the bounds). When grad
// is non-empty (only for NeedsGradient() algorithms) it has x.size() entries
// to fill with ∂cost/∂x. Must not throw (a throw terminates the process).
// A NaN or infinite return is counted and shown to the optimiser as a very
// large cost (1e30).
using CostFunction = std::function<double(std::span<const double> x, std::span<double> grad)>;

// Minimise cost over the box, starting at x0 (clamped into the box).
//
// The evaluation budget is shared as follows: 1 evaluation for the start
// point; kCrs2Bobyqa and kMlslBobyqa give min(global_evaluations, rest) to
// the global stage (which normally uses all of it) and what is left to the
// BOBYQA polish; kMultiStartBobyqa splits what is left evenly over the
// 1 + multistart_count starts, recomputed before each start so that a start
// that converges early leaves its evaluations to the later ones. Restarts of
// a local run come out of that run's share.
//
// The quasi-random starts of kMultiStartBobyqa follow the additive recurrence
// z_k = frac(s + k·α) with α_j = φ_d^-(j+1), φ_d the real root of
// φ^(d+1) = φ + 1 (Roberts 2018, the R_d sequence), shifted by s drawn from
// the seed (SplitMix64).
//
// The stochastic NLopt methods use NLopt's random generator, which is seeded
// from options.seed before each stage; that state is per thread (and is left
// seeded afterwards). There is no other shared state: calls in different
// threads are independent.
//
// On a non-smooth cost (a mean absolute error) the simplex methods (kSbplx,
// kNelderMead) are the most robust. BOBYQA and the methods built on it need
// the kinks to weigh roughly alike in unit coordinates (log scale where a
// parameter acts relatively) and rely on the restarts; with kinks whose
// slopes differ by 1e4 they stall 30 % from the minimum. COBYLA stalls on
// kinks even when they weigh alike. (tests/unit/test_optimizer.cc)
//
// Termination reports the run that produced the returned point (the polish
// stage for kCrs2Bobyqa, the best start for kMultiStartBobyqa), or
// kMaxEvaluations / kMaxTime when the budget ran out inside it, or
// kNonFiniteCost when no evaluation was finite.
OptimizerResult Minimize(const CostFunction& cost, std::span<const double> x0, const Bounds& bounds,
                         const OptimizerOptions& options);

// The map between the caller's coordinates and the unit box searched by
// Minimize (see the top of this file). Exposed so that callers can express
// steps in unit coordinates and tests can check the gradient chain rule.
class UnitBox {
 public:
  // bounds must be valid (Bounds::IsValid) for the dimension it holds.
  explicit UnitBox(const Bounds& bounds);

  std::size_t dimension() const { return lower_.size(); }
  // Variables searched (lower < upper); the others are fixed at lower.
  std::size_t free_dimension() const { return free_.size(); }

  // z (free_dimension entries) from x (dimension entries); x is clamped into
  // the box first.
  void ToUnit(std::span<const double> x, std::span<double> z) const;
  // x (dimension entries) from z (free_dimension entries, clamped to [0, 1]);
  // fixed variables get their bound. Exact at the bounds.
  void FromUnit(std::span<const double> z, std::span<double> x) const;
  // Chain rule: grad_z[j] = grad_x[i] · ∂x_i/∂z_j for the j-th free variable
  // i, evaluated at x (the point FromUnit gave).
  void GradientToUnit(std::span<const double> x, std::span<const double> grad_x,
                      std::span<double> grad_z) const;

 private:
  std::vector<double> lower_, upper_;
  std::vector<bool> log_;
  std::vector<double> width_;  // upper − lower, or ln(upper / lower) if log
  std::vector<std::size_t> free_;
};

}  // namespace pvtwin
