// The coarse stage of identification; see core/fit/coarse_stage.h.
#include "core/fit/coarse_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <vector>

#include "core/common/calendar.h"
#include "core/effects/registry.h"

namespace pvtwin::fit_internal {

void Coarsen(const Drivers& d, const Measurements& m, int factor, Drivers* cd, Measurements* cm,
             const std::vector<std::uint8_t>* keep) {
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

FreeSet SelectFree(const Drivers& drivers, const ParamVector& start, const IdentOptions& options) {
  const auto used = UsedParams(drivers.spec);
  const auto requested = options.free.any() ? options.free : DefaultFreeParams(drivers.spec);
  FreeSet fs;
  fs.base = start;
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const ParamInfo info = SearchInfo(static_cast<Param>(i), drivers.plant, options);
    fs.base[i] = std::clamp(fs.base[i], info.lower, info.upper);
    if (used.test(i) && requested.test(i) && info.upper > info.lower) {
      fs.free.push_back(static_cast<Param>(i));
      fs.infos.push_back(info);
    }
  }
  return fs;
}

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

int CoarseFactor(const Drivers& drivers, const IdentOptions& options, const FreeSet& fs) {
  const double data_step_s = drivers.dt_s.empty() ? 0.0 : drivers.dt_s[0];
  const double coarse_step_s =
      data_step_s < 30.0 && options.coarse_step_s > 60.0 ? 60.0 : options.coarse_step_s;
  if (fs.free.empty() || options.optimizer.max_evaluations < 200) return 1;
  return coarse_step_s > 0.0 && data_step_s > 0.0
             ? static_cast<int>(coarse_step_s / data_step_s + 0.5)
             : 1;
}

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

bool MergedNodesWithBothCapacitancesFree(const FreeSet& fs, const ParamVector& p) {
  auto position = [&](Param q) { return std::ranges::find(fs.free, q) - fs.free.begin(); };
  const auto n = static_cast<std::ptrdiff_t>(fs.free.size());
  const std::ptrdiff_t u = position(Param::kUCollWM2K);
  if (position(Param::kCPvJM2K) == n || position(Param::kCCollJM2K) == n || u == n) return false;
  const ParamInfo& info = fs.infos[static_cast<std::size_t>(u)];
  return ToUnit(info, p[static_cast<std::size_t>(info.param)]) > 1.0 - kAtBoundZ;
}

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

double CostOfTheFineStart(Objective& obj, const FreeSet& fs, const IdentOptions& options,
                          const ParamVector& p) {
  if (!options.jacobian_ahead || options.method != IdentMethod::kLadLm) return obj.DataCost(p);
  obj.SetFree(fs.free, fs.infos, std::vector<double>(fs.free.size(), 0.0));
  return obj.DataCostWithJacobianAhead(p, fs.infos);
}

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

}  // namespace pvtwin::fit_internal
