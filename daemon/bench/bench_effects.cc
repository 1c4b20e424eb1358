// pvtwin-bench effects: the cost and the payoff of each effect of the
// library on synthetic data with a known answer. For every effect: 21 days
// at 1 min of a truth = base + effect (TruthParamsFor, realistic noise, the
// paper's data defects corrected as the import does), the first 14 days
// train, the last 7 are held out (the diagnosis's protocol of issue 6).
// Printed per effect: the median identification runtime of base + effect
// (one core), its simulations, the held-out MAE (P_el + Q_u per m², the
// paper's objective) of the true parameters, of base + effect and of the
// base alone, and the effect's first parameter against its truth.
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "core/data/qc.h"
#include "core/effects/effects.h"
#include "core/fit/identification.h"
#include "core/synth/synthetic_plant.h"
#include "daemon/bench/bench.h"

namespace pvtwin::cli {

namespace {

constexpr int kTrainDays = 14;
constexpr int kHeldOutDays = 7;

// The base model each effect is added to: 1N1Cwr, or for an effect that
// 1N1Cwr has (a letter of the paper's), 1N1Cwr without that letter.
ModelSpec BaseFor(const EffectModule& e) {
  for (const char* variant : {"1N1Cwr", "1Nwr", "1N1Cr", "1N1Cw"}) {
    ModelSpec spec;
    std::string error;
    ParseVariant(variant, &spec, &error);
    if (!HasEffect(spec, e)) return spec;
  }
  return {};
}

struct Scored {
  double heldout_w_m2 = 0.0;
  double runtime_s = 0.0;
  int evaluations = 0;
  ParamVector params{};
  double irradiance_bias = 0.0;  // Drivers::irradiance_bias of the whole series
};

// Identifies spec on the training rows (or takes *fixed) and scores it on
// the held-out rows. Drivers span the whole series so that time-dependent
// drivers (soiling's days since cleaning) continue into the held-out days.
Scored FitAndScore(const Series& data, std::size_t split, const Plant& plant, const ModelSpec& spec,
                   int repeats, const ParamVector* fixed) {
  Scored s;
  std::string error;
  Drivers train_d, all_d;
  const Series train = data.Slice(0, split);
  if (!PrepareDrivers(train, plant, spec, &train_d, &error) ||
      !PrepareDrivers(data, plant, spec, &all_d, &error)) {
    std::printf("  %s: %s\n", spec.Name().c_str(), error.c_str());
    return s;
  }
  s.irradiance_bias = all_d.irradiance_bias;
  if (fixed != nullptr) {
    s.params = *fixed;
  } else {
    const Measurements meas = MakeMeasurements(train, train_d);
    std::vector<double> times;
    for (int r = 0; r < repeats; ++r) {
      const auto start = std::chrono::steady_clock::now();
      const IdentSummary fit = Identify(train_d, meas, StartParams(plant), IdentOptions{});
      times.push_back(SecondsSince(start));
      s.params = fit.params;
      s.evaluations = fit.evaluations;
    }
    s.runtime_s = Median(times);
  }
  Measurements held = MakeMeasurements(data, all_d);
  std::vector<std::uint32_t> rows;
  for (std::uint32_t r : held.rows) {
    if (r >= split) rows.push_back(r);
  }
  held.rows = rows;
  SimOutputs out;
  Simulate(all_d, s.params, &out);
  s.heldout_w_m2 = ComputeErrors(held, out, plant.area_m2).objective_w_m2();
  return s;
}

}  // namespace

void BenchEffects(int repeats, std::uint64_t seed) {
  const Plant plant = DesignExamplePlant();
  std::printf(
      "effects: truth = base + effect at its typical magnitude, %d + %d days at 1 min, seed "
      "%llu,\n  realistic noise and data defects; identification from StartParams, median of %d "
      "runs\n",
      kTrainDays, kHeldOutDays, static_cast<unsigned long long>(seed), repeats);
  std::printf("  %-17s %-26s %8s %6s %28s  %s\n", "effect", "truth", "fit (s)", "sims",
              "held-out MAE W/m2 truth/with/base", "parameter: fit (truth)");
  double total_s = 0.0;
  for (const EffectModule* effect : EffectRegistry()) {
    const EffectModule& info = *effect;
    const ModelSpec base = BaseFor(info);
    const ModelSpec with = WithEffect(base, info);
    SyntheticOptions options;
    std::string error;
    if (!DefaultSyntheticOptions(plant, with.Name(), kTrainDays + kHeldOutDays, seed, &options,
                                 &error)) {
      std::printf("  %s: %s\n", std::string(info.name).c_str(), error.c_str());
      continue;
    }
    Series data = MakeSyntheticPlantData(plant, options);
    ApplyPaperCorrections(&data);
    std::size_t split = 0;
    while (split < data.size() && data.time_s[split] < data.time_s[0] + kTrainDays * 86400) {
      ++split;
    }
    const Scored truth = FitAndScore(data, split, plant, with, repeats, &options.truth);
    const Scored fit = FitAndScore(data, split, plant, with, repeats, nullptr);
    const Scored without = FitAndScore(data, split, plant, base, 1, nullptr);
    total_s += fit.runtime_s;
    // The parameter to compare: the module's compared_param (the first of
    // its parameters unless it names one), except for an effect that the
    // drivers estimate (irradiance_bias, from GHI/DHI).
    std::string param = "-";
    if (!info.params.empty()) {
      const Param p = info.compared_param.value_or(info.params.front());
      const double value = info.sensor_estimate != nullptr
                               ? fit.irradiance_bias
                               : fit.params[static_cast<std::size_t>(p)];
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s %.4g (%.4g)", std::string(Info(p).name).c_str(), value,
                    options.truth[static_cast<std::size_t>(p)]);
      param = buf;
    }
    std::printf("  %-17s %-26s %8.2f %6d %10.3f %8.3f %8.3f  %s\n", std::string(info.name).c_str(),
                with.Name().c_str(), fit.runtime_s, fit.evaluations, truth.heldout_w_m2,
                fit.heldout_w_m2, without.heldout_w_m2, param.c_str());
  }
  std::printf("  sum of the base + effect fits: %.2f s\n", total_s);
}

}  // namespace pvtwin::cli
