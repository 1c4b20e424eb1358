// pvtwin-bench table6: the protocol of the paper's Table 6 on synthetic data
// with a known answer: 14 + 29 days at 1 min of a 2N1Ccolwr "truth" with
// realistic sensor noise, the nine variants identified on the 14 days before
// each of the 29 test days, on every core. Prints the wall time and the table,
// first with every identification from Table 3, then with warm starts.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <thread>

#include "core/forecast/backtest.h"
#include "core/synth/synthetic_plant.h"
#include "daemon/bench/bench.h"

namespace pvtwin::cli {
namespace {

// Where each variant's identification time goes, summed over its days: the
// coarse stage, of it the fits on a day subset; the fine stage, of it the
// identifiability analysis (the standard errors and the rounds that decide
// which undetermined parameters to fix), and of that the rounds' trial fits.
void PrintTimeSplit(const BacktestResult& result) {
  std::printf(
      "time split per variant, s summed over the days: coarse (of it day subset) + fine (of it "
      "identifiability: standard errors and fixing rounds; of that trial fits) = "
      "identification\n");
  struct Split {
    double coarse = 0.0, subset = 0.0, fixing = 0.0, trials = 0.0, total = 0.0;
    void Add(const Split& o) {
      coarse += o.coarse;
      subset += o.subset;
      fixing += o.fixing;
      trials += o.trials;
      total += o.total;
    }
    void Print(const char* name) const {
      std::printf("  %-12s %6.2f (%6.2f) + %6.2f (%6.2f; %6.2f) = %6.2f\n", name, coarse, subset,
                  total - coarse, fixing, trials, total);
    }
  };
  Split all;
  for (const BacktestAverage& a : result.averages) {
    Split v;
    for (const BacktestDay& d : result.days) {
      if (d.variant != a.variant || d.train_days != a.train_days) continue;
      v.Add({d.coarse_runtime_s, d.coarse_subset_runtime_s, d.fixing_runtime_s, d.trial_runtime_s,
             d.runtime_s});
    }
    v.Print(a.variant.c_str());
    all.Add(v);
  }
  all.Print("all");
}

}  // namespace

void BenchTable6(std::uint64_t seed) {
  const Plant plant = DesignExamplePlant();
  WeatherOptions weather;
  weather.num_days = 14 + 29;
  weather.step_s = 60.0;
  weather.seed = seed;
  ModelSpec truth_spec;
  std::string error;
  ParseVariant("2N1Ccolwr", &truth_spec, &error);
  const auto generate_start = std::chrono::steady_clock::now();
  const Series data = MakeSyntheticPlantData(
      plant, weather, truth_spec, ReferenceTruthParams(plant), RealisticSensorNoise(seed));
  const double generate_s = SecondsSince(generate_start);

  BacktestOptions options;
  options.variants = PaperVariants();
  options.train_days = {14};
  options.step_s = 60.0;
  options.test_days = 29;
  options.threads = 0;  // every core
  const unsigned cores = std::thread::hardware_concurrency();
  std::printf(
      "table6: %d days of synthetic 1-min data (truth 2N1Ccolwr, realistic sensor noise, seed "
      "%llu, generated in %.1f s); 9 variants x 29 test days, 14-day windows, %u thread(s)\n",
      weather.num_days, static_cast<unsigned long long>(seed), generate_s, cores);
  std::fflush(stdout);
  BacktestResult result;
  if (!RunBacktest(data, plant, options, &result, &error)) {
    std::printf("table6: %s\n", error.c_str());
    return;
  }
  std::printf("table6: wall time %.1f s for %zu identifications\n%s", result.wall_time_s,
              result.days.size(), FormatBacktestTables(result).c_str());
  PrintTimeSplit(result);

  // The same protocol as the daemon re-identifies nightly: each day starts
  // from the day before's parameters (`pvtwin backtest --warm-start`).
  std::fflush(stdout);
  options.warm_start = true;
  BacktestResult warm;
  if (!RunBacktest(data, plant, options, &warm, &error)) {
    std::printf("table6 with warm starts: %s\n", error.c_str());
    return;
  }
  std::printf(
      "\ntable6 with warm starts: wall time %.1f s for %zu identifications (%.2f of the "
      "cold starts' time)\n%s",
      warm.wall_time_s, warm.days.size(), warm.wall_time_s / result.wall_time_s,
      FormatBacktestTables(warm).c_str());
  PrintTimeSplit(warm);
  std::printf("mean MAE per variant, W/m2, P_el and Q_u: from Table 3 -> with warm starts\n");
  for (std::size_t a = 0; a < result.averages.size() && a < warm.averages.size(); ++a) {
    const BacktestAverage& c = result.averages[a];
    const BacktestAverage& w = warm.averages[a];
    std::printf("  %-12s %6.3f -> %6.3f   %6.3f -> %6.3f   (%d and %d days ok)\n",
                c.variant.c_str(), c.mae_p_el_w_m2, w.mae_p_el_w_m2, c.mae_q_th_w_m2,
                w.mae_q_th_w_m2, c.days_ok, w.days_ok);
  }
}

}  // namespace pvtwin::cli
