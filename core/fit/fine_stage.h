// The fine stage of identification: the fit of the active parameters on the
// data as given, the identifiability loop (a parameter the data do not
// determine is fixed, worst first, when that costs at most
// fix_cost_tolerance) and the polish of the rest; the estimates it reports.
// Internal to core/fit/.
#pragma once

#include <vector>

#include "core/fit/coarse_stage.h"
#include "core/fit/objective.h"

namespace pvtwin::fit_internal {

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
                                     const IdentOptions& options);

}  // namespace pvtwin::fit_internal
