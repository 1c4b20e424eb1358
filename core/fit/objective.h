// The objective of identification (paper 3.2: the MAE of P_el plus Q_u per
// m², with the measured PV temperature optionally) in the optimiser's unit
// coordinates, with its bookkeeping; one fit of the active parameters
// (RunFit) and the standard errors at a fit. Internal to core/fit/: the
// stages (coarse_stage.h, fine_stage.h) and Identify (identification.h) use it.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/common/threads.h"
#include "core/fit/identification.h"
#include "core/fit/lad_fit.h"
#include "core/model/sensitivities.h"

namespace pvtwin::fit_internal {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A parameter this close to a bound of its unit coordinate is at it.
constexpr double kAtBoundZ = 1e-3;

// Unit coordinate of value x in [lower, upper] (log where the range spans
// decades), as the optimiser sees it.
double ToUnit(const ParamInfo& info, double x);

double FromUnit(const ParamInfo& info, double z);

// dx/dz of FromUnit at x: upper − lower, or x·ln(upper / lower) on a log scale.
double DxDz(ParamScale scale, double lower, double upper, double x);

double DxDz(const ParamInfo& info, double x);

// The objective and its bookkeeping, shared by the optimiser callback and
// the identifiability analysis. Simulate() reuses `sim`, so an evaluation
// allocates nothing.
class Objective {
 public:
  Objective(const Drivers& d, const Measurements& m, const IdentOptions& o, ParamVector base)
      : drivers_(d), meas_(m), options_(o), base_(base) {
    const double area = d.plant.area_m2;
    inv_rows_area_ = 1.0 / (static_cast<double>(m.rows.size()) * area);
    use_t_pv_ = o.use_t_pv && !m.t_pv_c.empty();
    position_.assign(d.size(), -1);
    for (std::size_t k = 0; k < m.rows.size(); ++k) {
      position_[m.rows[k]] = static_cast<std::int32_t>(k);
    }
  }

  void SetFree(const std::vector<Param>& free, const std::vector<ParamInfo>& infos,
               const std::vector<double>& z_ref) {
    free_ = free;
    infos_ = infos;
    z_ref_ = z_ref;
    // The run with sensitivities gives the columns of the parameters no
    // effect hook reads; the hooks' parameters take differences.
    const std::vector<Param> hook = HookParams(drivers_.spec);
    sens_free_.clear();
    sens_cols_.clear();
    diff_cols_.clear();
    for (std::size_t j = 0; j < free.size(); ++j) {
      if (std::find(hook.begin(), hook.end(), free[j]) != hook.end()) {
        diff_cols_.push_back(j);
      } else {
        sens_cols_.push_back(j);
        sens_free_.push_back(free[j]);
      }
    }
  }
  const std::vector<Param>& free() const { return free_; }
  void SetBase(const ParamVector& base) { base_ = base; }

  ParamVector Params(std::span<const double> x) const {
    ParamVector p = base_;
    for (std::size_t j = 0; j < free_.size(); ++j) p[static_cast<std::size_t>(free_[j])] = x[j];
    return p;
  }

  // Paper objective at p (W/m²), plus the T_PV term when enabled; NaN if the
  // model produced a non-finite output in an objective row.
  double DataCost(const ParamVector& p, double smoothing_w = 0.0) {
    Run(p);
    double sum_p = 0.0, sum_q = 0.0, sum_t = 0.0;
    const double d2 = smoothing_w * smoothing_w;
    for (std::uint32_t i : meas_.rows) {
      const double ep = sim_.p_el_w[i] - meas_.p_el_w[i];
      const double eq = sim_.q_th_w[i] - meas_.q_th_w[i];
      if (smoothing_w > 0.0) {
        sum_p += std::sqrt(ep * ep + d2) - smoothing_w;
        sum_q += std::sqrt(eq * eq + d2) - smoothing_w;
      } else {
        sum_p += std::fabs(ep);
        sum_q += std::fabs(eq);
      }
      if (use_t_pv_) sum_t += std::fabs(sim_.t_pv_c[i] - meas_.t_pv_c[i]);
    }
    double cost = (sum_p + sum_q) * inv_rows_area_;
    if (use_t_pv_) {
      cost += options_.t_pv_weight_w_m2k * sum_t / static_cast<double>(meas_.rows.size());
    }
    return std::isfinite(cost) ? cost : kNaN;
  }

  double Prior(std::span<const double> x) const {
    double sum = 0.0;
    for (std::size_t j = 0; j < free_.size(); ++j) {
      const double dz = ToUnit(infos_[j], x[j]) - z_ref_[j];
      sum += dz * dz;
    }
    return options_.prior_weight_w_m2 * sum;
  }

  double Cost(std::span<const double> x, double smoothing_w = 0.0) {
    return DataCost(Params(x), smoothing_w) + Prior(x);
  }

  // Residuals at p in blocks over the objective rows: P_el per m², Q_u per
  // m², and w_T·(T_PV error) when the T_PV term is on. Σ|r|/rows is the
  // objective.
  void Residuals(const ParamVector& p, Eigen::VectorXd* r) {
    Run(p);
    FillResiduals(sim_.p_el_w, sim_.q_th_w, sim_.t_pv_c, r);
  }

  // True when Jacobian() serves the active parameters.
  bool HasSensitivities() const {
    return options_.analytic_jacobian && !sens_free_.empty() &&
           SensitivitiesSupported(drivers_.spec, sens_free_, nullptr);
  }

  // Simulations one Jacobian() is charged: the run with sensitivities and
  // one run per column taken by differences.
  int JacobianCost() const { return kSensitivityRunCost + static_cast<int>(diff_cols_.size()); }

  // The Jacobian of Residuals at p in the active parameters' unit
  // coordinates (infos: their scales; dx/dz = upper − lower, or x·ln(upper /
  // lower) on a log scale), from one run with sensitivities; the columns of
  // the parameters an effect hook reads by forward differences from its
  // outputs (DifferenceColumns). A column with a non-finite entry is left
  // zero. False when not supported.
  bool Jacobian(const ParamVector& p, const std::vector<ParamInfo>& infos, Eigen::MatrixXd* jac) {
    if (!HasSensitivities()) return false;
    ColumnFactors(p, infos, &sink_factors_);
    if (TakeAhead(p, jac)) return true;
    const auto m = static_cast<Eigen::Index>(meas_.rows.size());
    jac->resize((use_t_pv_ ? 3 : 2) * m, static_cast<Eigen::Index>(free_.size()));
    const double inv_area = 1.0 / drivers_.plant.area_m2;
    // The run writes the sensitivities' columns straight into *jac, scaled
    // to unit coordinates (dx/dz, sink_factors_) per W/m² (or weighted K) at
    // the objective rows, as the copy below does when it cannot (an output
    // transform).
    sink_.base = jac->data();
    sink_.stride = static_cast<std::size_t>(jac->rows());
    sink_.rows = static_cast<std::size_t>(m);
    sink_.position = position_;
    sink_.column = sens_cols_;
    sink_.column_factor = sink_factors_;
    sink_.value_factor = inv_area;
    sink_.t_pv_factor = options_.t_pv_weight_w_m2k;
    sens_.sink = &sink_;
    sens_.t_pv_derivatives = use_t_pv_;
    sens_.threads = options_.threads;
    if (!SimulateSensitivities(drivers_, p, sens_free_, &sens_)) return false;
    simulations_ += kSensitivityRunCost;
    ++sensitivity_runs_;
    for (std::size_t a = 0; a < sens_cols_.size() && sens_.in_sink; ++a) {
      if (!sink_.finite[a]) jac->col(static_cast<Eigen::Index>(sens_cols_[a])).setZero();
    }
    for (std::size_t a = 0; a < sens_cols_.size() && !sens_.in_sink; ++a) {
      const auto j = static_cast<Eigen::Index>(sens_cols_[a]);
      const double dx_dz = sink_factors_[a];
      const double* dp = sens_.DPEl(a);
      const double* dq = sens_.DQTh(a);
      const double* dt = use_t_pv_ ? sens_.DTPv(a) : nullptr;
      double* col = jac->col(j).data();
      bool finite = true;  // checked in the pass that fills the column
      for (Eigen::Index k = 0; k < m; ++k) {
        const std::uint32_t i = meas_.rows[static_cast<std::size_t>(k)];
        const double vp = dp[i] * inv_area * dx_dz;
        const double vq = dq[i] * inv_area * dx_dz;
        col[k] = vp;
        col[m + k] = vq;
        if (!std::isfinite(vp) || !std::isfinite(vq)) finite = false;
        if (use_t_pv_) {
          const double vt = options_.t_pv_weight_w_m2k * dt[i] * dx_dz;
          col[2 * m + k] = vt;
          if (!std::isfinite(vt)) finite = false;
        }
      }
      if (!finite) jac->col(j).setZero();
    }
    if (!diff_cols_.empty()) {
      Eigen::VectorXd r0;
      FillResiduals(sens_.p_el_w, sens_.q_th_w, sens_.t_pv_c, &r0);
      DifferenceColumns(p, infos, r0, diff_cols_, jac);
    }
    // The run's P_el, Q_u and T_PV are Simulate's to the bit
    // (sensitivities.h): they serve the next run at p, as a plain run's
    // would.
    sim_.p_el_w.swap(sens_.p_el_w);
    sim_.q_th_w.swap(sens_.q_th_w);
    sim_.t_pv_c.swap(sens_.t_pv_c);
    sim_at_ = p;
    return true;
  }

  // DataCost(p), with the Jacobian at p (Jacobian(p, infos)) computed by
  // the same run when the active parameters have sensitivities: the fit
  // that starts at p asks for that Jacobian first, and gets it without
  // another run (TakeAhead); the plain run the cost would have taken is
  // saved. The Jacobian is charged when it is taken, as if computed then,
  // so that the counts and the budget's course do not depend on it; one
  // that is not taken (the fit starts elsewhere) was a run with
  // sensitivities in vain, uncharged.
  double DataCostWithJacobianAhead(const ParamVector& p, const std::vector<ParamInfo>& infos) {
    const int simulations = simulations_;
    const int runs = sensitivity_runs_;
    ahead_.reset();
    if (Jacobian(p, infos, &ahead_jac_)) {
      ahead_ = Ahead{p, free_, sink_factors_, simulations_ - simulations, sensitivity_runs_ - runs};
      simulations_ = simulations;
      sensitivity_runs_ = runs;
    }
    return DataCost(p);
  }

  // Columns `cols` of the Jacobian at p (residuals r0) by forward
  // differences, a step of kDifferenceStep in unit coordinates (inwards at
  // the upper bound); a non-finite column is left zero.
  void DifferenceColumns(const ParamVector& p, const std::vector<ParamInfo>& infos,
                         const Eigen::VectorXd& r0, std::span<const std::size_t> cols,
                         Eigen::MatrixXd* jac) {
    constexpr double kDifferenceStep = 1e-4;
    for (std::size_t uj : cols) {
      ParamVector q = p;
      const auto idx = static_cast<std::size_t>(free_[uj]);
      const double z = ToUnit(infos[uj], p[idx]);
      const double h = z + kDifferenceStep <= 1.0 ? kDifferenceStep : -kDifferenceStep;
      q[idx] = FromUnit(infos[uj], z + h);
      Residuals(q, &diff_r_);
      const auto j = static_cast<Eigen::Index>(uj);
      jac->col(j) = (diff_r_ - r0) / h;
      if (!jac->col(j).allFinite()) jac->col(j).setZero();
    }
  }

  // Gradient of Cost(x, smoothing_w) in the caller's coordinates x from one
  // run with sensitivities: d/dr of the pseudo-Huber term of each P_el and
  // Q_u row (of |r| for the T_PV rows) times the Jacobian, divided by dx/dz
  // per parameter, plus the prior's. False when the active parameters have
  // no sensitivities (the caller differences instead).
  bool CostGradient(std::span<const double> x, double smoothing_w, std::span<double> grad) {
    if (!HasSensitivities()) return false;
    const ParamVector p = Params(x);
    Eigen::MatrixXd jac;
    if (!Jacobian(p, infos_, &jac)) return false;
    Eigen::VectorXd r;
    FillResiduals(sim_.p_el_w, sim_.q_th_w, sim_.t_pv_c, &r);  // Jacobian() left p's there
    const auto m = static_cast<Eigen::Index>(meas_.rows.size());
    const double rows = static_cast<double>(m);
    const double area = drivers_.plant.area_m2;
    const double d2 = smoothing_w * smoothing_w;
    Eigen::VectorXd dcost_dr(r.size());
    for (Eigen::Index k = 0; k < r.size(); ++k) {
      if (k < 2 * m && smoothing_w > 0.0) {
        const double e = r(k) * area;  // W
        dcost_dr(k) = e / (std::sqrt(e * e + d2) * rows);
      } else {
        dcost_dr(k) = (r(k) > 0.0 ? 1.0 : r(k) < 0.0 ? -1.0 : 0.0) / rows;
      }
    }
    const Eigen::VectorXd grad_z = jac.transpose() * dcost_dr;
    for (std::size_t j = 0; j < free_.size(); ++j) {
      const ParamInfo& info = infos_[j];
      const double dx_dz = DxDz(info, x[j]);
      const double dz = ToUnit(info, x[j]) - z_ref_[j];
      grad[j] =
          (grad_z(static_cast<Eigen::Index>(j)) + 2.0 * options_.prior_weight_w_m2 * dz) / dx_dz;
    }
    return true;
  }

  // The last run's P_el, Q_u and T_PV (sim_).
  const SimOutputs& last() const { return sim_; }
  int simulations() const { return simulations_; }
  int sensitivity_runs() const { return sensitivity_runs_; }
  int served() const { return served_; }

 private:
  // Simulate's outputs at p in sim_, charged as one simulation. The stages
  // after a fit ask again for its result (its cost, its residuals for the
  // identifiability analysis), which the fit's last run often computed:
  // a repeat of the last run's parameters (a plain run's, or a run with
  // sensitivities', Jacobian) is served from sim_, the same outputs to the
  // bit, and still charged, so that the budget's course and the counts do
  // not depend on it.
  void Run(const ParamVector& p) {
    ++simulations_;
    if (sim_at_ && *sim_at_ == p) {
      ++served_;
      return;
    }
    Simulate(drivers_, p, &sim_);
    sim_at_ = p;
  }

  // Per column of sens_free_: dx/dz at p.
  void ColumnFactors(const ParamVector& p, const std::vector<ParamInfo>& infos,
                     std::vector<double>* factors) const {
    factors->resize(sens_cols_.size());
    for (std::size_t a = 0; a < sens_cols_.size(); ++a) {
      const std::size_t uj = sens_cols_[a];
      (*factors)[a] = DxDz(infos[uj], p[static_cast<std::size_t>(free_[uj])]);
    }
  }

  // The Jacobian computed ahead (DataCostWithJacobianAhead) into *jac, and
  // charged now, when it is the one asked for: at p, for the same active
  // parameters and scales (sink_factors_, just set), with p's values still
  // in sim_. Any other request drops it.
  bool TakeAhead(const ParamVector& p, Eigen::MatrixXd* jac) {
    if (!ahead_) return false;
    const bool same = ahead_->at == p && ahead_->free == free_ &&
                      ahead_->factors == sink_factors_ && sim_at_ && *sim_at_ == p;
    if (same) {
      jac->swap(ahead_jac_);
      simulations_ += ahead_->simulations;
      sensitivity_runs_ += ahead_->sensitivity_runs;
      served_ += ahead_->simulations;
    }
    ahead_.reset();
    ahead_jac_.resize(0, 0);
    return same;
  }

  void FillResiduals(const std::vector<double>& p_el_w, const std::vector<double>& q_th_w,
                     const std::vector<double>& t_pv_c, Eigen::VectorXd* r) const {
    const auto m = static_cast<Eigen::Index>(meas_.rows.size());
    r->resize((use_t_pv_ ? 3 : 2) * m);
    const double inv_area = 1.0 / drivers_.plant.area_m2;
    for (Eigen::Index k = 0; k < m; ++k) {
      const std::uint32_t i = meas_.rows[static_cast<std::size_t>(k)];
      (*r)(k) = (p_el_w[i] - meas_.p_el_w[i]) * inv_area;
      (*r)(m + k) = (q_th_w[i] - meas_.q_th_w[i]) * inv_area;
      if (use_t_pv_) (*r)(2 * m + k) = options_.t_pv_weight_w_m2k * (t_pv_c[i] - meas_.t_pv_c[i]);
    }
  }

  const Drivers& drivers_;
  const Measurements& meas_;
  const IdentOptions& options_;
  ParamVector base_;
  std::vector<Param> free_;
  std::vector<Param> sens_free_;                    // free_ without the hooks' parameters
  std::vector<std::size_t> sens_cols_, diff_cols_;  // their columns, the others'
  Eigen::VectorXd diff_r_;
  std::vector<ParamInfo> infos_;
  std::vector<double> z_ref_;
  // The last run's outputs: P_el, Q_u and T_PV at sim_at_, which a run with
  // sensitivities leaves too (Jacobian); the others are the last plain
  // run's.
  SimOutputs sim_;
  std::optional<ParamVector> sim_at_;  // the parameters of sim_'s P_el, Q_u, T_PV
  // A Jacobian computed ahead (DataCostWithJacobianAhead), until TakeAhead.
  struct Ahead {
    ParamVector at;
    std::vector<Param> free;
    std::vector<double> factors;  // sink_factors_ of its run
    int simulations = 0;          // what its computation was charged, and undone
    int sensitivity_runs = 0;
  };
  std::optional<Ahead> ahead_;
  Eigen::MatrixXd ahead_jac_;
  SimSensitivities sens_;
  SensitivitySink sink_;
  std::vector<double> sink_factors_;    // per column of sens_free_: dx/dz
  std::vector<std::int32_t> position_;  // per simulated row: its objective row, or −1
  double inv_rows_area_ = 0.0;
  bool use_t_pv_ = false;
  int simulations_ = 0;
  int sensitivity_runs_ = 0;
  int served_ = 0;  // of simulations_, served without a model run
};

// Standard errors of the parameters of J's columns (unit coordinates) from
// J (residuals × parameters) and the residuals r at the fit: se_j =
// σ·√[(JᵀJ)⁻¹]_jj with σ the residual RMS (floored at sigma_floor)
// inflated by √((1+ρ)/(1−ρ)) for the lag-1 autocorrelation ρ of the
// residuals, which are far from independent at a 1-min step. JᵀJ is summed
// on `threads` (WeightedNormalEquations).
Eigen::VectorXd StandardErrors(const Eigen::MatrixXd& jac, const Eigen::VectorXd& r,
                               double sigma_floor, int threads);

struct FitOutcome {
  ParamVector params;
  Termination termination = Termination::kFailure;
  bool ok = false;
  std::string message;
  Eigen::MatrixXd jacobian;  // at or near params when the method had it, else empty
};

// One fit of the active parameters from `from`; lad_lm stops before a step
// on `stop_prediction_factor` (LadFitOptions::stop_prediction_factor).
FitOutcome RunFit(Objective& obj, const std::vector<ParamInfo>& infos,
                  const std::vector<double>& z_ref, const ParamVector& from,
                  const IdentOptions& options, int budget, double n_rows, double area_m2,
                  double stop_prediction_factor);

// Sensitivity matrix of the residuals to the active parameters (unit
// coordinates) at p, from the run with sensitivities when the objective has
// it, else by forward differences; r0 gets the residuals at p.
Eigen::MatrixXd SensitivityMatrix(Objective& obj, const std::vector<ParamInfo>& infos,
                                  const ParamVector& p, Eigen::VectorXd* r0);

std::string Name(Param p);

}  // namespace pvtwin::fit_internal
