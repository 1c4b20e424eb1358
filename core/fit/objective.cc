// The objective's standard errors and one fit of the active parameters; see
// core/fit/objective.h.
#include "core/fit/objective.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace pvtwin::fit_internal {

double ToUnit(const ParamInfo& info, double x) {
  if (info.upper <= info.lower) return 0.0;
  if (info.scale == ParamScale::kLog) {
    return std::log(x / info.lower) / std::log(info.upper / info.lower);
  }
  return (x - info.lower) / (info.upper - info.lower);
}

double FromUnit(const ParamInfo& info, double z) {
  if (info.scale == ParamScale::kLog) {
    return info.lower * std::pow(info.upper / info.lower, z);
  }
  return info.lower + z * (info.upper - info.lower);
}

double DxDz(ParamScale scale, double lower, double upper, double x) {
  return scale == ParamScale::kLog ? x * std::log(upper / lower) : upper - lower;
}

double DxDz(const ParamInfo& info, double x) { return DxDz(info.scale, info.lower, info.upper, x); }

Eigen::VectorXd StandardErrors(const Eigen::MatrixXd& jac, const Eigen::VectorXd& r,
                               double sigma_floor, int threads) {
  Eigen::MatrixXd jtj;
  Eigen::VectorXd no_g;
  WeightedNormalEquations(jac, Eigen::VectorXd(), Eigen::VectorXd(), threads, &jtj, &no_g);
  const double rms =
      std::sqrt(r.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(r.size(), 1)));
  // Lag-1 autocorrelation of the residual sequences (blocks per output).
  double num = 0.0, den = 0.0;
  for (Eigen::Index i = 1; i < r.size(); ++i) {
    num += r(i) * r(i - 1);
    den += r(i) * r(i);
  }
  const double rho = den > 0.0 ? std::clamp(num / den, 0.0, 0.9) : 0.0;
  const double sigma = std::max(rms, sigma_floor) * std::sqrt((1.0 + rho) / (1.0 - rho));
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jtj);
  const Eigen::VectorXd lam =
      eig.eigenvalues().cwiseMax(1e-14 * std::max(eig.eigenvalues().maxCoeff(), 1e-300));
  const Eigen::MatrixXd cov =
      eig.eigenvectors() * lam.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
  return sigma * cov.diagonal().cwiseSqrt();
}

FitOutcome RunFit(Objective& obj, const std::vector<ParamInfo>& infos,
                  const std::vector<double>& z_ref, const ParamVector& from,
                  const IdentOptions& options, int budget, double n_rows, double area_m2,
                  double stop_prediction_factor) {
  FitOutcome out;
  out.params = from;
  const std::vector<Param>& active = obj.free();
  const std::size_t n = active.size();
  std::vector<double> x0(n);
  for (std::size_t j = 0; j < n; ++j) x0[j] = from[static_cast<std::size_t>(active[j])];
  if (options.method == IdentMethod::kLadLm) {
    LadFitOptions lo;
    lo.max_evaluations = budget;
    lo.ftol_rel = options.optimizer.ftol_rel;
    lo.xtol = options.optimizer.xtol_rel;
    lo.stop_prediction_factor = stop_prediction_factor;
    lo.prior_weight = options.prior_weight_w_m2;
    lo.n_scale = n_rows;
    lo.threads = options.threads;
    if (!options.correct_bends) lo.max_correction = 0.0;
    Eigen::VectorXd z0(static_cast<Eigen::Index>(n)), zr(static_cast<Eigen::Index>(n));
    for (std::size_t j = 0; j < n; ++j) {
      z0(static_cast<Eigen::Index>(j)) = ToUnit(infos[j], x0[j]);
      zr(static_cast<Eigen::Index>(j)) = z_ref[j];
    }
    // The parameters at z. FromUnit(ToUnit(x)) is x only within rounding:
    // at the start's coordinates the fit takes the start itself, the point
    // whose cost the caller has just asked for, which the objective then
    // serves from that run instead of running it again (12 ms at 5 s).
    const ParamVector start = obj.Params(x0);
    std::vector<double> x(n);
    auto params_at = [&](const Eigen::VectorXd& z) {
      if (z == z0) return start;
      for (std::size_t j = 0; j < n; ++j)
        x[j] = FromUnit(infos[j], z(static_cast<Eigen::Index>(j)));
      return obj.Params(x);
    };
    ResidualFunction residuals = [&](const Eigen::VectorXd& z, Eigen::VectorXd* r) {
      obj.Residuals(params_at(z), r);
      return r->allFinite();
    };
    JacobianFunction jacobian = nullptr;
    if (obj.HasSensitivities()) {
      lo.jacobian_cost = obj.JacobianCost();
      jacobian = [&](const Eigen::VectorXd& z, const Eigen::VectorXd&, Eigen::MatrixXd* jac) {
        return obj.Jacobian(params_at(z), infos, jac);
      };
    }
    LadFitResult fit = LadFit(residuals, z0, zr, lo, jacobian);
    out.params = params_at(fit.z);
    out.ok = std::isfinite(fit.final_cost) && fit.final_cost <= fit.initial_cost;
    out.termination = !std::isfinite(fit.final_cost) ? Termination::kNonFiniteCost
                      : fit.converged                ? Termination::kConverged
                                                     : Termination::kMaxEvaluations;
    out.message = fit.message;
    // The identifiability analysis takes the last Jacobian when the fit
    // ended within this distance of where it was computed (unit
    // coordinates, 0.3 % of each range): the standard errors and the
    // linear predictions of the fixing rounds hardly notice, and another
    // run with sensitivities is saved.
    constexpr double kJacobianReuseDistance = 3e-3;
    if (fit.jacobian_distance <= kJacobianReuseDistance) out.jacobian = std::move(fit.jacobian);
    return out;
  }
  const bool smooth = NeedsGradient(options.optimizer.algorithm);
  const double smoothing_w = smooth ? 0.5 * area_m2 : 0.0;  // 0.5 W/m² pseudo-Huber width
  std::vector<double> lower(n), upper(n), xp(n);
  std::vector<bool> log_scale(n);
  for (std::size_t j = 0; j < n; ++j) {
    lower[j] = infos[j].lower;
    upper[j] = infos[j].upper;
    log_scale[j] = infos[j].scale == ParamScale::kLog;
  }
  CostFunction cost = [&](std::span<const double> x, std::span<double> grad) -> double {
    // The run with sensitivities first: its values serve the cost.
    const bool exact = !grad.empty() && obj.CostGradient(x, smoothing_w, grad);
    const double c = obj.Cost(x, smoothing_w);
    if (!grad.empty() && !exact) {
      // Forward differences on the smoothed objective.
      std::copy(x.begin(), x.end(), xp.begin());
      for (std::size_t j = 0; j < n; ++j) {
        const double h = log_scale[j] ? 1e-5 * xp[j] : 1e-5 * (upper[j] - lower[j]);
        const double xj = xp[j];
        xp[j] = xj + h <= upper[j] ? xj + h : xj - h;
        grad[j] = (obj.Cost(xp, smoothing_w) - c) / (xp[j] - xj);
        xp[j] = xj;
      }
    }
    return c;
  };
  OptimizerOptions opt = options.optimizer;
  // A gradient method's cost call runs n + 1 simulations, or one plain run
  // and one with sensitivities (plus one per column an effect hook's
  // parameter takes by differences).
  const int call_cost = obj.HasSensitivities() ? 1 + obj.JacobianCost() : static_cast<int>(n + 1);
  opt.max_evaluations = std::max(smooth ? budget / call_cost : budget, 1);
  const OptimizerResult result = Minimize(cost, x0, Bounds{lower, upper, log_scale}, opt);
  if (!result.x.empty()) out.params = obj.Params(result.x);
  out.ok = result.ok();
  out.termination = result.termination;
  out.message = result.message;
  return out;
}

Eigen::MatrixXd SensitivityMatrix(Objective& obj, const std::vector<ParamInfo>& infos,
                                  const ParamVector& p, Eigen::VectorXd* r0) {
  const std::vector<Param>& active = obj.free();
  Eigen::MatrixXd jac;
  // The run with sensitivities first: its values serve the residuals.
  if (obj.Jacobian(p, infos, &jac)) {
    obj.Residuals(p, r0);
    return jac;
  }
  obj.Residuals(p, r0);
  jac.resize(r0->size(), static_cast<Eigen::Index>(active.size()));
  std::vector<std::size_t> all(active.size());
  for (std::size_t j = 0; j < all.size(); ++j) all[j] = j;
  obj.DifferenceColumns(p, infos, *r0, all, &jac);
  return jac;
}

std::string Name(Param p) { return std::string(kParamTable[static_cast<std::size_t>(p)].name); }

}  // namespace pvtwin::fit_internal
