// pvtwin-bench diagnose: wall time of one gap diagnosis over the whole effect
// library, 14 training + 7 held-out days at 1 min, both cores.
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "core/data/qc.h"
#include "core/diagnosis/diagnosis.h"
#include "core/synth/synthetic_plant.h"
#include "daemon/bench/bench.h"

namespace pvtwin::cli {

void BenchDiagnosis(std::uint64_t seed) {
  const Plant plant = DesignExamplePlant();
  // Truth with one effect the base lacks, so the ladder has a step and a
  // second search.
  const std::string truth = "1N1Cwr+pv_clipping";
  SyntheticOptions synth;
  std::string error;
  if (!DefaultSyntheticOptions(plant, truth, 21, seed, &synth, &error)) {
    std::printf("diagnosis: %s\n", error.c_str());
    return;
  }
  Series data = MakeSyntheticPlantData(plant, synth);
  ApplyPaperCorrections(&data);
  ModelSpec base;
  ParseVariant("1N1Cwr", &base, &error);
  DiagnosisOptions options;
  options.train_days = 14;
  options.heldout_days = 7;
  std::printf(
      "diagnosis: base 1N1Cwr on data from %s, 14 training + 7 held-out days at 1 min "
      "(%zu rows), every effect of the library, %u threads, seed %llu\n",
      truth.c_str(), data.size(), std::thread::hardware_concurrency(),
      static_cast<unsigned long long>(seed));
  DiagnosisResult result;
  const auto start = std::chrono::steady_clock::now();
  if (!Diagnose(data, plant, base, options, &result, &error)) {
    std::printf("  FAILED: %s\n", error.c_str());
    return;
  }
  const double wall_s = SecondsSince(start);
  std::printf(
      "  wall time %.1f s (target <= 60 s), %d identifications, ladder %zu steps, "
      "verdict %s\n",
      wall_s, result.identifications, result.ladder.size(), result.verdict.c_str());
}

}  // namespace pvtwin::cli
