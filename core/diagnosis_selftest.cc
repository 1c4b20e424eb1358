#include "core/diagnosis_selftest.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "core/backtest.h"
#include "core/identification.h"
#include "core/qc.h"
#include "core/synthetic_plant.h"
#include "core/thermal_model.h"

namespace pvtwin {

namespace {

const double kNaN = std::nan("");

ModelSpec Parse(const std::string& name) {
  ModelSpec spec;
  std::string error;
  if (!ParseVariant(name, &spec, &error)) {
    std::cerr << "diagnosis self-test: bad built-in variant " << name << ": " << error << "\n";
    std::abort();
  }
  return spec;
}

SimOutputs SimulateOrAbort(const Series& s, const Plant& plant, const ModelSpec& spec,
                           const ParamVector& params) {
  Drivers d;
  std::string error;
  if (!PrepareDrivers(s, plant, spec, &d, &error)) {
    std::cerr << "diagnosis self-test: " << error << "\n";
    std::abort();  // the generator provides every channel: a bug
  }
  SimOutputs out;
  Simulate(d, params, &out);
  return out;
}

std::string Fixed(double x, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << x;
  return s.str();
}

// Held-out objective of the truth model with its true parameters.
double TruthHeldoutObjective(const Series& data, const Plant& plant, const SelftestCase& c,
                             int train_days) {
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  const std::int64_t start = SolarDayStartS(data.time_s.front(), offset_s) +
                             static_cast<std::int64_t>(train_days) * kSecondsPerDay;
  const auto first = static_cast<std::size_t>(
      std::lower_bound(data.time_s.begin(), data.time_s.end(), start) - data.time_s.begin());
  const Series heldout = data.Slice(first, data.size());
  Drivers d;
  std::string error;
  if (!PrepareDrivers(heldout, plant, c.truth, &d, &error)) return kNaN;
  const Measurements m = MakeMeasurements(heldout, d);
  SimOutputs out;
  Simulate(d, c.truth_params, &out);
  return ComputeErrors(m, out, plant.area_m2).objective_w_m2();
}

}  // namespace

std::vector<SelftestCase> SelftestCases(const Plant& plant) {
  std::vector<SelftestCase> cases;
  const ParamVector truth = ReferenceTruthParams(plant);
  // Bases to withhold an effect from, in order of preference.
  const std::vector<std::string> bases = {"1N1Cwr", "1Nwr", "1N1Cr", "1N1Cw"};
  // Data with every channel, to ask which effects can be added.
  WeatherOptions probe_options;
  probe_options.num_days = 1;
  probe_options.step_s = 3600.0;
  const Series probe = GenerateWeather(plant, probe_options);
  for (const std::string& effect : EffectNames()) {
    for (const std::string& base_name : bases) {
      const ModelSpec base = Parse(base_name);
      std::vector<EffectCandidate> candidates = CandidateEffects(base, probe, nullptr);
      const auto it =
          std::find_if(candidates.begin(), candidates.end(),
                       [&effect](const EffectCandidate& c) { return c.name == effect; });
      if (it == candidates.end()) continue;
      cases.push_back({effect, effect, base, it->spec, truth, Disturbance::kNone});
      break;
    }
  }
  const ModelSpec plain = Parse("1N1Cwr");
  cases.push_back({"null", "none", plain, plain, truth, Disturbance::kNone});
  cases.push_back({"failing_pump", "unknown", plain, plain, truth, Disturbance::kFailingPump});
  cases.push_back({"snow_cover", "unknown", plain, plain, truth, Disturbance::kSnowCover});
  return cases;
}

Series SelftestData(const Plant& plant, const SelftestCase& c, std::uint64_t seed,
                    const SelftestOptions& options, std::vector<std::int64_t>* disturbed_days) {
  WeatherOptions weather;
  weather.num_days = options.train_days + options.heldout_days;
  weather.step_s = options.step_s;
  weather.seed = seed;
  // Start at local solar midnight so that the data are whole solar days.
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  weather.start_time_s = SolarDayStartS(weather.start_time_s, offset_s) + kSecondsPerDay;
  Series s = MakeSyntheticPlantData(plant, weather, c.truth, c.truth_params,
                                    RealisticSensorNoise(seed * 7919 + 17));
  std::mt19937_64 rng(seed * 104729 + 3);

  // An uncatalogued disturbance on two held-out days: the truth model runs
  // on altered inputs; the measured inputs stay as logged, and the noise of
  // the undisturbed data is kept.
  if (c.disturbance != Disturbance::kNone) {
    std::vector<std::int64_t> days;
    const std::int64_t first = SolarDayStartS(s.time_s.front(), offset_s);
    for (int k : {1, 4}) {
      if (k < options.heldout_days) {
        days.push_back(first + static_cast<std::int64_t>(options.train_days + k) * kSecondsPerDay);
      }
    }
    if (disturbed_days != nullptr) *disturbed_days = days;
    Series altered = s;
    auto disturbed = [&](std::size_t i) {
      const std::int64_t d = SolarDayStartS(s.time_s[i], offset_s);
      return std::find(days.begin(), days.end(), d) != days.end();
    };
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (!disturbed(i)) continue;
      if (c.disturbance == Disturbance::kFailingPump) {
        // The pump delivers a quarter of the flow the meter reports.
        altered[Channel::kMdotKgS][i] *= 0.25;
      } else {
        // Snow-like cover: 5 % of the light reaches the cells.
        for (Channel ch :
             {Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaDiffuseWM2}) {
          if (altered.Has(ch)) altered[ch][i] *= 0.05;
        }
      }
    }
    const SimOutputs normal = SimulateOrAbort(s, plant, c.truth, c.truth_params);
    const SimOutputs changed = SimulateOrAbort(altered, plant, c.truth, c.truth_params);
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (!disturbed(i)) continue;
      s[Channel::kPElW][i] += changed.p_el_w[i] - normal.p_el_w[i];
      s[Channel::kQThW][i] += changed.q_th_w[i] - normal.q_th_w[i];
      s[Channel::kTOutC][i] += changed.t_out_c[i] - normal.t_out_c[i];
    }
  }

  // The paper's data defects and gaps.
  const std::size_t n = s.size();
  std::vector<double>& g = s[Channel::kGPoaWM2];
  std::vector<double>& flow = s[Channel::kMdotKgS];
  std::vector<double>& valid = s.Ensure(Channel::kValid);
  for (std::size_t i = 0; i < n; ++i) {
    const double u = static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
    if (g[i] == 0.0 && u < 0.002) g[i] = 6553.5;            // night glitch
    if (flow[i] == 0.0 && u > 0.9) flow[i] = -2e-4;         // meter at standstill
    if (u > 0.3 && u < 0.305) s[Channel::kPElW][i] = kNaN;  // dropped reading
    if (u > 0.5 && u < 0.503) valid[i] = 0.0;               // flagged by the logger
  }
  ApplyPaperCorrections(&s);
  s.step_s = options.step_s;
  return s;
}

SelftestOutcome RunSelftestCase(const Plant& plant, const SelftestCase& c, std::uint64_t seed,
                                const SelftestOptions& options,
                                const std::function<void(const std::string&)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  SelftestOutcome o;
  o.case_name = c.name;
  o.seed = seed;
  o.expected = c.expected;
  std::vector<std::int64_t> disturbed_days;
  const Series data = SelftestData(plant, c, seed, options, &disturbed_days);
  DiagnosisOptions dopt = options.diagnosis;
  dopt.train_days = options.train_days;
  dopt.heldout_days = options.heldout_days;
  dopt.step_s = 0.0;
  std::string error;
  if (!Diagnose(data, plant, c.base, dopt, &o.result, &error, progress)) {
    o.verdict = "error";
    o.why = error;
    return o;
  }
  const DiagnosisResult& r = o.result;
  o.verdict = r.verdict;
  o.first_step = r.ladder.size() > 1 ? r.ladder[1].added : "";
  o.heldout_before_w_m2 = r.ladder.front().objective_w_m2;
  o.heldout_after_w_m2 = r.ladder.back().objective_w_m2;
  o.heldout_truth_w_m2 = TruthHeldoutObjective(data, plant, c, options.train_days);
  for (const EffectTrial& t : r.effects) {
    if (c.expected == "none" && t.significant) o.false_significant = true;
  }
  std::ostringstream why;
  if (o.verdict != c.expected)
    why << "verdict " << o.verdict << ", expected " << c.expected << "; ";
  if (c.expected != "none" && c.expected != "unknown") {
    if (o.first_step != c.expected) why << "first ladder step '" << o.first_step << "'; ";
    // After the ladder, the held-out error is near the truth model's.
    if (!(o.heldout_after_w_m2 <= (1.0 + options.after_tolerance) * o.heldout_truth_w_m2)) {
      why << "held-out after " << Fixed(o.heldout_after_w_m2, 3) << " W/m² > (1 + "
          << options.after_tolerance << ") × truth " << Fixed(o.heldout_truth_w_m2, 3) << "; ";
    }
  }
  if (c.expected == "unknown") {
    const GapRegion* day_region = nullptr;
    for (const GapRegion& w : r.where) {
      if (w.driver == "day") {
        day_region = &w;
        break;
      }
    }
    bool hit = false;
    if (day_region != nullptr) {
      for (std::int64_t d : disturbed_days) {
        hit = hit || (static_cast<double>(d) >= day_region->lower &&
                      static_cast<double>(d) < day_region->upper);
      }
    }
    if (!hit) why << "where does not point at a disturbed day first; ";
  }
  o.why = why.str();
  o.correct = o.why.empty();
  o.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return o;
}

std::string FormatSelftestReport(const std::vector<SelftestOutcome>& outcomes) {
  std::ostringstream out;
  out << "case              seed  verdict            1st step           before  after  truth "
         " W/m²   s    ok\n";
  for (const SelftestOutcome& o : outcomes) {
    char line[256];
    std::snprintf(line, sizeof line, "%-17s %4llu  %-18s %-18s %6.3f %6.3f %6.3f %6.1f  %s",
                  o.case_name.c_str(), static_cast<unsigned long long>(o.seed), o.verdict.c_str(),
                  o.first_step.empty() ? "-" : o.first_step.c_str(), o.heldout_before_w_m2,
                  o.heldout_after_w_m2, o.heldout_truth_w_m2, o.wall_time_s,
                  o.correct ? "yes" : "NO");
    out << line;
    if (!o.correct) out << "  (" << o.why << ")";
    out << "\n";
  }
  // Confusion table: rows expected, columns verdict.
  std::vector<std::string> labels;
  for (const SelftestOutcome& o : outcomes) {
    for (const std::string& l : {o.expected, o.verdict}) {
      if (std::find(labels.begin(), labels.end(), l) == labels.end()) labels.push_back(l);
    }
  }
  std::map<std::pair<std::string, std::string>, int> counts;
  for (const SelftestOutcome& o : outcomes) ++counts[{o.expected, o.verdict}];
  out << "\nconfusion (rows: expected, columns: verdict)\n" << std::string(17, ' ');
  for (const std::string& l : labels) {
    char cell[32];
    std::snprintf(cell, sizeof cell, " %6.6s", l.c_str());
    out << cell;
  }
  out << "\n";
  for (const std::string& e : labels) {
    bool any = false;
    for (const SelftestOutcome& o : outcomes) any = any || o.expected == e;
    if (!any) continue;
    char head[32];
    std::snprintf(head, sizeof head, "%-17s", e.c_str());
    out << head;
    for (const std::string& v : labels) {
      const auto it = counts.find({e, v});
      char cell[32];
      std::snprintf(cell, sizeof cell, " %6d", it == counts.end() ? 0 : it->second);
      out << cell;
    }
    out << "\n";
  }
  int correct = 0, false_significant = 0, null_cases = 0;
  for (const SelftestOutcome& o : outcomes) {
    correct += o.correct;
    false_significant += o.false_significant;
    null_cases += o.expected == "none";
  }
  out << "\nhit rate: " << correct << " / " << outcomes.size() << " = "
      << Fixed(outcomes.empty() ? 0.0 : 100.0 * correct / static_cast<double>(outcomes.size()), 1)
      << " %; false significant effects on null cases: " << false_significant << " of "
      << null_cases << "\n";
  return out.str();
}

}  // namespace pvtwin
