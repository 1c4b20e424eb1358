// Identify: the coarse stage, then the fine stage with its identifiability
// loop (core/fit/coarse_stage.h, core/fit/fine_stage.h), on the objective of
// core/fit/objective.h.
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
#include "core/fit/coarse_stage.h"
#include "core/fit/fine_stage.h"
#include "core/fit/lad_fit.h"
#include "core/fit/objective.h"
#include "core/model/sensitivities.h"

namespace pvtwin {

using fit_internal::CoarseFactor;
using fit_internal::CoarseFits;
using fit_internal::CostOfTheFineStart;
using fit_internal::DxDz;
using fit_internal::Estimates;
using fit_internal::FineFit;
using fit_internal::FitCoarse;
using fit_internal::FitOutcome;
using fit_internal::FreeSet;
using fit_internal::kNaN;
using fit_internal::Name;
using fit_internal::Objective;
using fit_internal::PickCoarse;
using fit_internal::SelectFree;

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
