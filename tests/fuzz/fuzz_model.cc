// libFuzzer harness for the model's path from data to outputs: a canonical
// CSV (as the reader accepts it, physical limits applied) → PrepareDrivers →
// Simulate, for a variant chosen by the first byte among the paper's nine
// and each effect of the library. It must never crash; a row whose drivers
// are usable must get finite outputs (a missing input is a missing row,
// never a crash or a NaN elsewhere). Seeds: tests/fuzz/corpus/model/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "core/effects/effects.h"
#include "core/model/thermal_model.h"
#include "core/model/variant.h"
#include "core/synth/synthetic_plant.h"
#include "io/files/csv.h"

namespace {

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

std::vector<pvtwin::ModelSpec> Variants() {
  std::vector<pvtwin::ModelSpec> specs;
  std::string error;
  for (const std::string& name : pvtwin::PaperVariants()) {
    pvtwin::ModelSpec spec;
    if (pvtwin::ParseVariant(name, &spec, &error)) specs.push_back(spec);
  }
  pvtwin::ModelSpec base;
  pvtwin::ParseVariant("2N1CcolwrI", &base, &error);
  for (const pvtwin::EffectModule* e : pvtwin::EffectRegistry()) {
    specs.push_back(pvtwin::WithEffect(base, *e));
  }
  return specs;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::vector<pvtwin::ModelSpec> specs = Variants();
  static const pvtwin::Plant plant = pvtwin::DesignExamplePlant();
  if (size < 1) return 0;
  const pvtwin::ModelSpec& spec = specs[data[0] % specs.size()];
  std::istringstream in(std::string(reinterpret_cast<const char*>(data + 1), size - 1));
  pvtwin::CsvReadOptions options;
  options.area_m2 = plant.area_m2;
  pvtwin::Series series;
  pvtwin::Diagnostics errors;
  if (!pvtwin::ParseCanonicalCsv(in, "fuzz.csv", options, &series, &errors, nullptr)) return 0;
  if (series.size() > 20000) return 0;  // keep one run short
  pvtwin::Drivers drivers;
  std::string error;
  if (!pvtwin::PrepareDrivers(series, plant, spec, &drivers, &error)) {
    Require(!error.empty());
    return 0;
  }
  pvtwin::SimOutputs out;
  pvtwin::Simulate(drivers, pvtwin::TruthParamsFor(plant, spec), &out);
  Require(out.p_el_w.size() == series.size() && out.q_th_w.size() == series.size());
  // transport_delay and clock_offset read neighbouring rows, which may be
  // missing; every other variant gives a usable row finite outputs.
  const bool reads_neighbours = pvtwin::HasEffect(spec, *pvtwin::FindEffect("transport_delay")) ||
                                pvtwin::HasEffect(spec, *pvtwin::FindEffect("clock_offset"));
  for (std::size_t i = 0; i < series.size(); ++i) {
    Require(!std::isinf(out.p_el_w[i]) && !std::isinf(out.q_th_w[i]));
    if (drivers.usable[i] && !reads_neighbours) {
      Require(std::isfinite(out.p_el_w[i]) && std::isfinite(out.q_th_w[i]));
    }
  }
  return 0;
}
