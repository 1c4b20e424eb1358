// NLopt backend of core/fit/optimizer.h. This is the only file that includes
// NLopt; it uses the C API, so nothing here throws and every NLopt result
// code is mapped to a Termination.
//
// Every run sees the unit box [0, 1]^n_free (see UnitBox). The objective
// trampoline counts evaluations itself, keeps the best point over all stages
// and starts, refuses to evaluate past the evaluation budget or the deadline
// (it then asks NLopt to stop), and does not allocate.
#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "core/fit/optimizer.h"

namespace pvtwin {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// What the optimiser sees when the cost is NaN or infinite: large enough to
// lose against any real cost, small enough to keep quadratic models finite.
constexpr double kNonFinitePenalty = 1e30;

template <typename... Args>
std::string Format(const char* format, Args... args) {
  const int size = std::snprintf(nullptr, 0, format, args...);
  if (size <= 0) return {};
  std::string text(static_cast<std::size_t>(size), '\0');
  std::snprintf(text.data(), text.size() + 1, format, args...);
  return text;
}

// a is a finite cost lower than b, or b is not finite.
bool Better(double a, double b) { return std::isfinite(a) && (!std::isfinite(b) || a < b); }

// Owns an nlopt_opt.
class NloptHandle {
 public:
  NloptHandle(nlopt_algorithm algorithm, unsigned n) : opt_(nlopt_create(algorithm, n)) {}
  ~NloptHandle() { nlopt_destroy(opt_); }
  NloptHandle(const NloptHandle&) = delete;
  NloptHandle& operator=(const NloptHandle&) = delete;
  nlopt_opt get() const { return opt_; }
  explicit operator bool() const { return opt_ != nullptr; }

 private:
  nlopt_opt opt_;
};

// State shared by all stages of one Minimize call; the objective trampoline
// works on it through the void* NLopt hands back.
struct Search {
  const CostFunction* cost = nullptr;
  const UnitBox* box = nullptr;
  std::vector<double> x;       // scratch: the point in caller coordinates
  std::vector<double> grad_x;  // scratch: the caller's gradient
  std::vector<double> best_x;  // best point so far, caller coordinates
  std::vector<double> best_z;  // the same point in unit coordinates
  double best_cost = kNaN;     // NaN until a finite cost is seen
  int evaluations = 0;
  int max_evaluations = 0;
  int non_finite_evaluations = 0;
  bool has_deadline = false;
  Clock::time_point deadline;
  bool out_of_evaluations = false;  // the trampoline refused an evaluation
  bool out_of_time = false;         // the trampoline saw the deadline pass
  nlopt_opt active = nullptr;       // the run to stop when a budget is hit

  // Cost at unit point z; fills grad_z if it is non-empty. Returns the raw
  // cost, which may be non-finite.
  double Evaluate(std::span<const double> z, std::span<double> grad_z) {
    box->FromUnit(z, x);
    std::span<double> grad;
    if (!grad_z.empty()) {
      std::fill(grad_x.begin(), grad_x.end(), 0.0);
      grad = grad_x;
    }
    const double cost_value = (*cost)(x, grad);
    ++evaluations;
    if (!std::isfinite(cost_value)) {
      ++non_finite_evaluations;
      std::fill(grad_z.begin(), grad_z.end(), 0.0);
      return cost_value;
    }
    if (Better(cost_value, best_cost)) {
      best_cost = cost_value;
      std::copy(x.begin(), x.end(), best_x.begin());
      for (std::size_t j = 0; j < z.size(); ++j) best_z[j] = std::clamp(z[j], 0.0, 1.0);
    }
    if (!grad_z.empty()) box->GradientToUnit(x, grad_x, grad_z);
    return cost_value;
  }

  double SecondsLeft() const {
    return std::chrono::duration<double>(deadline - Clock::now()).count();
  }
};

// The nlopt_func handed to every run.
double Objective(unsigned n, const double* z, double* grad_z, void* data) noexcept {
  Search& search = *static_cast<Search*>(data);
  const std::span<double> grad = grad_z ? std::span<double>(grad_z, n) : std::span<double>();
  const bool out_of_evaluations = search.evaluations >= search.max_evaluations;
  const bool out_of_time =
      !out_of_evaluations && search.has_deadline && Clock::now() >= search.deadline;
  if (out_of_evaluations || out_of_time) {
    search.out_of_evaluations = search.out_of_evaluations || out_of_evaluations;
    search.out_of_time = search.out_of_time || out_of_time;
    if (search.active != nullptr) nlopt_force_stop(search.active);
    std::fill(grad.begin(), grad.end(), 0.0);
    return kNonFinitePenalty;
  }
  const double cost = search.Evaluate(std::span<const double>(z, n), grad);
  return std::isfinite(cost) ? cost : kNonFinitePenalty;
}

Termination FromNlopt(nlopt_result code, const Search& search) {
  switch (code) {
    case NLOPT_SUCCESS:
    case NLOPT_STOPVAL_REACHED:
    case NLOPT_FTOL_REACHED:
    case NLOPT_XTOL_REACHED:
      return Termination::kConverged;
    case NLOPT_MAXEVAL_REACHED:
      return Termination::kMaxEvaluations;
    case NLOPT_MAXTIME_REACHED:
      return Termination::kMaxTime;
    case NLOPT_INVALID_ARGS:
      return Termination::kInvalidArgs;
    case NLOPT_OUT_OF_MEMORY:
      return Termination::kOutOfMemory;
    default:
      break;
  }
  // Some methods (L-BFGS) do not check the stop flag and fail on the penalty
  // the trampoline returns once the budget is spent: the budget is the reason.
  if (search.out_of_evaluations) return Termination::kMaxEvaluations;
  if (search.out_of_time) return Termination::kMaxTime;
  if (code == NLOPT_ROUNDOFF_LIMITED) return Termination::kRoundoffLimited;
  if (code == NLOPT_FORCED_STOP) return Termination::kForcedStop;
  return Termination::kFailure;
}

struct RunOutcome {
  Termination termination = Termination::kFailure;
  std::string message;
  double minimum = kNaN;  // NLopt's minimum for the run (penalised if non-finite)
};

std::string Named(std::string_view name, const char* what) {
  return Format("%.*s: %s", static_cast<int>(name.size()), name.data(), what);
}

// The unit box and the options' tolerances; the first step for local runs.
void Configure(nlopt_opt opt, const OptimizerOptions& options, bool local) {
  nlopt_set_lower_bounds1(opt, 0.0);
  nlopt_set_upper_bounds1(opt, 1.0);
  nlopt_set_ftol_rel(opt, options.ftol_rel);
  nlopt_set_xtol_rel(opt, options.xtol_rel);
  if (local) nlopt_set_initial_step1(opt, options.initial_step);
}

// Runs opt from z (updated to NLopt's answer) with at most `cap` evaluations
// (0 = whatever is left of the budget).
RunOutcome Run(Search& search, nlopt_opt opt, std::string_view name, std::vector<double>& z,
               int cap) {
  RunOutcome outcome;
  const int left = search.max_evaluations - search.evaluations;
  if (left <= 0) {
    search.out_of_evaluations = true;
    outcome.termination = Termination::kMaxEvaluations;
    outcome.message = Named(name, "not run, no evaluations left");
    return outcome;
  }
  nlopt_set_maxeval(opt, cap > 0 ? std::min(cap, left) : left);
  if (search.has_deadline) {
    const double seconds_left = search.SecondsLeft();
    if (seconds_left <= 0) {
      search.out_of_time = true;
      outcome.termination = Termination::kMaxTime;
      outcome.message = Named(name, "not run, no time left");
      return outcome;
    }
    nlopt_set_maxtime(opt, seconds_left);
  }
  nlopt_set_min_objective(opt, Objective, &search);
  for (double& zj : z) zj = std::clamp(zj, 0.0, 1.0);
  search.active = opt;
  const nlopt_result code = nlopt_optimize(opt, z.data(), &outcome.minimum);
  search.active = nullptr;
  outcome.termination = FromNlopt(code, search);
  outcome.message = Named(name, nlopt_result_to_string(code));
  const char* detail = nlopt_get_errmsg(opt);
  if (detail != nullptr && detail[0] != '\0') outcome.message += Format(" (%s)", detail);
  if (outcome.termination == Termination::kMaxEvaluations && code != NLOPT_MAXEVAL_REACHED) {
    outcome.message += ", evaluation budget used up";
  } else if (outcome.termination == Termination::kMaxTime && code != NLOPT_MAXTIME_REACHED) {
    outcome.message += ", deadline passed";
  }
  return outcome;
}

RunOutcome OutOfMemory(std::string_view name) {
  return {Termination::kOutOfMemory, Named(name, "NLopt could not create the optimiser"), kNaN};
}

// A local search from z (updated to its best point) with at most `cap`
// evaluations (0 = the rest of the budget). A run that stops on its
// tolerances is restarted from its answer with a fresh initial step, up to
// options.max_restarts times, while a restart lowers the cost by more than
// ftol_rel·|cost|: on a non-smooth cost a trust region or simplex can shrink
// onto a kink (or a face of the box) far from the minimum, and a fresh step
// gets it moving again.
RunOutcome RunLocal(Search& search, nlopt_algorithm algorithm, std::string_view name,
                    std::vector<double>& z, const OptimizerOptions& options, int cap) {
  NloptHandle opt(algorithm, static_cast<unsigned>(z.size()));
  if (!opt) return OutOfMemory(name);
  Configure(opt.get(), options, /*local=*/true);
  const int end =
      cap > 0 ? std::min(search.max_evaluations, search.evaluations + cap) : search.max_evaluations;
  RunOutcome outcome = Run(search, opt.get(), name, z, end - search.evaluations);
  std::vector<double> best_z = z;
  double best = outcome.minimum;
  int restarts = 0;
  while (restarts < options.max_restarts &&
         (outcome.termination == Termination::kConverged ||
          outcome.termination == Termination::kRoundoffLimited) &&
         end - search.evaluations > 0) {
    ++restarts;
    z = best_z;
    outcome = Run(search, opt.get(), name, z, end - search.evaluations);
    const bool improved = outcome.minimum < best - options.ftol_rel * std::abs(best);
    if (outcome.minimum < best) {
      best = outcome.minimum;
      best_z = z;
    }
    if (!improved) break;
  }
  z = best_z;
  outcome.minimum = best;
  if (restarts > 0) {
    outcome.message += Format(" after %d restart%s", restarts, restarts == 1 ? "" : "s");
  }
  return outcome;
}

// The R_d quasi-random sequence (Roberts 2018): z_k = frac(s + k·α) with
// α_j = φ_d^-(j+1), φ_d the real root of φ^(d+1) = φ + 1, and the shift s
// drawn from the seed.
class RdSequence {
 public:
  RdSequence(std::size_t dimension, std::uint64_t seed) : alpha_(dimension), shift_(dimension) {
    double phi = 2.0;
    for (int i = 0; i < 64; ++i) {
      phi = std::pow(1.0 + phi, 1.0 / static_cast<double>(dimension + 1));
    }
    std::uint64_t state = seed;
    for (std::size_t j = 0; j < dimension; ++j) {
      alpha_[j] = std::fmod(std::pow(1.0 / phi, static_cast<double>(j + 1)), 1.0);
      shift_[j] = static_cast<double>(SplitMix64(state) >> 11) * 0x1.0p-53;
    }
  }

  void Next(std::span<double> z) {
    ++k_;
    for (std::size_t j = 0; j < z.size(); ++j) {
      const double value = shift_[j] + static_cast<double>(k_) * alpha_[j];
      z[j] = value - std::floor(value);
    }
  }

 private:
  static std::uint64_t SplitMix64(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  std::vector<double> alpha_, shift_;
  std::uint64_t k_ = 0;
};

nlopt_algorithm LocalAlgorithm(OptAlgorithm algorithm) {
  switch (algorithm) {
    case OptAlgorithm::kSbplx:
      return NLOPT_LN_SBPLX;
    case OptAlgorithm::kNelderMead:
      return NLOPT_LN_NELDERMEAD;
    case OptAlgorithm::kCobyla:
      return NLOPT_LN_COBYLA;
    case OptAlgorithm::kLbfgs:
      return NLOPT_LD_LBFGS;
    case OptAlgorithm::kMma:
      return NLOPT_LD_MMA;
    default:
      return NLOPT_LN_BOBYQA;
  }
}

// A global stage with min(global_evaluations, rest) evaluations, then a
// BOBYQA polish from the best point seen with the rest.
RunOutcome RunGlobalThenPolish(Search& search, nlopt_opt global_opt, std::string_view name,
                               std::vector<double> z, const OptimizerOptions& options) {
  nlopt_srand(static_cast<unsigned long>(options.seed));
  const RunOutcome global = Run(search, global_opt, name, z, options.global_evaluations);
  if (global.termination == Termination::kInvalidArgs ||
      global.termination == Termination::kOutOfMemory) {
    return global;
  }
  if (std::isfinite(search.best_cost)) z = search.best_z;
  RunOutcome polish = RunLocal(search, NLOPT_LN_BOBYQA, "bobyqa polish", z, options, 0);
  polish.message = global.message + "; " + polish.message;
  return polish;
}

RunOutcome RunCrs2Bobyqa(Search& search, const std::vector<double>& z0,
                         const OptimizerOptions& options) {
  NloptHandle opt(NLOPT_GN_CRS2_LM, static_cast<unsigned>(z0.size()));
  if (!opt) return OutOfMemory("crs2");
  Configure(opt.get(), options, /*local=*/false);
  return RunGlobalThenPolish(search, opt.get(), "crs2", z0, options);
}

RunOutcome RunMlslBobyqa(Search& search, const std::vector<double>& z0,
                         const OptimizerOptions& options) {
  const auto n = static_cast<unsigned>(z0.size());
  NloptHandle opt(NLOPT_G_MLSL_LDS, n);
  NloptHandle local(NLOPT_LN_BOBYQA, n);
  if (!opt || !local) return OutOfMemory("mlsl");
  Configure(opt.get(), options, /*local=*/false);
  Configure(local.get(), options, /*local=*/true);
  nlopt_set_local_optimizer(opt.get(), local.get());
  return RunGlobalThenPolish(search, opt.get(), "mlsl", z0, options);
}

RunOutcome RunMultiStart(Search& search, const std::vector<double>& z0,
                         const OptimizerOptions& options) {
  const int starts = 1 + options.multistart_count;
  RdSequence sequence(z0.size(), options.seed);
  std::vector<double> z(z0.size());
  RunOutcome best;
  int completed = 0;
  for (int k = 0; k < starts; ++k) {
    const int left = search.max_evaluations - search.evaluations;
    if (left <= 0) break;
    if (k == 0) {
      z = z0;
    } else {
      sequence.Next(z);
    }
    const int share = std::max(1, left / (starts - k));
    const double best_before = search.best_cost;
    const std::string name = Format("bobyqa start %d/%d", k + 1, starts);
    RunOutcome outcome = RunLocal(search, NLOPT_LN_BOBYQA, name, z, options, share);
    ++completed;
    if (k == 0 || Better(search.best_cost, best_before)) best = std::move(outcome);
  }
  if (completed < starts) {
    best.termination = search.out_of_time ? Termination::kMaxTime : Termination::kMaxEvaluations;
    best.message += Format("; only %d of %d starts ran", completed, starts);
  }
  if (completed > 0) best.message = "best of " + best.message;
  return best;
}

}  // namespace

std::string_view ToString(OptAlgorithm algorithm) {
  switch (algorithm) {
    case OptAlgorithm::kBobyqa:
      return "bobyqa";
    case OptAlgorithm::kSbplx:
      return "sbplx";
    case OptAlgorithm::kNelderMead:
      return "nelder_mead";
    case OptAlgorithm::kCobyla:
      return "cobyla";
    case OptAlgorithm::kLbfgs:
      return "lbfgs";
    case OptAlgorithm::kMma:
      return "mma";
    case OptAlgorithm::kCrs2Bobyqa:
      return "crs2_bobyqa";
    case OptAlgorithm::kMultiStartBobyqa:
      return "multistart_bobyqa";
    case OptAlgorithm::kMlslBobyqa:
      return "mlsl_bobyqa";
  }
  return "unknown";
}

std::optional<OptAlgorithm> OptAlgorithmFromString(std::string_view name) {
  for (OptAlgorithm algorithm : kAllOptAlgorithms) {
    if (ToString(algorithm) == name) return algorithm;
  }
  return std::nullopt;
}

bool NeedsGradient(OptAlgorithm algorithm) {
  return algorithm == OptAlgorithm::kLbfgs || algorithm == OptAlgorithm::kMma;
}

std::string_view ToString(Termination termination) {
  switch (termination) {
    case Termination::kConverged:
      return "converged";
    case Termination::kMaxEvaluations:
      return "max_evaluations";
    case Termination::kMaxTime:
      return "max_time";
    case Termination::kRoundoffLimited:
      return "roundoff_limited";
    case Termination::kInvalidArgs:
      return "invalid_args";
    case Termination::kOutOfMemory:
      return "out_of_memory";
    case Termination::kFailure:
      return "failure";
    case Termination::kForcedStop:
      return "forced_stop";
    case Termination::kNonFiniteCost:
      return "non_finite_cost";
  }
  return "unknown";
}

bool OptimizerOptions::IsValid(std::string* why) const {
  std::string problem;
  if (ToString(algorithm) == "unknown") {
    problem = Format("algorithm = %d: not a known algorithm", static_cast<int>(algorithm));
  } else if (!std::isfinite(ftol_rel) || ftol_rel < 0) {
    problem = Format("ftol_rel = %g: must be finite and >= 0", ftol_rel);
  } else if (!std::isfinite(xtol_rel) || xtol_rel < 0) {
    problem = Format("xtol_rel = %g: must be finite and >= 0", xtol_rel);
  } else if (max_evaluations < 1) {
    problem = Format("max_evaluations = %d: must be >= 1", max_evaluations);
  } else if (!std::isfinite(max_time_s) || max_time_s < 0) {
    problem = Format("max_time_s = %g: must be finite and >= 0 (0 = no limit)", max_time_s);
  } else if (multistart_count < 0) {
    problem = Format("multistart_count = %d: must be >= 0", multistart_count);
  } else if (max_restarts < 0) {
    problem = Format("max_restarts = %d: must be >= 0", max_restarts);
  } else if (global_evaluations < 1) {
    problem = Format("global_evaluations = %d: must be >= 1", global_evaluations);
  } else if (!(initial_step > 0 && initial_step <= 0.5)) {
    problem = Format("initial_step = %g: must be in (0, 0.5] (unit-box coordinates)", initial_step);
  }
  if (problem.empty()) return true;
  if (why != nullptr) *why = std::move(problem);
  return false;
}

bool Bounds::IsValid(std::size_t dimension, std::string* why) const {
  std::string problem;
  if (lower.size() != dimension) {
    problem = Format("bounds.lower has %zu entries: must have %zu (one per variable)", lower.size(),
                     dimension);
  } else if (upper.size() != dimension) {
    problem = Format("bounds.upper has %zu entries: must have %zu (one per variable)", upper.size(),
                     dimension);
  } else if (!log_scale.empty() && log_scale.size() != dimension) {
    problem = Format("bounds.log_scale has %zu entries: must be empty or have %zu",
                     log_scale.size(), dimension);
  } else {
    for (std::size_t i = 0; i < dimension && problem.empty(); ++i) {
      const bool log = !log_scale.empty() && log_scale[i];
      if (!std::isfinite(lower[i])) {
        problem = Format("bounds.lower[%zu] = %g: must be finite", i, lower[i]);
      } else if (!std::isfinite(upper[i])) {
        problem = Format("bounds.upper[%zu] = %g: must be finite", i, upper[i]);
      } else if (upper[i] < lower[i]) {
        problem = Format("bounds.upper[%zu] = %g: must be >= bounds.lower[%zu] = %g", i, upper[i],
                         i, lower[i]);
      } else if (log && !(lower[i] > 0)) {
        problem =
            Format("bounds.lower[%zu] = %g: must be > 0 for a log-scaled variable", i, lower[i]);
      }
    }
  }
  if (problem.empty()) return true;
  if (why != nullptr) *why = std::move(problem);
  return false;
}

bool OptimizerResult::ok() const {
  const bool stopped_normally =
      termination == Termination::kConverged || termination == Termination::kMaxEvaluations ||
      termination == Termination::kMaxTime || termination == Termination::kRoundoffLimited;
  return stopped_normally && std::isfinite(final_cost) &&
         (!std::isfinite(initial_cost) || final_cost <= initial_cost);
}

std::string OptimizerResult::BriefReport() const {
  const std::string_view algorithm_name = ToString(algorithm);
  const std::string_view termination_name = ToString(termination);
  std::string report = Format("%.*s: %.*s, cost %.6g -> %.6g, %d evaluations, %.3f s",
                              static_cast<int>(algorithm_name.size()), algorithm_name.data(),
                              static_cast<int>(termination_name.size()), termination_name.data(),
                              initial_cost, final_cost, evaluations, runtime_s);
  if (non_finite_evaluations > 0) report += Format(" (%d non-finite)", non_finite_evaluations);
  return report;
}

UnitBox::UnitBox(const Bounds& bounds)
    : lower_(bounds.lower),
      upper_(bounds.upper),
      log_(bounds.lower.size(), false),
      width_(bounds.lower.size(), 0.0) {
  if (!bounds.log_scale.empty()) log_ = bounds.log_scale;
  for (std::size_t i = 0; i < lower_.size(); ++i) {
    width_[i] = log_[i] ? std::log(upper_[i]) - std::log(lower_[i]) : upper_[i] - lower_[i];
    if (upper_[i] > lower_[i]) free_.push_back(i);
  }
}

void UnitBox::ToUnit(std::span<const double> x, std::span<double> z) const {
  for (std::size_t j = 0; j < free_.size(); ++j) {
    const std::size_t i = free_[j];
    const double xi = std::clamp(x[i], lower_[i], upper_[i]);
    const double zj = log_[i] ? std::log(xi / lower_[i]) / width_[i] : (xi - lower_[i]) / width_[i];
    z[j] = std::clamp(zj, 0.0, 1.0);
  }
}

void UnitBox::FromUnit(std::span<const double> z, std::span<double> x) const {
  for (std::size_t i = 0; i < lower_.size(); ++i) x[i] = lower_[i];
  for (std::size_t j = 0; j < free_.size(); ++j) {
    const std::size_t i = free_[j];
    const double zj = z[j];
    double xi;
    if (!(zj > 0)) {
      xi = lower_[i];
    } else if (zj >= 1) {
      xi = upper_[i];
    } else if (log_[i]) {
      xi = lower_[i] * std::exp(zj * width_[i]);
    } else {
      xi = lower_[i] + zj * width_[i];
    }
    x[i] = std::clamp(xi, lower_[i], upper_[i]);
  }
}

void UnitBox::GradientToUnit(std::span<const double> x, std::span<const double> grad_x,
                             std::span<double> grad_z) const {
  for (std::size_t j = 0; j < free_.size(); ++j) {
    const std::size_t i = free_[j];
    // linear: ∂x/∂z = upper − lower; log: x = lower·e^(z·w), ∂x/∂z = x·w.
    const double dx_dz = log_[i] ? x[i] * width_[i] : width_[i];
    grad_z[j] = grad_x[i] * dx_dz;
  }
}

OptimizerResult Minimize(const CostFunction& cost, std::span<const double> x0, const Bounds& bounds,
                         const OptimizerOptions& options) {
  const Clock::time_point start = Clock::now();
  OptimizerResult result;
  result.algorithm = options.algorithm;
  result.initial_cost = kNaN;
  result.final_cost = kNaN;
  result.x.assign(x0.begin(), x0.end());
  auto reject = [&](std::string why) {
    result.termination = Termination::kInvalidArgs;
    result.message = std::move(why);
    result.runtime_s = std::chrono::duration<double>(Clock::now() - start).count();
    return result;
  };

  std::string why;
  if (!options.IsValid(&why)) return reject("options." + why);
  if (x0.empty()) return reject("x0 is empty: need at least one variable");
  for (std::size_t i = 0; i < x0.size(); ++i) {
    if (!std::isfinite(x0[i])) return reject(Format("x0[%zu] = %g: must be finite", i, x0[i]));
  }
  if (!bounds.IsValid(x0.size(), &why)) return reject(why);
  if (!cost) return reject("cost: the cost function is empty");

  const UnitBox box(bounds);
  const std::size_t n = x0.size();
  Search search;
  search.cost = &cost;
  search.box = &box;
  search.x.assign(n, 0.0);
  search.grad_x.assign(n, 0.0);
  search.best_x.assign(n, 0.0);
  search.best_z.assign(box.free_dimension(), 0.0);
  search.max_evaluations = options.max_evaluations;
  if (options.max_time_s > 0) {
    search.has_deadline = true;
    search.deadline = start + std::chrono::duration_cast<Clock::duration>(
                                  std::chrono::duration<double>(options.max_time_s));
  }

  std::vector<double> z0(box.free_dimension());
  box.ToUnit(x0, z0);
  result.initial_cost = search.Evaluate(z0, {});
  box.FromUnit(z0, result.x);  // the clamped start point

  RunOutcome outcome;
  if (box.free_dimension() == 0) {
    outcome = {Termination::kConverged, "every variable is fixed by its bounds"};
  } else {
    switch (options.algorithm) {
      case OptAlgorithm::kCrs2Bobyqa:
        outcome = RunCrs2Bobyqa(search, z0, options);
        break;
      case OptAlgorithm::kMultiStartBobyqa:
        outcome = RunMultiStart(search, z0, options);
        break;
      case OptAlgorithm::kMlslBobyqa:
        outcome = RunMlslBobyqa(search, z0, options);
        break;
      default: {
        std::vector<double> z = z0;
        outcome = RunLocal(search, LocalAlgorithm(options.algorithm), ToString(options.algorithm),
                           z, options, 0);
        break;
      }
    }
  }

  result.termination = outcome.termination;
  result.message = std::move(outcome.message);
  result.evaluations = search.evaluations;
  result.non_finite_evaluations = search.non_finite_evaluations;
  if (std::isfinite(search.best_cost)) {
    result.x = search.best_x;
    result.final_cost = search.best_cost;
  } else {
    result.termination = Termination::kNonFiniteCost;
    result.message = Format("the cost was NaN or infinite at all %d evaluations (%s)",
                            search.evaluations, result.message.c_str());
  }
  if (result.non_finite_evaluations > 0 && std::isfinite(search.best_cost)) {
    result.message += Format("; %d of %d evaluations were not finite",
                             result.non_finite_evaluations, result.evaluations);
  }
  result.runtime_s = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace pvtwin
