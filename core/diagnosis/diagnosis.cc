#include "core/diagnosis/diagnosis.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "core/common/calendar.h"
#include "core/common/units.h"
#include "core/data/resample.h"
#include "core/effects/effects.h"
#include "core/model/irradiance_drivers.h"
#include "core/model/thermal_model.h"
#include "core/physics/solar_position.h"

namespace pvtwin {

namespace {

const double kNaN = std::nan("");

std::string PValue(double p) {
  std::ostringstream s;
  s.precision(2);
  s << p;
  return s.str();
}

// One part of the data (training or held-out) prepared for one model.
struct Part {
  Drivers drivers;
  Measurements meas;
};

// data_start_s: the first row of the whole data set. Soiling counts the days
// since the last cleaning; with no cleaning known, from the start of the data,
// not from the start of each part (SetCleaningTimes ignores cleanings before a
// part's first row, so the count is set here).
bool PreparePart(const Series& s, const Plant& plant, const ModelSpec& spec,
                 std::int64_t data_start_s, Part* part, std::string* error) {
  if (!PrepareDrivers(s, plant, spec, &part->drivers, error)) return false;
  Drivers& d = part->drivers;
  if (d.days_since_clean.size() == d.size()) {
    for (std::size_t i = 0; i < d.size(); ++i) {
      d.days_since_clean[i] = static_cast<double>(d.time_s[i] - data_start_s) / 86400.0;
    }
  }
  part->meas = MakeMeasurements(s, part->drivers);
  return true;
}

// Held-out scores of one model.
struct Score {
  SimOutputs sim;
  ErrorMetrics errors;
  std::vector<double> unit_objective_w_m2;  // per test unit, NaN if the unit has no rows
};

struct Units {
  std::vector<int> unit_of_row;  // per held-out row, −1 = none
  int count = 0;
};

Score ScoreHeldout(const Part& heldout, const ParamVector& params, const Units& units,
                   double area_m2) {
  Score score;
  Simulate(heldout.drivers, params, &score.sim);
  score.errors = ComputeErrors(heldout.meas, score.sim, area_m2);
  std::vector<double> sum(static_cast<std::size_t>(units.count), 0.0);
  std::vector<double> rows(static_cast<std::size_t>(units.count), 0.0);
  for (std::uint32_t i : heldout.meas.rows) {
    const int u = units.unit_of_row[i];
    if (u < 0) continue;
    const auto k = static_cast<std::size_t>(u);
    sum[k] += std::fabs(score.sim.p_el_w[i] - heldout.meas.p_el_w[i]) +
              std::fabs(score.sim.q_th_w[i] - heldout.meas.q_th_w[i]);
    rows[k] += 1.0;
  }
  score.unit_objective_w_m2.assign(static_cast<std::size_t>(units.count), kNaN);
  for (std::size_t k = 0; k < sum.size(); ++k) {
    if (rows[k] > 0.0) score.unit_objective_w_m2[k] = sum[k] / rows[k] / area_m2;
  }
  return score;
}

double MaeSumW(const ErrorMetrics& e) { return e.mae_p_el_w + e.mae_q_th_w; }

PairedTest CompareUnits(const Score& before, const Score& after) {
  std::vector<double> b, a;
  for (std::size_t k = 0; k < before.unit_objective_w_m2.size(); ++k) {
    const double x = before.unit_objective_w_m2[k], y = after.unit_objective_w_m2[k];
    if (std::isfinite(x) && std::isfinite(y)) {
      b.push_back(x);
      a.push_back(y);
    }
  }
  return OneSidedPairedTest(b, a);
}

// Start values for `spec`: the reference values, overwritten by `fitted`
// for every parameter the fitted model used.
ParamVector MergedStart(const Plant& plant, const ModelSpec& fitted_spec,
                        const ParamVector& fitted) {
  ParamVector start = StartParams(plant);
  const std::bitset<kNumParams> used = UsedParams(fitted_spec);
  for (std::size_t p = 0; p < kNumParams; ++p) {
    if (used.test(p)) start[p] = fitted[p];
  }
  return start;
}

// Controls of the evidence regression, per held-out row.
std::vector<std::vector<double>> EvidenceControls(const Drivers& d) {
  const std::size_t n = d.size();
  std::vector<double> g(n), dt(n), flow(n);
  for (std::size_t i = 0; i < n; ++i) {
    g[i] = d.g_poa_w_m2[i];
    dt[i] = d.t_in_c[i] - d.t_amb_c[i];
    flow[i] = d.mdot_kg_s[i];
  }
  return {g, dt, flow};
}

// Residual (predicted − measured) of one output over the objective rows, NaN elsewhere.
std::vector<double> Residual(const Measurements& m, const std::vector<double>& pred,
                             const std::vector<double>& meas) {
  std::vector<double> r(m.size(), kNaN);
  for (std::uint32_t i : m.rows) r[i] = pred[i] - meas[i];
  return r;
}

// The sensor test of a sensor fault (EffectModule::sensor_estimate, see
// EffectTrial): its size estimated on each day of data.
void SensorTest(const Series& data, const std::vector<std::int64_t>& day_starts, const Plant& plant,
                const ModelSpec& spec, const EffectModule& effect, EffectTrial* t) {
  std::vector<double> k;
  for (std::int64_t day : day_starts) {
    const std::size_t lo = data.RowAtOrAfter(day);
    const std::size_t hi = data.RowAtOrAfter(day + kSecondsPerDay);
    Drivers d;
    std::string why;
    if (hi <= lo || !PrepareDrivers(data.Slice(lo, hi), plant, spec, &d, &why)) continue;
    const double kd = effect.sensor_estimate(d);
    if (std::isfinite(kd)) k.push_back(kd);
  }
  if (k.size() < 3) return;
  std::vector<double> sorted = k;
  std::sort(sorted.begin(), sorted.end());
  t->irradiance_bias = sorted[sorted.size() / 2];
  const std::vector<double> zeros(k.size(), 0.0);
  const PairedTest up = OneSidedPairedTest(k, zeros);
  const PairedTest down = OneSidedPairedTest(zeros, k);
  t->irradiance_bias_p = std::min(1.0, 2.0 * std::min(up.wilcoxon_p, down.wilcoxon_p));
  t->irradiance_bias_days = static_cast<int>(k.size());
}

}  // namespace

std::string FixedDecimals(double x, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << x;
  return s.str();
}

IdentOptions DiagnosisIdentOptions() {
  IdentOptions o;
  o.optimizer.ftol_rel = 1e-4;
  return o;
}

bool DiagnosisOptions::IsValid(std::string* why) const {
  std::ostringstream out;
  if (train_days < 0) out << "train_days = " << train_days << ": must be ≥ 0 (0 = automatic); ";
  if (heldout_days < 0)
    out << "heldout_days = " << heldout_days << ": must be ≥ 0 (0 = the rest); ";
  if (step_s != 0.0 &&
      !(step_s >= 1.0 && step_s == std::floor(step_s) && std::fmod(86400.0, step_s) == 0.0)) {
    out << "step_s = " << step_s << ": must be 0 or whole seconds dividing 86400; ";
  }
  std::string ident_why;
  if (!ident.IsValid(&ident_why)) out << "ident: " << ident_why << "; ";
  if (!(alpha > 0.0 && alpha < 1.0)) out << "alpha = " << alpha << ": must be in (0, 1); ";
  if (!(min_shrink_pct >= 0.0 && min_shrink_pct < 100.0)) {
    out << "min_shrink_pct = " << min_shrink_pct << ": must be in [0, 100); ";
  }
  if (min_test_units < 2) out << "min_test_units = " << min_test_units << ": must be ≥ 2; ";
  if (max_ladder_steps < 1) out << "max_ladder_steps = " << max_ladder_steps << ": must be ≥ 1; ";
  if (!(unknown_noise_ratio > 1.0)) {
    out << "unknown_noise_ratio = " << unknown_noise_ratio << ": must be > 1; ";
  }
  const std::vector<std::string> names = EffectNames();
  for (const std::string& e : effects) {
    if (std::find(names.begin(), names.end(), e) == names.end()) {
      out << "effects = " << e << ": not an effect of the vocabulary; ";
    }
  }
  std::string where_why;
  if (!where.IsValid(&where_why)) out << "where: " << where_why << "; ";
  if (threads < 0) out << "threads = " << threads << ": must be ≥ 0; ";
  const std::string text = out.str();
  if (why != nullptr) *why = text.empty() ? "" : text.substr(0, text.size() - 2);
  return text.empty();
}

bool Diagnose(const Series& data_in, const Plant& plant, const ModelSpec& base,
              const DiagnosisOptions& options, DiagnosisResult* result, std::string* error,
              const std::function<void(const std::string&)>& progress_in) {
  const auto t0 = std::chrono::steady_clock::now();
  std::mutex progress_mutex;
  auto progress = [&](const std::string& line) {
    if (!progress_in) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    progress_in(line);
  };
  if (!options.IsValid(error)) return false;
  if (data_in.size() < 2) {
    *error = "the data have fewer than 2 rows";
    return false;
  }
  Series data;
  if (options.step_s > 0.0 && options.step_s != data_in.step_s) {
    if (!Resample(data_in, options.step_s, &data, error)) return false;
  } else {
    data = data_in;
  }
  DiagnosisResult r;
  r.base_variant = base.Name();
  r.step_s = data.step_s;

  // 1. Days and the split.
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  std::vector<std::int64_t> day_starts;
  for (std::int64_t t : data.time_s) {
    const std::int64_t d = SolarDayStartS(t, offset_s);
    if (day_starts.empty() || day_starts.back() != d) day_starts.push_back(d);
  }
  const int n_days = static_cast<int>(day_starts.size());
  if (n_days < 2) {
    *error = "the data span " + std::to_string(n_days) +
             " local solar day; the diagnosis needs at least one training and one held-out day";
    return false;
  }
  int train_days = options.train_days;
  if (train_days == 0)
    train_days = std::clamp(static_cast<int>(std::lround(n_days * 2.0 / 3.0)), 1, n_days - 1);
  if (train_days >= n_days) {
    *error = "train_days = " + std::to_string(train_days) + ": the data span only " +
             std::to_string(n_days) + " local solar days, none would be left for held-out";
    return false;
  }
  const int heldout_days = options.heldout_days == 0
                               ? n_days - train_days
                               : std::min(options.heldout_days, n_days - train_days);
  const std::int64_t train_end_s = day_starts[static_cast<std::size_t>(train_days)];
  const std::int64_t heldout_end_s =
      day_starts[static_cast<std::size_t>(train_days + heldout_days - 1)] + kSecondsPerDay;
  const std::int64_t data_start_s = data.time_s.front();
  const Series train_series = data.Slice(0, data.RowAtOrAfter(train_end_s));
  const Series heldout_series = data.Between(train_end_s, heldout_end_s);

  // 2. Base fit.
  Part base_train, base_heldout;
  if (!PreparePart(train_series, plant, base, data_start_s, &base_train, error) ||
      !PreparePart(heldout_series, plant, base, data_start_s, &base_heldout, error)) {
    return false;
  }
  const std::size_t min_rows = static_cast<std::size_t>(std::max(options.ident.min_rows, 1));
  if (base_train.meas.rows.size() < min_rows || base_heldout.meas.rows.size() < min_rows) {
    *error = "too little data: " + std::to_string(base_train.meas.rows.size()) +
             " objective rows in the training days and " +
             std::to_string(base_heldout.meas.rows.size()) + " in the held-out days (need " +
             std::to_string(min_rows) + " each)";
    return false;
  }
  // Test units: held-out days, or hours when there are too few days.
  Units units;
  r.low_confidence = heldout_days < options.min_test_units;
  r.test_unit = r.low_confidence ? "hour" : "day";
  {
    std::map<std::int64_t, int> index;
    const std::int64_t unit_s = r.low_confidence ? 3600 : kSecondsPerDay;
    units.unit_of_row.assign(heldout_series.size(), -1);
    for (std::uint32_t i : base_heldout.meas.rows) {
      const std::int64_t t = heldout_series.time_s[i];
      const std::int64_t key =
          r.low_confidence ? (t - offset_s) / unit_s : SolarDayStartS(t, offset_s);
      auto [it, inserted] = index.emplace(key, units.count);
      if (inserted) ++units.count;
      units.unit_of_row[i] = it->second;
    }
  }
  if (r.low_confidence) {
    r.notes.push_back("only " + std::to_string(heldout_days) +
                      " held-out day(s): improvements are tested over one-hour blocks, which share "
                      "the weather of their day, so a significant result is weaker evidence than "
                      "one over " +
                      std::to_string(options.min_test_units) + "+ days");
  }
  progress("diagnosis: " + std::to_string(train_days) + " training days, " +
           std::to_string(heldout_days) + " held-out days, step " + FixedDecimals(data.step_s, 0) +
           " s; fitting the base model " + r.base_variant);
  const IdentSummary base_fit =
      Identify(base_train.drivers, base_train.meas, StartParams(plant), options.ident);
  r.identifications = 1;
  if (!base_fit.ok) {
    *error = "identification of the base model " + r.base_variant +
             " failed: " + base_fit.failure_reason;
    return false;
  }
  const double area_m2 = plant.area_m2;
  SimOutputs base_train_sim;
  Simulate(base_train.drivers, base_fit.params, &base_train_sim);
  Score base_score = ScoreHeldout(base_heldout, base_fit.params, units, area_m2);
  r.gap = base_score.errors;
  progress("base " + r.base_variant + ": held-out MAE P_el " + FixedDecimals(r.gap.mae_p_el_w, 2) +
           " W, Q_u " + FixedDecimals(r.gap.mae_q_th_w, 2) + " W (" +
           FixedDecimals(base_fit.runtime_s, 2) + " s)");
  {
    LadderStep step;
    step.variant = r.base_variant;
    step.heldout = base_score.errors;
    step.heldout_mae_w = MaeSumW(base_score.errors);
    step.objective_w_m2 = base_score.errors.objective_w_m2();
    step.params = base_fit.params;
    r.ladder.push_back(step);
  }

  // 3. Where: localise the base model's held-out residuals.
  const std::vector<RegimeDriver> regimes =
      StandardRegimeDrivers(heldout_series, base_heldout.drivers, plant);
  const std::vector<double> res_p =
      Residual(base_heldout.meas, base_score.sim.p_el_w, base_heldout.meas.p_el_w);
  const std::vector<double> res_q =
      Residual(base_heldout.meas, base_score.sim.q_th_w, base_heldout.meas.q_th_w);
  for (const auto& [res, name] : {std::pair{&res_p, "p_el"}, std::pair{&res_q, "q_th"}}) {
    const Localisation loc = LocaliseGap(heldout_series.time_s, *res, name, regimes, options.where);
    r.where.insert(r.where.end(), loc.regions.begin(), loc.regions.end());
    r.where_bins.insert(r.where_bins.end(), loc.bins.begin(), loc.bins.end());
  }
  std::stable_sort(r.where.begin(), r.where.end(), [](const GapRegion& a, const GapRegion& b) {
    return a.share_of_abs_error - a.share_of_rows > b.share_of_abs_error - b.share_of_rows;
  });

  // 4–5. Candidates and the ladder.
  const std::vector<std::vector<double>> controls = EvidenceControls(base_heldout.drivers);
  ModelSpec current_spec = base;
  ParamVector current_params = base_fit.params;
  Score current_score = base_score;
  std::set<std::string> accepted;
  const int threads = options.threads > 0
                          ? options.threads
                          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int step = 1; step <= options.max_ladder_steps; ++step) {
    std::vector<SkippedEffect> skipped;
    std::vector<EffectCandidate> candidates = CandidateEffects(current_spec, data, &skipped);
    if (!options.effects.empty()) {
      std::erase_if(candidates, [&options](const EffectCandidate& c) {
        return std::find(options.effects.begin(), options.effects.end(), c.name) ==
               options.effects.end();
      });
    }
    // An effect that needs more training days than there are (a drift over days).
    std::erase_if(candidates, [&skipped, train_days](const EffectCandidate& c) {
      if (train_days >= c.module->min_train_days) return false;
      skipped.push_back({c.name, "needs at least " + std::to_string(c.module->min_train_days) +
                                     " training days " +
                                     std::string(c.module->min_train_days_why)});
      return true;
    });
    if (step == 1) r.skipped = skipped;
    if (candidates.empty()) break;
    std::vector<EffectTrial> trials(candidates.size());
    std::vector<Score> scores(candidates.size());
    std::atomic<std::size_t> next{0};
    std::atomic<int> done{0};
    auto worker = [&] {
      for (std::size_t k = next++; k < candidates.size(); k = next++) {
        const EffectCandidate& c = candidates[k];
        EffectTrial& t = trials[k];
        t.name = c.name;
        t.variant = c.spec.Name();
        t.tested_against = current_spec.Name();
        t.explanation = c.explanation;
        t.signature = c.signature;
        t.advice = std::string(c.module->advice);
        t.heldout_mae_before_w = MaeSumW(current_score.errors);
        Part tr, ho;
        std::string why;
        if (!PreparePart(train_series, plant, c.spec, data_start_s, &tr, &why) ||
            !PreparePart(heldout_series, plant, c.spec, data_start_s, &ho, &why)) {
          t.failure = why;
        } else {
          // Evidence on the base model's residuals (the gap being explained).
          if (step == 1) {
            const std::vector<double> sig = CandidateSignature(c, ho.drivers, base_score.sim);
            std::vector<std::vector<double>> ctl = controls;
            const PartialCorrelation cp = [&] {
              ctl.push_back(base_score.sim.p_el_w);
              return PartialCorrelate(res_p, sig, ctl);
            }();
            ctl.back() = base_score.sim.q_th_w;
            const PartialCorrelation cq = PartialCorrelate(res_q, sig, ctl);
            const bool use_q = std::fabs(cq.z) >= std::fabs(cp.z);
            t.evidence_corr = use_q ? cq : cp;
            t.evidence_output = use_q ? "q_th" : "p_el";
          }
          ParamVector start = MergedStart(plant, current_spec, current_params);
          if (c.module->start_from_residuals != nullptr) {
            EffectResiduals res;
            res.drivers = &base_train.drivers;
            res.base = &base_train_sim;
            res.rows = &base_train.meas.rows;
            res.p_el_meas_w = &base_train.meas.p_el_w;
            c.module->start_from_residuals(res, &start);
          }
          const IdentSummary fit = Identify(tr.drivers, tr.meas, start, options.ident);
          t.fit_runtime_s = fit.runtime_s;
          t.params = fit.params;
          if (!fit.ok) {
            t.failure = "identification failed: " + fit.failure_reason;
          } else {
            scores[k] = ScoreHeldout(ho, fit.params, units, area_m2);
            if (!std::isfinite(scores[k].errors.objective_w_m2())) {
              t.failure = "non-finite held-out outputs";
            } else {
              t.fit_ok = true;
              t.heldout_mae_after_w = MaeSumW(scores[k].errors);
              t.shrink_pct = 100.0 * (1.0 - scores[k].errors.objective_w_m2() /
                                                current_score.errors.objective_w_m2());
              t.test = CompareUnits(current_score, scores[k]);
              t.significant =
                  t.test.wilcoxon_p <= options.alpha && t.shrink_pct >= options.min_shrink_pct;
              if (c.module->sensor_estimate != nullptr) {
                SensorTest(data, day_starts, plant, c.spec, *c.module, &t);
                t.significant = t.irradiance_bias_p <= options.alpha &&
                                std::fabs(t.irradiance_bias) >= options.min_sensor_error;
              }
            }
          }
        }
        const int finished = ++done;
        progress("[step " + std::to_string(step) + ", " + std::to_string(finished) + "/" +
                 std::to_string(candidates.size()) + "] +" + t.name + ": " +
                 (t.fit_ok ? "shrink " + FixedDecimals(t.shrink_pct, 1) + " %, better on " +
                                 std::to_string(t.test.positives) + " of " +
                                 std::to_string(t.test.pairs) + " " + r.test_unit + "s, p = " +
                                 PValue(t.test.wilcoxon_p) + (t.significant ? " (significant)" : "")
                           : "FAILED: " + t.failure) +
                 " (" + FixedDecimals(t.fit_runtime_s, 2) + " s)");
      }
    };
    {
      std::vector<std::thread> pool;
      const int n_threads = std::min<int>(threads, static_cast<int>(candidates.size()));
      for (int w = 1; w < n_threads; ++w) pool.emplace_back(worker);
      worker();
      for (std::thread& th : pool) th.join();
    }
    r.identifications += static_cast<int>(candidates.size());
    // Evidence sentences.
    for (std::size_t k = 0; k < trials.size(); ++k) {
      EffectTrial& t = trials[k];
      const EffectModule& effect = *candidates[k].module;
      std::ostringstream ev;
      if (step == 1 && t.evidence_corr.rows > 0) {
        ev << "partial correlation of the " << (t.evidence_output == "q_th" ? "Q_u" : "P_el")
           << " residual with " << t.signature << " r = " << FixedDecimals(t.evidence_corr.r, 2)
           << " (z = " << FixedDecimals(t.evidence_corr.z, 1)
           << ", n_eff = " << FixedDecimals(t.evidence_corr.n_eff, 0) << "); ";
      }
      if (effect.sensor_evidence != nullptr && std::isfinite(t.irradiance_bias)) {
        ev << effect.sensor_evidence(t.irradiance_bias, t.irradiance_bias_p,
                                     t.irradiance_bias_days);
      }
      if (t.fit_ok) {
        ev << "re-identified " << t.variant << " lowers the held-out MAE on " << t.test.positives
           << " of " << t.test.pairs << " " << r.test_unit
           << "s (one-sided Wilcoxon p = " << PValue(t.test.wilcoxon_p)
           << ", sign test p = " << PValue(t.test.sign_p) << ")";
      } else {
        ev << "not tested: " << t.failure;
      }
      t.evidence = ev.str();
    }
    // Pick the best significant effect.
    std::size_t best = candidates.size();
    for (std::size_t k = 0; k < trials.size(); ++k) {
      if (!trials[k].significant) continue;
      if (best == candidates.size() || trials[k].shrink_pct > trials[best].shrink_pct) best = k;
    }
    if (step == 1) {
      r.effects = trials;
    }
    if (best == candidates.size()) break;
    EffectTrial& chosen = trials[best];
    chosen.accepted_at_step = step;
    // The effects list keeps, for an effect accepted later, its trial at that step.
    bool replaced = false;
    for (EffectTrial& e : r.effects) {
      if (e.name == chosen.name) {
        const PartialCorrelation ev_corr = e.evidence_corr;
        const std::string ev_out = e.evidence_output;
        const std::string first_evidence = e.evidence;
        e = chosen;
        if (step > 1) {
          e.evidence_corr = ev_corr;
          e.evidence_output = ev_out;
          e.evidence = first_evidence.substr(0, first_evidence.find("; ") + 2) + chosen.evidence;
        }
        replaced = true;
      }
    }
    if (!replaced) r.effects.push_back(chosen);
    LadderStep ls;
    ls.variant = chosen.variant;
    ls.added = chosen.name;
    ls.heldout = scores[best].errors;
    ls.heldout_mae_w = MaeSumW(scores[best].errors);
    ls.objective_w_m2 = scores[best].errors.objective_w_m2();
    ls.shrink_pct = chosen.shrink_pct;
    ls.p_value = chosen.test.wilcoxon_p;
    ls.params = chosen.params;
    r.ladder.push_back(ls);
    current_spec = candidates[best].spec;
    current_params = chosen.params;
    current_score = std::move(scores[best]);
    accepted.insert(chosen.name);
    progress("accepted +" + chosen.name + ": " + chosen.variant);
  }
  r.final_variant = current_spec.Name();

  // Rank: accepted effects in ladder order, then significant ones, then by shrink.
  std::stable_sort(r.effects.begin(), r.effects.end(),
                   [](const EffectTrial& a, const EffectTrial& b) {
                     auto key = [](const EffectTrial& t) {
                       return std::tuple(t.accepted_at_step > 0 ? 0 : 1,
                                         t.accepted_at_step > 0 ? t.accepted_at_step : 0,
                                         t.significant ? 0 : 1, t.fit_ok ? -t.shrink_pct : 1e300);
                     };
                     return key(a) < key(b);
                   });

  // 6. Noise floor from the final model's held-out residuals.
  {
    Part final_heldout;
    std::string why;
    if (!PreparePart(heldout_series, plant, current_spec, data_start_s, &final_heldout, &why)) {
      *error = "internal: final model " + r.final_variant + ": " + why;
      return false;
    }
    const std::vector<double> fp =
        Residual(final_heldout.meas, current_score.sim.p_el_w, final_heldout.meas.p_el_w);
    const std::vector<double> fq =
        Residual(final_heldout.meas, current_score.sim.q_th_w, final_heldout.meas.q_th_w);
    std::vector<std::int64_t> segment(heldout_series.size());
    const double step = heldout_series.step_s > 0.0 ? heldout_series.step_s : 1.0;
    for (std::size_t i = 0; i < segment.size(); ++i) {
      segment[i] = heldout_series.time_s[i] -
                   static_cast<std::int64_t>(std::llround(static_cast<double>(i) * step));
    }
    r.noise.mae_p_el_w = NoiseMaeFromSecondDifferences(fp, segment);
    r.noise.mae_q_th_w = NoiseMaeFromSecondDifferences(fq, segment);
    r.noise.objective_w_m2 = (r.noise.mae_p_el_w + r.noise.mae_q_th_w) / area_m2;
    r.noise.ratio = current_score.errors.objective_w_m2() / r.noise.objective_w_m2;

    // Trace for the plots.
    DiagnosisTrace& tr = r.trace;
    const std::vector<RegimeDriver>& rg = regimes;
    auto driver_values = [&rg](const std::string& name, bool second) -> const std::vector<double>* {
      for (const RegimeDriver& d : rg) {
        if (d.name == name) return second ? &d.values2 : &d.values;
      }
      return nullptr;
    };
    const std::vector<double>* hour = driver_values("hour_of_day", false);
    const std::vector<double>* aoi = driver_values("aoi_deg", false);
    const std::vector<double>* az = driver_values("sun_azimuth_deg", false);
    const std::vector<double>* el = driver_values("sun_azimuth_deg", true);
    for (std::uint32_t i : base_heldout.meas.rows) {
      tr.time_s.push_back(heldout_series.time_s[i]);
      tr.p_el_meas_w.push_back(base_heldout.meas.p_el_w[i]);
      tr.q_th_meas_w.push_back(base_heldout.meas.q_th_w[i]);
      tr.p_el_base_w.push_back(base_score.sim.p_el_w[i]);
      tr.q_th_base_w.push_back(base_score.sim.q_th_w[i]);
      tr.p_el_final_w.push_back(current_score.sim.p_el_w[i]);
      tr.q_th_final_w.push_back(current_score.sim.q_th_w[i]);
      tr.hour_of_day.push_back(hour ? (*hour)[i] : kNaN);
      tr.aoi_deg.push_back(aoi ? (*aoi)[i] : kNaN);
      tr.sun_azimuth_deg.push_back(az ? (*az)[i] : kNaN);
      tr.sun_elevation_deg.push_back(el ? (*el)[i] : kNaN);
    }
  }

  // Days.
  for (int k = 0; k < train_days + heldout_days; ++k) {
    DiagnosisDay day;
    day.start_s = day_starts[static_cast<std::size_t>(k)];
    day.date = SolarDate(day.start_s, offset_s);
    day.heldout = k >= train_days;
    const Measurements& m = day.heldout ? base_heldout.meas : base_train.meas;
    const Series& s = day.heldout ? heldout_series : train_series;
    double base_sum = 0.0, final_sum = 0.0;
    for (std::uint32_t i : m.rows) {
      if (SolarDayStartS(s.time_s[i], offset_s) != day.start_s) continue;
      ++day.rows;
      if (day.heldout) {
        base_sum += std::fabs(base_score.sim.p_el_w[i] - m.p_el_w[i]) +
                    std::fabs(base_score.sim.q_th_w[i] - m.q_th_w[i]);
        final_sum += std::fabs(current_score.sim.p_el_w[i] - m.p_el_w[i]) +
                     std::fabs(current_score.sim.q_th_w[i] - m.q_th_w[i]);
      }
    }
    if (day.heldout) {
      day.base_objective_w_m2 =
          day.rows ? base_sum / static_cast<double>(day.rows) / area_m2 : kNaN;
      day.final_objective_w_m2 =
          day.rows ? final_sum / static_cast<double>(day.rows) / area_m2 : kNaN;
    }
    r.days.push_back(day);
  }

  // 7. Verdict.
  const LadderStep& last = r.ladder.back();
  const LadderStep& first = r.ladder.front();
  if (r.ladder.size() > 1) {
    r.verdict = r.ladder[1].added;
    const EffectTrial* top = nullptr;
    for (const EffectTrial& t : r.effects) {
      if (t.name == r.verdict) top = &t;
    }
    std::ostringstream s;
    s << "The model " << r.base_variant << " misses " << r.verdict
      << ": adding it and re-identifying "
      << "cuts the held-out error (MAE P_el + Q_u) by " << FixedDecimals(r.ladder[1].shrink_pct, 1)
      << " %, from " << FixedDecimals(first.heldout_mae_w, 1) << " W to "
      << FixedDecimals(r.ladder[1].heldout_mae_w, 1) << " W";
    if (top != nullptr) {
      s << ", lower on " << top->test.positives << " of " << top->test.pairs << " held-out "
        << r.test_unit << "s (Wilcoxon p = " << PValue(top->test.wilcoxon_p) << ")";
    }
    s << ".";
    if (r.ladder.size() > 2) {
      s << " Then";
      for (std::size_t k = 2; k < r.ladder.size(); ++k) {
        s << (k > 2 ? "," : "") << " +" << r.ladder[k].added << " (−"
          << FixedDecimals(r.ladder[k].shrink_pct, 1) << " %)";
      }
      s << ", ending at " << FixedDecimals(last.heldout_mae_w, 1) << " W with " << r.final_variant
        << ".";
    }
    if (r.low_confidence) s << " Low confidence: too few held-out days.";
    r.verdict_sentence = s.str();
  } else if (r.noise.ratio > options.unknown_noise_ratio) {
    r.verdict = "unknown";
    std::ostringstream s;
    s << "The held-out error of " << r.base_variant << " (" << FixedDecimals(first.heldout_mae_w, 1)
      << " W, MAE P_el + Q_u) is " << FixedDecimals(r.noise.ratio, 1)
      << "× what sensor noise explains, but no catalogued effect removes it consistently";
    if (!r.where.empty()) {
      const GapRegion& w = r.where.front();
      s << "; it concentrates where " << w.driver << " is in [" << FixedDecimals(w.lower, 1) << ", "
        << FixedDecimals(w.upper, 1) << ")";
      if (!w.label.empty()) s << " (" << w.label << ")";
      if (!w.driver2.empty()) {
        s << " and " << w.driver2 << " in [" << FixedDecimals(w.lower2, 1) << ", "
          << FixedDecimals(w.upper2, 1) << ")";
      }
      s << ": " << FixedDecimals(100.0 * w.share_of_abs_error, 0) << " % of the "
        << (w.output == "q_th" ? "Q_u" : "P_el") << " error in "
        << FixedDecimals(100.0 * w.share_of_rows, 0) << " % of the rows";
    }
    s << ".";
    r.verdict_sentence = s.str();
  } else {
    r.verdict = "none";
    r.verdict_sentence = "No catalogued effect lowers the held-out error of " + r.base_variant +
                         " consistently; its held-out error (" +
                         FixedDecimals(first.heldout_mae_w, 1) + " W, MAE P_el + Q_u) is " +
                         FixedDecimals(r.noise.ratio, 1) + "× the sensor-noise floor.";
  }
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  *result = std::move(r);
  return true;
}

}  // namespace pvtwin
