#include "core/fit/identification.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <span>

#include "core/common/calendar.h"
#include "core/common/threads.h"
#include "core/effects/registry.h"
#include "core/fit/lad_fit.h"
#include "core/model/sensitivities.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A parameter this close to a bound of its unit coordinate is at it.
constexpr double kAtBoundZ = 1e-3;

// Unit coordinate of value x in [lower, upper] (log where the range spans
// decades), as the optimiser sees it.
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

// dx/dz of FromUnit at x: upper − lower, or x·ln(upper / lower) on a log scale.
double DxDz(ParamScale scale, double lower, double upper, double x) {
  return scale == ParamScale::kLog ? x * std::log(upper / lower) : upper - lower;
}
double DxDz(const ParamInfo& info, double x) { return DxDz(info.scale, info.lower, info.upper, x); }

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

}  // namespace

Measurements MakeMeasurements(const Series& s, const Drivers& d) {
  Measurements m;
  const std::size_t n = s.size();
  m.p_el_w = s.Has(Channel::kPElW) ? s[Channel::kPElW] : std::vector<double>(n, kNaN);
  if (s.Has(Channel::kQThW)) {
    m.q_th_w = s[Channel::kQThW];
  } else {
    m.q_th_w.assign(n, kNaN);
  }
  if (s.Has(Channel::kTOutC) && s.Has(Channel::kTInC)) {
    for (std::size_t i = 0; i < n; ++i) {
      if (std::isnan(m.q_th_w[i])) {
        m.q_th_w[i] = d.capacity_flow_w_k[i] * (s[Channel::kTOutC][i] - s[Channel::kTInC][i]);
      }
    }
  }
  if (s.Has(Channel::kTPvC)) m.t_pv_c = s[Channel::kTPvC];
  for (std::size_t i = 0; i < n; ++i) {
    const double valid = s.At(Channel::kValid, i);
    if (valid == 0.0 || !d.usable[i]) continue;
    if (!std::isfinite(m.p_el_w[i]) || !std::isfinite(m.q_th_w[i])) continue;
    m.rows.push_back(static_cast<std::uint32_t>(i));
  }
  return m;
}

ErrorMetrics ComputeErrors(const Measurements& meas, const SimOutputs& sim, double area_m2) {
  ErrorMetrics e;
  e.rows = meas.rows.size();
  if (e.rows == 0) return e;
  double abs_p = 0.0, abs_q = 0.0, sum_p = 0.0, sum_q = 0.0, sum_t = 0.0;
  for (std::uint32_t i : meas.rows) {
    sum_p += std::fabs(sim.p_el_w[i] - meas.p_el_w[i]);
    sum_q += std::fabs(sim.q_th_w[i] - meas.q_th_w[i]);
    abs_p += std::fabs(meas.p_el_w[i]);
    abs_q += std::fabs(meas.q_th_w[i]);
    if (!meas.t_pv_c.empty()) sum_t += std::fabs(sim.t_pv_c[i] - meas.t_pv_c[i]);
  }
  const double n = static_cast<double>(e.rows);
  e.mae_p_el_w = sum_p / n;
  e.mae_q_th_w = sum_q / n;
  e.mae_p_el_w_m2 = e.mae_p_el_w / area_m2;
  e.mae_q_th_w_m2 = e.mae_q_th_w / area_m2;
  e.nmae_p_el = abs_p > 0.0 ? sum_p / abs_p : kNaN;
  e.nmae_q_th = abs_q > 0.0 ? sum_q / abs_q : kNaN;
  e.mae_t_pv_k = meas.t_pv_c.empty() ? kNaN : sum_t / n;
  return e;
}

OptimizerOptions IdentOptions::DefaultOptimizerOptions() {
  OptimizerOptions o;
  o.algorithm = OptAlgorithm::kSbplx;
  o.max_evaluations = 4000;
  // With lad_lm's stop on the promised decrease, 1e-3 comes within about
  // 0.1 % of the held-out MAE of 1e-4 on the bench data; 1e-4 runs
  // misspecified variants into the budget (core/fit/README.md).
  o.ftol_rel = 1e-3;
  o.xtol_rel = 1e-6;
  o.initial_step = 0.1;
  o.max_restarts = 3;
  return o;
}

bool IdentOptions::IsValid(std::string* why) const {
  auto fail = [why](const std::string& field, double value, const std::string& rule) {
    if (why) {
      char buf[64];
      std::snprintf(buf, sizeof(buf), "%g", value);
      *why = field + " = " + buf + ": " + rule;
    }
    return false;
  };
  if (!optimizer.IsValid(why)) return false;
  if (!(t_pv_weight_w_m2k >= 0.0))
    return fail("t_pv_weight_w_m2k", t_pv_weight_w_m2k, "must be >= 0");
  if (!(prior_weight_w_m2 >= 0.0))
    return fail("prior_weight_w_m2", prior_weight_w_m2, "must be >= 0");
  if (!(undetermined_se > 0.0)) return fail("undetermined_se", undetermined_se, "must be > 0");
  if (!(polish_stop_prediction_factor >= 0.0))
    return fail("polish_stop_prediction_factor", polish_stop_prediction_factor, "must be >= 0");
  if (min_rows < 1) return fail("min_rows", min_rows, "must be >= 1");
  if (threads < 1 || threads > 2) return fail("threads", threads, "must be 1 or 2");
  return true;
}

std::vector<std::string> IdentSummary::AtBounds() const {
  std::vector<std::string> names;
  for (const ParamEstimate& e : estimates) {
    if (e.free && e.at_bound) names.emplace_back(Info(e.param).name);
  }
  return names;
}

std::string IdentSummary::CoarseSubsetText() const {
  char buf[96];
  if (coarse_subset_days > 0) {
    std::snprintf(buf, sizeof(buf), "first on %d of the days, %.1f ms", coarse_subset_days,
                  1e3 * coarse_subset_runtime_s);
  } else if (coarse_subset_runtime_s > 0.0) {
    std::snprintf(buf, sizeof(buf), "a fit on a day subset not taken, %.1f ms",
                  1e3 * coarse_subset_runtime_s);
  } else {
    return {};
  }
  return buf;
}

std::string IdentSummary::BriefReport() const {
  char buf[320];
  std::snprintf(buf, sizeof(buf),
                "%s: %s, %s (%s), cost %.4g -> %.4g W/m2, %d simulations, %.3f s%s%s",
                variant.c_str(), ok ? "ok" : "FAILED", algorithm.c_str(),
                std::string(ToString(termination)).c_str(), initial_cost_w_m2, final_cost_w_m2,
                evaluations, runtime_s, ok ? "" : ": ", ok ? "" : failure_reason.c_str());
  std::string report = buf;
  const std::vector<std::string> bounds = AtBounds();
  if (ok && !bounds.empty()) {
    report += "; ok, but " + std::to_string(bounds.size()) +
              (bounds.size() == 1 ? " parameter" : " parameters") + " at bounds (";
    for (std::size_t i = 0; i < bounds.size(); ++i) report += (i ? ", " : "") + bounds[i];
    report += "): the data or the model do not hold them inside their physical range";
  }
  return report;
}

std::string IdentAlgorithmName(const IdentOptions& options) {
  return options.method == IdentMethod::kLadLm ? "lad_lm"
                                               : std::string(ToString(options.optimizer.algorithm));
}

bool SetIdentAlgorithm(std::string_view name, IdentOptions* options) {
  if (name == "lad_lm") {
    options->method = IdentMethod::kLadLm;
    return true;
  }
  const std::optional<OptAlgorithm> a = OptAlgorithmFromString(name);
  if (!a) return false;
  options->method = IdentMethod::kNlopt;
  options->optimizer.algorithm = *a;
  return true;
}

namespace {

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

// Sensitivity matrix of the residuals to the active parameters (unit
// coordinates) at p, from the run with sensitivities when the objective has
// it, else by forward differences; r0 gets the residuals at p.
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

// Averages groups of `factor` consecutive rows of drivers and measurements
// (never across a restart, an unusable row or a pump start or stop), as
// resampling the data to a coarser step would. Used for the coarse first
// stage of identification. A group that mixed minutes with and without flow
// would have a mean flow the collector never saw, and the fluid conductance
// 2w/(r1 + 2w·r0) is far from linear in w: that bias moved the coarse
// optimum along the r0_fluid/r1_fluid valley, and the fine stage spent two
// thirds of its runs walking back.
// With `keep` (one flag per row of d), the rows not kept are left out: each
// stretch of them becomes one group that is not usable and not in the
// objective (the model restarts after it, as after a gap in the data).
void Coarsen(const Drivers& d, const Measurements& m, int factor, Drivers* cd, Measurements* cm,
             const std::vector<std::uint8_t>* keep = nullptr) {
  const std::size_t n = d.size();
  auto kept = [&](std::size_t i) { return keep == nullptr || (*keep)[i] != 0; };
  RowGroups groups;
  groups.begin.reserve(n / static_cast<std::size_t>(factor) * 5 / 4 + 16);
  groups.dt_s.reserve(groups.begin.capacity());
  for (std::size_t i = 0; i < n;) {
    std::size_t end = i + 1;
    if (!kept(i)) {
      while (end < n && !kept(end)) ++end;
    } else if (d.usable[i]) {
      const bool flow = d.capacity_flow_w_k[i] > 0.0;
      while (end < n && end - i < static_cast<std::size_t>(factor) && d.usable[end] && kept(end) &&
             !d.restart[end] && (d.capacity_flow_w_k[end] > 0.0) == flow) {
        ++end;
      }
    }
    groups.Add(end, d.dt_s);
    i = end;
  }
  const std::size_t coarse_rows = groups.size();
  cd->spec = d.spec;
  cd->plant = d.plant;
  cd->dt_s = groups.dt_s;
  cd->time_s.resize(coarse_rows);
  cd->restart.resize(coarse_rows);
  cd->usable.resize(coarse_rows);
  cd->ln_wind.resize(coarse_rows);
  for (std::size_t g = 0; g < coarse_rows; ++g) {
    const std::size_t first = groups.begin[g];
    cd->time_s[g] = d.time_s[first];
    cd->restart[g] = d.restart[first];
    cd->usable[g] = d.usable[first] && kept(first);
    double wind = 0.0;
    for (std::size_t k = first; k < groups.begin[g + 1]; ++k) {
      wind += std::exp(d.ln_wind[k]) * d.dt_s[k];
    }
    cd->ln_wind[g] = std::log(wind / groups.dt_s[g]);
  }
  auto mean = [&](const std::vector<double>& v, std::vector<double>* out) {
    groups.Means(v, d.dt_s, out);
  };
  mean(d.t_in_c, &cd->t_in_c);
  mean(d.mdot_kg_s, &cd->mdot_kg_s);
  mean(d.capacity_flow_w_k, &cd->capacity_flow_w_k);
  mean(d.g_poa_w_m2, &cd->g_poa_w_m2);
  mean(d.g_abs_w_m2, &cd->g_abs_w_m2);
  mean(d.t_amb_c, &cd->t_amb_c);
  mean(d.t_back_c, &cd->t_back_c);
  mean(d.t_sky_k4, &cd->t_sky_k4);
  CoarsenEffectDrivers(d, groups, cd);
  // The measurements of a group whose rows are all in the objective; NaN
  // (and not in the objective) for the others.
  std::vector<std::uint8_t> in_obj(n, 0);
  for (std::uint32_t i : m.rows) in_obj[i] = kept(i) ? 1 : 0;
  const bool t_pv = !m.t_pv_c.empty();
  mean(m.p_el_w, &cm->p_el_w);
  mean(m.q_th_w, &cm->q_th_w);
  if (t_pv) mean(m.t_pv_c, &cm->t_pv_c);
  cm->rows.clear();
  for (std::size_t g = 0; g < coarse_rows; ++g) {
    bool all_obj = true;
    for (std::size_t k = groups.begin[g]; k < groups.begin[g + 1]; ++k) {
      all_obj = all_obj && in_obj[k];
    }
    if (all_obj) {
      cm->rows.push_back(static_cast<std::uint32_t>(g));
    } else {
      cm->p_el_w[g] = cm->q_th_w[g] = kNaN;
      if (t_pv) cm->t_pv_c[g] = kNaN;
    }
  }
}

// The parameters a fit frees: used by the variant, requested (or free by
// default), with a non-empty range; `base` is the start clamped into the
// bounds.
struct FreeSet {
  ParamVector base{};
  std::vector<Param> free;
  std::vector<ParamInfo> infos;  // resolved, per free parameter
};

FreeSet SelectFree(const Drivers& drivers, const ParamVector& start, const IdentOptions& options) {
  const auto used = UsedParams(drivers.spec);
  const auto requested = options.free.any() ? options.free : DefaultFreeParams(drivers.spec);
  FreeSet fs;
  fs.base = start;
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const ParamInfo info = ResolvedInfo(static_cast<Param>(i), drivers.plant);
    fs.base[i] = std::clamp(fs.base[i], info.lower, info.upper);
    if (used.test(i) && requested.test(i) && info.upper > info.lower) {
      fs.free.push_back(static_cast<Param>(i));
      fs.infos.push_back(info);
    }
  }
  return fs;
}

// Starts for a second coarse fit, one per effect of the spec whose module
// reads a start from the residuals of the model without it
// (EffectModule::start_from_residuals) and whose parameters are free: that
// start at `at` (the first coarse optimum) with the effect removed. A local
// fit does not find such an effect's geometry from an arbitrary start (the
// shading obstacle: it only moves an obstacle whose window the sun already
// crosses, and where the fit ends depended on its path).
std::vector<ParamVector> RestartsFromResiduals(const Drivers& drivers, const Measurements& meas,
                                               const FreeSet& fs, const ParamVector& at) {
  std::vector<ParamVector> starts;
  for (const EffectModule* module : EffectRegistry()) {
    const ModelExtension* ext = module->extension;
    if (module->start_from_residuals == nullptr || ext == nullptr || !drivers.spec.Has(*ext)) {
      continue;
    }
    const bool frees_one = std::any_of(ext->params.begin(), ext->params.end(), [&](Param p) {
      return std::find(fs.free.begin(), fs.free.end(), p) != fs.free.end();
    });
    if (!frees_one) continue;
    Drivers without = drivers;
    without.spec.Remove(*ext);
    SimOutputs base;
    Simulate(without, at, &base);
    ParamVector start = at;
    if (!module->start_from_residuals(ResidualsForStart(without, base, meas), &start)) continue;
    for (std::size_t j = 0; j < fs.free.size(); ++j) {
      const auto i = static_cast<std::size_t>(fs.free[j]);
      start[i] = std::clamp(start[i], fs.infos[j].lower, fs.infos[j].upper);
    }
    starts.push_back(start);
  }
  return starts;
}

// Coarse stage: the same fit on the data averaged to about 5 min gets close
// to the optimum at a fraction of the cost; the fine stage starts from there.
// (The model at 5 min is the same model: its exact step makes the coarse
// optimum close to the fine one.) CoarseFits fits on the coarsened data
// only, without the fine objective, so that it can run beside the start's
// cost on the data as given; PickCoarse then compares on those data.
struct CoarseFits {
  std::vector<IdentSummary> fits;  // the first from the start, then the restarts
  int simulations = 0;
  int sensitivity_runs = 0;
  int served_runs = 0;
  // The first fit, with the day subset's before it, at least halved the
  // cost of its start.
  bool far = false;
  // The days of the subset whose optimum the first fit started from; 0
  // when it started from the start (IdentSummary::coarse_subset_days).
  int subset_days = 0;
  // The time of the fits on a day subset, this rung's and a finer rung's
  // (IdentSummary::coarse_subset_runtime_s).
  double subset_runtime_s = 0.0;
  // The position in `fits` of the fit on all the days from the start that
  // followed a merge of the two nodes (MergedNodesWithBothCapacitancesFree);
  // 0 when there was none.
  std::size_t from_start_after_merge = 0;
  // The coarse stage's data (the first rung's averages), which the fine
  // stage's trial fits run on too.
  Drivers drivers;
  Measurements meas;
};

// The factor of the coarse stage's averaging, below 2 when there is none.
int CoarseFactor(const Drivers& drivers, const IdentOptions& options, const FreeSet& fs) {
  const double data_step_s = drivers.dt_s.empty() ? 0.0 : drivers.dt_s[0];
  const double coarse_step_s =
      data_step_s < 30.0 && options.coarse_step_s > 60.0 ? 60.0 : options.coarse_step_s;
  if (fs.free.empty() || options.optimizer.max_evaluations < 200) return 1;
  return coarse_step_s > 0.0 && data_step_s > 0.0
             ? static_cast<int>(coarse_step_s / data_step_s + 0.5)
             : 1;
}

// IdentOptions::day_subset_stage: flags for the rows of every k-th solar
// day of d (k = max(2, days / 3): four or five days of 8 to 14, five of 29),
// and in *kept the number of days kept; empty for data covering fewer than
// kSubsetMinDays days.
constexpr double kSubsetMinDays = 8.0;
// The day subset's fit stops at this relative decrease (IdentOptions::ftol_rel),
// and the fit on all the days after it at this factor times the coarse one.
constexpr double kSubsetFtol = 1e-2;
constexpr double kAllDaysFtolFactor = 0.3;
std::vector<std::uint8_t> DaySubset(const Drivers& d, int* kept) {
  *kept = 0;
  if (d.size() < 2) return {};
  const double days =
      static_cast<double>(d.time_s.back() - d.time_s.front() + d.dt_s.back()) / 86400.0;
  if (days < kSubsetMinDays) return {};
  const std::int64_t offset_s = SolarDayOffsetS(d.plant);
  auto day = [&](std::size_t i) {
    const std::int64_t t = d.time_s[i] + offset_s;
    return t / 86400 - (t % 86400 < 0 ? 1 : 0);
  };
  const std::int64_t first = day(0);
  const std::int64_t every = std::max<std::int64_t>(2, static_cast<std::int64_t>(days) / 3);
  std::vector<std::uint8_t> keep(d.size());
  std::int64_t last_kept = first - 1;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const std::int64_t k = day(i);
    keep[i] = (k - first) % every == 0 ? 1 : 0;
    if (keep[i] && k != last_kept) {
      ++*kept;
      last_kept = k;
    }
  }
  return keep;
}

// The network with two capacitances (2N2Cwr) has two basins whose costs
// are close on a few days: C_PV at its lower bound, or the two nodes merged
// into one (U_coll at its upper bound) that holds the heat capacity in C_PV
// (C_coll small). A day subset's far descent lands in the second on some
// windows of the Table 6 protocol where the fit on all the days from the
// start finds the first (mean P_el MAE 0.188 -> 0.201 W/m² over its 29
// windows, core/fit/README.md). So when a fit with both capacitances free
// ends its fit on all the days from the subset's optimum with the nodes
// merged, a fit on all the days from the start follows, and the better of
// the two on the data as given is the fine stage's start (PickCoarse).
bool MergedNodesWithBothCapacitancesFree(const FreeSet& fs, const ParamVector& p) {
  auto position = [&](Param q) { return std::ranges::find(fs.free, q) - fs.free.begin(); };
  const auto n = static_cast<std::ptrdiff_t>(fs.free.size());
  const std::ptrdiff_t u = position(Param::kUCollWM2K);
  if (position(Param::kCPvJM2K) == n || position(Param::kCCollJM2K) == n || u == n) return false;
  const ParamInfo& info = fs.infos[static_cast<std::size_t>(u)];
  return ToUnit(info, p[static_cast<std::size_t>(info.param)]) > 1.0 - kAtBoundZ;
}

// The coarse fits on the data averaged by `coarse_factor` (CoarseFactor, at
// least 2).
CoarseFits FitCoarse(const Drivers& drivers, const Measurements& meas, const IdentOptions& options,
                     const FreeSet& fs, int coarse_factor) {
  CoarseFits out;
  // Counts a fit's runs (and `extra_runs` more) in the stage's.
  auto add = [&](const IdentSummary& fit, int extra_runs) {
    out.simulations += fit.evaluations + extra_runs;
    out.sensitivity_runs += fit.sensitivity_runs;
    out.served_runs += fit.served_runs;
    out.subset_runtime_s += fit.coarse_subset_runtime_s;
  };
  Drivers& cd = out.drivers;
  Measurements& cm = out.meas;
  Coarsen(drivers, meas, coarse_factor, &cd, &cm);
  if (static_cast<int>(cm.rows.size()) < options.min_rows) return out;
  IdentOptions coarse = options;
  // From data finer than 30 s the ladder has two rungs: 1 min, then the
  // configured coarse step.
  coarse.coarse_step_s =
      options.coarse_step_s > 60.0 && drivers.dt_s[0] < 30.0 ? options.coarse_step_s : 0.0;
  coarse.fix_unidentifiable = false;
  coarse.correct_bends = true;
  coarse.optimizer.ftol_rel = std::max(options.optimizer.ftol_rel, 1e-3);
  coarse.optimizer.max_evaluations = options.optimizer.max_evaluations / 4;
  // The coarsest rung's far descent on a subset of the days
  // (IdentOptions::day_subset_stage): stopped at a looser tolerance, as it
  // only has to bring the start near the optimum, whose polish on all the
  // days (and then on the data as given) follows.
  ParamVector start = fs.base;
  if (options.day_subset_stage && coarse.coarse_step_s == 0.0) {
    int days = 0;
    const std::vector<std::uint8_t> keep = DaySubset(drivers, &days);
    Drivers sd;
    Measurements sm;
    if (!keep.empty()) Coarsen(drivers, meas, coarse_factor, &sd, &sm, &keep);
    if (static_cast<int>(sm.rows.size()) >= options.min_rows) {
      IdentOptions subset = coarse;
      subset.optimizer.ftol_rel = std::max(coarse.optimizer.ftol_rel, kSubsetFtol);
      const IdentSummary sub = Identify(sd, sm, fs.base, subset);
      add(sub, 0);
      out.subset_runtime_s += sub.runtime_s;
      out.far = sub.ok && sub.final_cost_w_m2 <= 0.5 * sub.initial_cost_w_m2;
      if (out.far) {
        start = sub.params;
        out.subset_days = days;
      }
    }
  }
  // From the subset's optimum the fit on all the days polishes: a tighter
  // stop (kAllDaysFtolFactor) lets it move the directions the subset left
  // flat, whose end the stop at the coarse tolerance left where the subset
  // put them (one case of the other-form battery lost its verdict on P_el).
  IdentOptions all_days = coarse;
  if (out.subset_days > 0) all_days.optimizer.ftol_rel *= kAllDaysFtolFactor;
  out.fits.push_back(Identify(cd, cm, start, all_days));
  add(out.fits.back(), 0);
  const IdentSummary& first = out.fits.back();
  out.far = out.far || (first.ok && first.final_cost_w_m2 <= 0.5 * first.initial_cost_w_m2);
  const bool from_subset = out.subset_days > 0;
  if (!from_subset) out.subset_days = first.coarse_subset_days;  // a finer rung's
  // The other basin of two capacitances: a fit on all the days from the
  // start too (MergedNodesWithBothCapacitancesFree).
  if (from_subset && MergedNodesWithBothCapacitancesFree(fs, out.fits[0].params)) {
    out.from_start_after_merge = out.fits.size();
    out.fits.push_back(Identify(cd, cm, fs.base, coarse));
    add(out.fits.back(), 0);
  }
  // Restarts from the residuals of that optimum (RestartsFromResiduals), on
  // the coarsest rung only (a coarse fit with a coarse stage of its own
  // restarts there).
  const std::vector<ParamVector> restarts =
      coarse.coarse_step_s > 0.0 ? std::vector<ParamVector>{}
                                 : RestartsFromResiduals(drivers, meas, fs, out.fits[0].params);
  for (const ParamVector& restart : restarts) {
    out.fits.push_back(Identify(cd, cm, restart, coarse));
    add(out.fits.back(), 1);  // + the run without the effect
  }
  return out;
}

// The cost of p on the data as given where the fine stage will most likely
// start from p: with the Jacobian of all free parameters at p computed by
// the same run (Objective::DataCostWithJacobianAhead), when the fit asks
// for it first, at p itself: lad_lm (RunFit takes the start, not its round
// trip through the unit coordinates). NLopt's methods start at that round
// trip, a few ulps away, where the Jacobian would be in vain.
double CostOfTheFineStart(Objective& obj, const FreeSet& fs, const IdentOptions& options,
                          const ParamVector& p) {
  if (!options.jacobian_ahead || options.method != IdentMethod::kLadLm) return obj.DataCost(p);
  obj.SetFree(fs.free, fs.infos, std::vector<double>(fs.free.size(), 0.0));
  return obj.DataCostWithJacobianAhead(p, fs.infos);
}

// The best of the coarse fits on the data as given, in their order: a
// misspecified model can have its coarse optimum far from the fine one, so
// one replaces *best only if it also beats the start (`initial_cost`). A
// single coarse fit that at least halved its cost (on the coarse data) took
// the fit far from a start that fitted badly: its optimum is then the fine
// stage's start (CostOfTheFineStart). From a start that fits well already
// (a warm start, the daemon's nightly case) the coarse optimum often loses
// to it on the data as given, and a Jacobian computed ahead there would be
// a run with sensitivities in vain: 15 % more instructions on the bench's
// warm starts at 1 min when every coarse optimum was priced ahead (callgrind,
// 18520fd against bf74886; core/fit/README.md).
void PickCoarse(const CoarseFits& coarse, Objective& obj, const FreeSet& fs,
                const IdentOptions& options, double initial_cost, ParamVector* best) {
  double best_cost = initial_cost;
  for (const IdentSummary& fit : coarse.fits) {
    if (!fit.ok) continue;
    const double cost = coarse.fits.size() == 1 && coarse.far
                            ? CostOfTheFineStart(obj, fs, options, fit.params)
                            : obj.DataCost(fit.params);
    if (cost < best_cost) {
      *best = fit.params;
      best_cost = cost;
    }
  }
}

// The fine stage: the fit of the active parameters, then identifiability
// (standard errors of the free parameters at the fit; a parameter whose
// standard error exceeds undetermined_se of its range is fixed at its
// reference value, worst first, provided that costs at most
// fix_cost_tolerance more: a parameter the data really do not determine
// costs nothing to fix), then a polish of the rest. The trial fits that
// decide a fix run on the coarse stage's data when it had a fit (`coarse`).
class FineFit {
 public:
  FineFit(Objective& obj, const FreeSet& fs, const Measurements& meas, const IdentOptions& options,
          const Plant& plant, const CoarseFits& coarse, const ParamVector& best)
      : obj_(obj),
        fs_(fs),
        options_(options),
        area_m2_(plant.area_m2),
        coarse_simulations_(coarse.simulations),
        n_rows_(static_cast<double>(meas.rows.size())),
        active_(fs.free.size(), true),
        se_(fs.free.size(), 0.0),
        rejected_(fs.free.size(), false),
        kept_cost_(fs.free.size(), kNaN),
        best_(best) {
    // Floor of the residual spread for the standard errors: 0.1 % of the
    // mean measured power per m², so that noise-free data still expose
    // exactly flat directions and nothing else.
    double mean_abs = 0.0;
    for (std::uint32_t i : meas.rows)
      mean_abs += std::fabs(meas.p_el_w[i]) + std::fabs(meas.q_th_w[i]);
    sigma_floor_ = 1e-3 * mean_abs / (2.0 * n_rows_ * area_m2_);
    if (!coarse.fits.empty()) {
      trial_obj_.emplace(coarse.drivers, coarse.meas, options, fs.base);
      trial_rows_ = static_cast<double>(coarse.meas.rows.size());
    }
  }

  // The fit from the best point so far (coarse stage or start); after a
  // coarse stage a polish (IdentOptions::polish_stop_prediction_factor).
  void FitAll() {
    fit_ = FitActive(obj_, n_rows_, active_, best_, &best_cost_, std::numeric_limits<int>::max(),
                     trial_obj_ ? options_.polish_stop_prediction_factor
                                : LadFitOptions{}.stop_prediction_factor);
    if (fit_.termination == Termination::kMaxEvaluations && fit_.message == "no evaluations left") {
      fit_.ok = true;  // nothing could be tried; the start stands (and is reported)
    }
    best_ = fit_.params;
  }

  void FixUnidentifiable(std::vector<std::string>* notes) {
    for (int round = 0; fit_.ok && options_.fix_unidentifiable && round < 8; ++round) {
      if (!FixRound(notes)) break;
    }
  }

  // Polish the remaining parameters once with the fixed ones in place.
  void Polish() {
    if (!any_fixed_ || Remaining() <= 20) return;
    double polished_cost = 0.0;
    const FitOutcome polished = FitActive(obj_, n_rows_, active_, best_, &polished_cost);
    if (polished.ok && polished_cost <= best_cost_) {
      best_ = polished.params;
      best_cost_ = polished_cost;
      fit_.termination = polished.termination;
    }
  }

  int Remaining() const {
    return options_.optimizer.max_evaluations - obj_.simulations() - coarse_simulations_ -
           TrialSimulations();
  }
  // The trial fits' runs on the coarse stage's data, and of them with
  // sensitivities and served.
  int TrialSimulations() const { return trial_obj_ ? trial_obj_->simulations() : 0; }
  int TrialSensitivityRuns() const { return trial_obj_ ? trial_obj_->sensitivity_runs() : 0; }
  int TrialServed() const { return trial_obj_ ? trial_obj_->served() : 0; }
  // The time of the fixing rounds' trial fits (IdentSummary::trial_runtime_s).
  double TrialRuntime() const { return trial_runtime_s_; }
  const FitOutcome& fit() const { return fit_; }
  const ParamVector& best() const { return best_; }
  const std::vector<bool>& active() const { return active_; }
  const std::vector<double>& se() const { return se_; }

 private:
  // Fits the parameters marked in `act_mask` from `from_point` (the others
  // held at their reference values) on obj's data (n_rows objective rows);
  // returns the outcome, and its data cost when data_cost is not null.
  FitOutcome FitActive(Objective& obj, double n_rows, const std::vector<bool>& act_mask,
                       const ParamVector& from_point, double* data_cost,
                       int max_budget = std::numeric_limits<int>::max(),
                       double stop_prediction_factor = LadFitOptions{}.stop_prediction_factor) {
    std::vector<Param> act;
    std::vector<ParamInfo> act_infos;
    std::vector<double> z_ref;
    ParamVector from = from_point;
    for (std::size_t j = 0; j < fs_.free.size(); ++j) {
      const auto idx = static_cast<std::size_t>(fs_.free[j]);
      if (!act_mask[j]) {
        from[idx] = fs_.base[idx];
        continue;
      }
      act.push_back(fs_.free[j]);
      act_infos.push_back(fs_.infos[j]);
      z_ref.push_back(ToUnit(fs_.infos[j], fs_.base[idx]));
    }
    obj.SetBase(from);
    obj.SetFree(act, act_infos, z_ref);
    FitOutcome out;
    if (act.empty()) {
      out.params = from;
      out.ok = true;
      out.termination = Termination::kConverged;
    } else {
      // One simulation stays reserved for the final check of the result.
      const int budget = std::min(Remaining() - 1, max_budget);
      if (budget >= 2) {
        out = RunFit(obj, act_infos, z_ref, from, options_, budget, n_rows, area_m2_,
                     stop_prediction_factor);
      } else {
        out.params = from;
        out.ok = true;
        out.termination = Termination::kMaxEvaluations;
        out.message = "no evaluations left";
      }
    }
    if (data_cost != nullptr) *data_cost = obj.DataCost(out.params);
    return out;
  }

  std::vector<ParamInfo> ActiveInfos() const {
    std::vector<ParamInfo> v;
    for (std::size_t j = 0; j < fs_.free.size(); ++j) {
      if (active_[j]) v.push_back(fs_.infos[j]);
    }
    return v;
  }

  // One round of fixing: the standard errors of the active parameters, the
  // worst undetermined one fixed if that is cheap enough. False when no
  // round is left to do.
  bool FixRound(std::vector<std::string>* notes) {
    std::vector<std::size_t> act_index;  // positions in `free` of the active ones
    for (std::size_t j = 0; j < fs_.free.size(); ++j) {
      if (active_[j]) act_index.push_back(j);
    }
    const auto m = static_cast<Eigen::Index>(act_index.size());
    if (m <= 1 || Remaining() < static_cast<int>(m) + 10) return false;
    if (jac_.cols() != m) {
      if (fit_.jacobian.cols() == m) jac_ = std::move(fit_.jacobian);
      if (jac_.cols() == m) {
        obj_.Residuals(best_, &r_);
      } else {
        std::vector<Param> act;
        for (std::size_t j : act_index) act.push_back(fs_.free[j]);
        obj_.SetFree(act, ActiveInfos(), std::vector<double>(act.size(), 0.0));
        jac_ = SensitivityMatrix(obj_, ActiveInfos(), best_, &r_);
      }
    }
    const Eigen::VectorXd act_se = StandardErrors(jac_, r_, sigma_floor_, options_.threads);
    Eigen::Index worst = -1;
    for (Eigen::Index a = 0; a < m; ++a) {
      const std::size_t j = act_index[static_cast<std::size_t>(a)];
      se_[j] = act_se(a);
      if (rejected_[j] || !(act_se(a) > options_.undetermined_se)) continue;
      if (worst < 0 || act_se(a) > act_se(worst)) worst = a;
    }
    if (worst < 0) return false;
    const Eigen::Index mirror = MirrorOfAKeptParameter(act_index, worst);
    if (mirror >= 0) {
      const std::size_t j = act_index[static_cast<std::size_t>(worst)];
      rejected_[j] = true;
      kept_cost_[j] = kept_cost_[act_index[static_cast<std::size_t>(mirror)]];
      notes->push_back(FixNote(j, kept_cost_[j], false));
      return true;
    }
    ParamVector predicted;
    Eigen::VectorXd r_pred;
    double cost = PredictCostOfFixing(act_index, worst, &predicted, &r_pred);
    const std::size_t j = act_index[static_cast<std::size_t>(worst)];
    ParamVector point = predicted;
    // Relative tolerance, with an absolute floor (the 0.1 % of the measured
    // power used for sigma_floor) so that noise-free fits can fix too.
    const double limit = best_cost_ * (1.0 + options_.fix_cost_tolerance) + 2.0 * sigma_floor_;
    // The linear prediction is poor for large moves on a log scale: when it
    // is inconclusive (close to the limit, or the parameter is not bounded
    // by the data at all, se > 1) a short re-fit decides. It runs on the
    // coarse stage's data when there are (a fifth of the time per run at
    // 1 min), and its optimum is priced on the data as given, which decides
    // (core/fit/README.md compares it with the re-fit on the data as given).
    if (std::isfinite(cost) && cost > limit &&
        (cost <= 10.0 * limit - 9.0 * best_cost_ || se_[j] > 1.0)) {
      const auto trial_start = std::chrono::steady_clock::now();
      std::vector<bool> trial_mask = active_;
      trial_mask[j] = false;
      const int trial_budget = 8 * (static_cast<int>(m) + 2);
      const FitOutcome trial =
          trial_obj_
              ? FitActive(*trial_obj_, trial_rows_, trial_mask, predicted, nullptr, trial_budget)
              : FitActive(obj_, n_rows_, trial_mask, predicted, nullptr, trial_budget);
      point = trial.params;
      cost = trial.ok ? obj_.DataCost(point) : kNaN;
      // A coarse-data trial priced just above the limit: a short fit on the
      // data as given from its point decides.
      if (trial_obj_ && trial.ok && std::isfinite(cost) && cost > limit &&
          cost <= limit + options_.fix_cost_tolerance * best_cost_) {
        double fine_cost = kNaN;
        const FitOutcome fine_trial =
            FitActive(obj_, n_rows_, trial_mask, point, &fine_cost, 4 * (static_cast<int>(m) + 2));
        if (fine_trial.ok && fine_cost < cost) {
          point = fine_trial.params;
          cost = fine_cost;
        }
      }
      trial_runtime_s_ +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - trial_start).count();
    }
    if (std::isfinite(cost) && cost <= limit) {
      Fix(worst, j, point, cost, point == predicted ? &r_pred : nullptr);
    } else {
      rejected_[j] = true;
      kept_cost_[j] = cost;
    }
    notes->push_back(FixNote(j, cost, !rejected_[j]));
    return true;
  }

  // The active parameter (position in the Jacobian's columns) of which the
  // active parameter `worst` is the mirror image, when a fixing round kept
  // that one free: the same range, scale, reference value and value, and
  // the same column of the Jacobian (1N and 1N1C see u_front_w_m2k and
  // u_back_w_m2k only as their sum). Fixing `worst` is then the same fit
  // with the two exchanged, and gets the same verdict and cost without
  // another prediction or trial fit. -1 when there is none.
  Eigen::Index MirrorOfAKeptParameter(const std::vector<std::size_t>& act_index,
                                      Eigen::Index worst) const {
    constexpr double kSame = 1e-9;  // relative, of the column's norm and of the unit range
    const std::size_t k = act_index[static_cast<std::size_t>(worst)];
    const ParamInfo& info_k = fs_.infos[k];
    const auto idx_k = static_cast<std::size_t>(fs_.free[k]);
    const double column_norm = jac_.col(worst).norm();
    for (Eigen::Index a = 0; a < jac_.cols(); ++a) {
      const std::size_t j = act_index[static_cast<std::size_t>(a)];
      if (a == worst || !rejected_[j] || !std::isfinite(kept_cost_[j])) continue;
      const ParamInfo& info_j = fs_.infos[j];
      const auto idx_j = static_cast<std::size_t>(fs_.free[j]);
      if (info_j.lower != info_k.lower || info_j.upper != info_k.upper ||
          info_j.scale != info_k.scale || fs_.base[idx_j] != fs_.base[idx_k] ||
          std::fabs(ToUnit(info_j, best_[idx_j]) - ToUnit(info_k, best_[idx_k])) > kSame) {
        continue;
      }
      if ((jac_.col(a) - jac_.col(worst)).norm() <= kSame * column_norm) return a;
    }
    return -1;
  }

  // The cost of fixing the active parameter `worst` (position j in `free`)
  // at its reference value, predicted with one simulation per candidate
  // point: the others unchanged, and the others following the damped
  // (Levenberg) weighted least-squares response of the linearised
  // residuals for two dampings, each step limited to the size of the move of
  // parameter j (the linearisation holds only that far). The cheapest
  // predicts the cost; *predicted and *r_pred are its point and residuals.
  double PredictCostOfFixing(const std::vector<std::size_t>& act_index, Eigen::Index worst,
                             ParamVector* predicted, Eigen::VectorXd* r_pred) {
    const auto m = static_cast<Eigen::Index>(act_index.size());
    const std::size_t j = act_index[static_cast<std::size_t>(worst)];
    const auto idx = static_cast<std::size_t>(fs_.free[j]);
    Eigen::VectorXd z(m);
    for (Eigen::Index a = 0; a < m; ++a) {
      const std::size_t k = act_index[static_cast<std::size_t>(a)];
      z(a) = ToUnit(fs_.infos[k], best_[static_cast<std::size_t>(fs_.free[k])]);
    }
    const double dz_j = ToUnit(fs_.infos[j], fs_.base[idx]) - z(worst);
    Eigen::MatrixXd j_others(jac_.rows(), m - 1);
    for (Eigen::Index a = 0, c = 0; a < m; ++a) {
      if (a != worst) j_others.col(c++) = jac_.col(a);
    }
    const double delta = std::max(0.3 * r_.cwiseAbs().mean(), sigma_floor_);
    const Eigen::VectorXd w = r_.cwiseAbs().cwiseMax(delta).cwiseInverse();
    const Eigen::VectorXd b = r_ + jac_.col(worst) * dz_j;
    Eigen::MatrixXd h;
    Eigen::VectorXd g;
    WeightedNormalEquations(j_others, w, b, options_.threads, &h, &g);
    const double mean_diag = std::max(h.diagonal().mean(), 1e-300);
    const double limit_dz = std::max(std::fabs(dz_j), 0.02);
    double cost = kNaN;
    *predicted = best_;
    for (double damping : {-1.0, 1e-4, 1e-2}) {
      Eigen::VectorXd dz_o = Eigen::VectorXd::Zero(m - 1);
      if (damping > 0.0) {
        Eigen::MatrixXd hd = h;
        hd.diagonal().array() += damping * mean_diag;
        dz_o = -hd.ldlt().solve(g);
        const double norm = dz_o.cwiseAbs().maxCoeff();
        if (norm > limit_dz) dz_o *= limit_dz / norm;
      }
      ParamVector candidate = best_;
      candidate[idx] = fs_.base[idx];
      for (Eigen::Index a = 0, c = 0; a < m; ++a) {
        if (a == worst) continue;
        const std::size_t k = act_index[static_cast<std::size_t>(a)];
        candidate[static_cast<std::size_t>(fs_.free[k])] =
            FromUnit(fs_.infos[k], std::clamp(z(a) + dz_o(c++), 0.0, 1.0));
      }
      Eigen::VectorXd r_cand;
      obj_.Residuals(candidate, &r_cand);
      const double c_cost = r_cand.cwiseAbs().sum() / n_rows_;
      if (std::isfinite(c_cost) && !(c_cost >= cost)) {
        cost = c_cost;
        *predicted = candidate;
        *r_pred = r_cand;
      }
    }
    return cost;
  }

  // Fixes the active parameter `worst` (position j in `free`) at `point`;
  // the old Jacobian without its column serves the next round.
  void Fix(Eigen::Index worst, std::size_t j, const ParamVector& point, double cost,
           const Eigen::VectorXd* r_at_point) {
    const auto m = jac_.cols();
    active_[j] = false;
    best_ = point;
    best_cost_ = cost;
    any_fixed_ = true;
    Eigen::MatrixXd reduced(jac_.rows(), m - 1);
    for (Eigen::Index a = 0, c = 0; a < m; ++a) {
      if (a != worst) reduced.col(c++) = jac_.col(a);
    }
    jac_ = reduced;
    if (r_at_point != nullptr)
      r_ = *r_at_point;
    else
      obj_.Residuals(best_, &r_);
  }

  std::string FixNote(std::size_t j, double cost, bool fixed) const {
    const auto idx = static_cast<std::size_t>(fs_.free[j]);
    const char* range = fs_.infos[j].scale == ParamScale::kLog ? "log" : "search";
    char note[240];
    if (fixed) {
      std::snprintf(note, sizeof(note),
                    "%s is not determined by these data (standard error %.2g of its %s range); "
                    "fixed at its reference value %.4g",
                    Name(fs_.free[j]).c_str(), se_[j], range, fs_.base[idx]);
    } else {
      std::snprintf(note, sizeof(note),
                    "%s is only weakly determined (standard error %.2g of its %s range); kept "
                    "free because fixing it at %.4g raises the MAE by %.1f %%",
                    Name(fs_.free[j]).c_str(), se_[j], range, fs_.base[idx],
                    100.0 * (cost / best_cost_ - 1.0));
    }
    return note;
  }

  Objective& obj_;
  const FreeSet& fs_;
  const IdentOptions& options_;
  double area_m2_;
  int coarse_simulations_;
  double n_rows_;
  double sigma_floor_ = 0.0;
  std::vector<bool> active_;
  std::vector<double> se_;
  std::vector<bool> rejected_;
  std::vector<double> kept_cost_;  // the cost that kept a rejected parameter free
  ParamVector best_;
  double best_cost_ = 0.0;
  bool any_fixed_ = false;
  FitOutcome fit_;
  std::optional<Objective> trial_obj_;  // on the coarse stage's data
  double trial_runtime_s_ = 0.0;        // TrialRuntime
  double trial_rows_ = 0.0;
  Eigen::MatrixXd jac_;  // columns: active parameters, in `free` order
  Eigen::VectorXd r_;
};

// One estimate per parameter the variant uses.
std::vector<ParamEstimate> Estimates(const Drivers& drivers, const FreeSet& fs, const FineFit& fine,
                                     const IdentOptions& options) {
  std::vector<ParamEstimate> out;
  const auto used = UsedParams(drivers.spec);
  const ParamVector& best = fine.best();
  for (std::size_t i = 0; i < kNumParams; ++i) {
    if (!used.test(i)) continue;
    const ParamInfo info = ResolvedInfo(static_cast<Param>(i), drivers.plant);
    ParamEstimate e;
    e.param = info.param;
    e.value = best[i];
    e.start = fs.base[i];
    e.lower = info.lower;
    e.upper = info.upper;
    const auto it = std::find(fs.free.begin(), fs.free.end(), info.param);
    e.free = it != fs.free.end();
    if (e.free) {
      const auto j = static_cast<std::size_t>(it - fs.free.begin());
      e.undetermined = !fine.active()[j];
      e.se_unit = fine.se()[j];
      e.weak = fine.active()[j] && fine.se()[j] > options.undetermined_se;
      const double z = ToUnit(fs.infos[j], e.value);
      e.at_bound = fine.active()[j] && (z < kAtBoundZ || z > 1.0 - kAtBoundZ);
    }
    out.push_back(e);
  }
  return out;
}

}  // namespace

IdentSummary Identify(const Drivers& drivers, const Measurements& meas, const ParamVector& start,
                      const IdentOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  IdentSummary summary;
  summary.variant = drivers.spec.Name();
  summary.algorithm = IdentAlgorithmName(options);
  summary.params = start;
  auto finish = [&](bool ok, const std::string& reason) {
    summary.ok = ok;
    summary.failure_reason = reason;
    summary.runtime_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return summary;
  };
  std::string why;
  if (!options.IsValid(&why)) return finish(false, "invalid options: " + why);
  if (static_cast<int>(meas.rows.size()) < options.min_rows) {
    return finish(false, "too little data: " + std::to_string(meas.rows.size()) +
                             " rows in the objective, at least " +
                             std::to_string(options.min_rows) + " needed");
  }

  const FreeSet fs = SelectFree(drivers, start, options);
  Objective obj(drivers, meas, options, fs.base);
  // The start's cost on the data as given and the coarse stage's fits do
  // not depend on each other: with a second thread the first runs beside
  // the second (one run of the data as given, 12 ms at 5 s, and the
  // averaging of the coarse stage's data). The fit is the same either way.
  const int coarse_factor = CoarseFactor(drivers, options, fs);
  double initial_cost = kNaN;
  CoarseFits coarse;
  auto t_coarse = std::chrono::steady_clock::now();
  // Without a coarse stage the fine stage starts at the start.
  auto start_cost = [&] {
    initial_cost =
        coarse_factor < 2 ? CostOfTheFineStart(obj, fs, options, fs.base) : obj.DataCost(fs.base);
  };
  auto coarse_fits = [&] {
    t_coarse = std::chrono::steady_clock::now();
    coarse = FitCoarse(drivers, meas, options, fs, coarse_factor);
  };
  if (coarse_factor < 2) {
    start_cost();
  } else if (options.threads > 1) {
    RunBoth(start_cost, coarse_fits);
  } else {
    start_cost();
    if (std::isfinite(initial_cost)) coarse_fits();
  }
  summary.initial_cost_w_m2 = initial_cost;
  if (!std::isfinite(initial_cost)) {
    return finish(false, "the model gives non-finite outputs at the start values");
  }
  // The coarse stage's time ends with its fits: the check of their optima on
  // the data as given is the fine stage's first run (with sensitivities
  // for lad_lm, CostOfTheFineStart).
  if (!coarse.fits.empty()) {
    summary.coarse_runtime_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_coarse).count();
  }
  ParamVector best = fs.base;
  PickCoarse(coarse, obj, fs, options, initial_cost, &best);
  if (coarse.from_start_after_merge > 0) {
    const char* from = best == coarse.fits[coarse.from_start_after_merge].params ? "that fit"
                       : best == coarse.fits[0].params ? "the merged nodes"
                                                       : "neither (another point costs less)";
    summary.notes.push_back(
        "the coarse fit from the day subset's optimum merged the two nodes (u_coll_w_m2k at its "
        "upper bound); a coarse fit from the start followed, and the fine stage starts from " +
        std::string(from) + ", the lowest cost on the data as given");
  }
  const int coarse_simulations = coarse.simulations;
  const int coarse_sensitivity_runs = coarse.sensitivity_runs;
  summary.coarse_evaluations = coarse_simulations;
  summary.coarse_subset_days = coarse.subset_days;
  summary.coarse_subset_runtime_s = coarse.subset_runtime_s;
  FineFit fine(obj, fs, meas, options, drivers.plant, coarse, best);
  fine.FitAll();
  const auto t_fixing = std::chrono::steady_clock::now();
  const int fine_runs_before_fixing = obj.simulations();
  fine.FixUnidentifiable(&summary.notes);
  summary.fixing_runtime_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_fixing).count();
  summary.fixing_coarse_evaluations = fine.TrialSimulations();
  summary.trial_runtime_s = fine.TrialRuntime();
  summary.fixing_evaluations =
      obj.simulations() - fine_runs_before_fixing + summary.fixing_coarse_evaluations;
  fine.Polish();
  const FitOutcome& fit = fine.fit();
  summary.termination = fit.termination;
  summary.params = fine.best();
  const double final_cost = obj.DataCost(fine.best());
  summary.final_cost_w_m2 = final_cost;
  summary.train = ComputeErrors(meas, obj.last(), drivers.plant.area_m2);
  // The runs of all the stages; again when the start is kept (its cost run).
  auto count_runs = [&] {
    summary.evaluations = obj.simulations() + coarse_simulations + fine.TrialSimulations();
    summary.sensitivity_runs =
        obj.sensitivity_runs() + coarse_sensitivity_runs + fine.TrialSensitivityRuns();
    summary.served_runs = obj.served() + coarse.served_runs + fine.TrialServed();
  };
  count_runs();
  summary.estimates = Estimates(drivers, fs, fine, options);
  if (!fit.ok) {
    return finish(false, "optimiser stopped with " + std::string(ToString(fit.termination)) +
                             (fit.message.empty() ? "" : ": " + fit.message));
  }
  if (!std::isfinite(final_cost)) return finish(false, "the fitted model gives non-finite outputs");
  if (final_cost > initial_cost) {
    // The start fits better than the result. The fit only ever lowers the
    // cost, but fixing an undetermined parameter may raise it by up to
    // fix_cost_tolerance: from a start at an optimum already (a warm start
    // from the last calibration) the result can end a little above it. The
    // start keeps every fixed parameter at its start value too, so it is
    // the result.
    char buf[160];
    std::snprintf(buf, sizeof(buf),
                  "the start values fit better than the fit's result (%.4g < %.4g W/m2): kept",
                  initial_cost, final_cost);
    summary.notes.emplace_back(buf);
    summary.params = fs.base;
    summary.final_cost_w_m2 = obj.DataCost(fs.base);
    summary.train = ComputeErrors(meas, obj.last(), drivers.plant.area_m2);
    count_runs();
  }
  return finish(true, "");
}

EffectResiduals ResidualsForStart(const Drivers& drivers, const SimOutputs& base,
                                  const Measurements& meas) {
  EffectResiduals residuals;
  residuals.drivers = &drivers;
  residuals.base = &base;
  residuals.rows = &meas.rows;
  residuals.p_el_meas_w = &meas.p_el_w;
  return residuals;
}

double StdErrorInUnit(const ParamEstimate& e) {
  if (!e.free || e.undetermined || !(e.se_unit > 0.0)) return std::nan("");
  return DxDz(Info(e.param).scale, e.lower, e.upper, e.value) * e.se_unit;
}

}  // namespace pvtwin
