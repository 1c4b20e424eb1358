#include "io/sim/plant_source.h"

#include <algorithm>
#include <cmath>

#include "core/effects/effects.h"
#include "core/effects/registry.h"
#include "core/synth/synthetic_plant.h"
#include "io/files/csv.h"

namespace pvtwin {

namespace {

constexpr std::int64_t kDayS = 86400;
constexpr std::size_t kCachedChunks = 3;

// SplitMix64 finaliser: decorrelated per-day seeds from one user seed.
std::uint64_t Mix(std::uint64_t seed, std::int64_t day) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (static_cast<std::uint64_t>(day) + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

std::int64_t FloorDiv(std::int64_t a, std::int64_t b) {
  return a / b - ((a % b != 0) && ((a < 0) != (b < 0)));
}

Sample RowOf(const Series& s, std::size_t i) {
  Sample sample;
  sample.ts_s = s.time_s[i];
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    if (!s.columns[c].empty()) sample.value[c] = s.columns[c][i];
  }
  return sample;
}

// ReferenceTruthParams, with every effect that `spec` adds beyond the
// default truth at its module's typical magnitude (EffectModule::
// typical_truth): `--truth-variant …+pv_clipping` clips. The default truth's
// own parts keep the reference values that recorded data relies on.
ParamVector SimulatorTruthParams(const Plant& plant, const ModelSpec& spec) {
  ParamVector p = ReferenceTruthParams(plant);
  ModelSpec reference;
  std::string why;
  ParseVariant(kDefaultTruthVariant, &reference, &why);
  for (const EffectModule* m : EffectRegistry()) {
    if (!HasEffect(spec, *m) || HasEffect(reference, *m)) continue;
    for (const auto& [param, value] : m->typical_truth) p[static_cast<std::size_t>(param)] = value;
  }
  return p;
}

}  // namespace

std::optional<DayType> DayTypeFromName(std::string_view name) {
  for (const DayType type : {DayType::kClear, DayType::kBrokenClouds, DayType::kOvercast}) {
    if (DayTypeName(type) == name) return type;
  }
  return std::nullopt;
}

std::unique_ptr<PlantSource> PlantSource::Create(const PlantSourceOptions& options,
                                                 Diagnostics* errors) {
  std::unique_ptr<PlantSource> source(new PlantSource(options));
  std::string why;
  if (!ParseVariant(options.truth_variant, &source->spec_, &why)) {
    errors->push_back({"", 0, "--truth-variant", options.truth_variant, why});
    return nullptr;
  }
  source->truth_ = SimulatorTruthParams(options.plant, source->spec_);
  if (!options.replay_csv.empty()) {
    CsvReadOptions csv;
    csv.fluid_density_kg_m3 = options.plant.fluid_density_kg_m3;
    csv.area_m2 = options.plant.area_m2;
    if (!ReadCanonicalCsv(options.replay_csv, csv, &source->replay_, errors, nullptr)) {
      return nullptr;
    }
  }
  return source;
}

const Series& PlantSource::Chunk(std::int64_t day) {
  const auto found = chunks_.find(day);
  if (found != chunks_.end()) return found->second;
  if (chunks_.size() >= kCachedChunks) {
    // Drop the day farthest from the one asked for.
    auto farthest = std::max_element(chunks_.begin(), chunks_.end(), [day](auto& a, auto& b) {
      return std::llabs(a.first - day) < std::llabs(b.first - day);
    });
    chunks_.erase(farthest);
  }
  Series s =
      MakeSyntheticPlantData(options_.plant, Weather(day * kDayS, 1, Mix(options_.seed, day)),
                             spec_, truth_, RealisticSensorNoise(Mix(options_.seed ^ 0x5EED, day)));
  return chunks_.emplace(day, std::move(s)).first->second;
}

WeatherOptions PlantSource::Weather(std::int64_t start_s, int days, std::uint64_t seed) const {
  WeatherOptions weather;
  weather.start_time_s = start_s;
  weather.num_days = days;
  weather.step_s = kPlantSourceStepS;
  weather.seed = seed;
  weather.flow_mode = FlowMode::kVariable;
  weather.day_types = options_.day_types;
  weather.pump_control = options_.pump_control;
  weather.pump_dt_on_k = options_.pump_dt_on_k;
  weather.pump_dt_off_k = options_.pump_dt_off_k;
  weather.brine_below_ambient_k = options_.brine_below_ambient_k;
  weather.brine_min_c = options_.brine_min_c;
  weather.brine_max_c = options_.brine_max_c;
  return weather;
}

const Series& PlantSource::Run(std::int64_t until_s) {
  const std::int64_t start_s = options_.run_start_s;
  if (!run_.time_s.empty() && until_s <= run_.time_s.back()) return run_;
  const auto days =
      static_cast<int>(FloorDiv(std::max(until_s - start_s, std::int64_t{0}), kDayS) + 1);
  run_ = MakeSyntheticPlantData(options_.plant, Weather(start_s, days, options_.seed), spec_,
                                truth_, RealisticSensorNoise(Mix(options_.seed ^ 0x5EED, 0)));
  return run_;
}

Sample PlantSource::At(double t_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!options_.replay_csv.empty()) {
    const auto& times = replay_.time_s;
    const auto after = std::upper_bound(times.begin(), times.end(), std::floor(t_s),
                                        [](double t, std::int64_t row) { return t < row; });
    if (after == times.begin()) return Sample{};
    const std::size_t i = static_cast<std::size_t>(after - times.begin()) - 1;
    const double step_s = replay_.step_s > 0 ? replay_.step_s : kPlantSourceStepS;
    if (t_s >= static_cast<double>(times[i]) + step_s) return Sample{};
    return RowOf(replay_, i);
  }
  const auto t = static_cast<std::int64_t>(std::floor(t_s));
  if (options_.Continuous()) {
    if (t < options_.run_start_s) return Sample{};
    const Series& run = Run(t);
    return RowOf(run, static_cast<std::size_t>((t - options_.run_start_s) /
                                               static_cast<std::int64_t>(kPlantSourceStepS)));
  }
  const std::int64_t day = FloorDiv(t, kDayS);
  const Series& chunk = Chunk(day);
  const auto row =
      static_cast<std::size_t>((t - day * kDayS) / static_cast<std::int64_t>(kPlantSourceStepS));
  return RowOf(chunk, std::min(row, chunk.size() - 1));
}

Series PlantSource::History(std::int64_t start_s, int days) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::int64_t end_s = start_s + days * kDayS;
  if (!options_.replay_csv.empty()) {
    const auto& times = replay_.time_s;
    const auto begin = std::lower_bound(times.begin(), times.end(), start_s);
    const auto end = std::lower_bound(times.begin(), times.end(), end_s);
    return replay_.Slice(static_cast<std::size_t>(begin - times.begin()),
                         static_cast<std::size_t>(end - times.begin()));
  }
  if (options_.Continuous()) {
    const Series& run = Run(end_s - 1);
    const auto& times = run.time_s;
    const auto begin = std::lower_bound(times.begin(), times.end(), start_s);
    const auto end = std::lower_bound(times.begin(), times.end(), end_s);
    return run.Slice(static_cast<std::size_t>(begin - times.begin()),
                     static_cast<std::size_t>(end - times.begin()));
  }
  Series out;
  out.step_s = kPlantSourceStepS;
  for (std::int64_t day = FloorDiv(start_s, kDayS); day * kDayS < end_s; ++day) {
    const Series& chunk = Chunk(day);
    for (std::size_t i = 0; i < chunk.size(); ++i) {
      const std::int64_t t = chunk.time_s[i];
      if (t < start_s || t >= end_s) continue;
      out.time_s.push_back(t);
      for (std::size_t c = 0; c < kNumChannels; ++c) {
        if (chunk.columns[c].empty()) continue;
        out.columns[c].resize(out.time_s.size() - 1, std::nan(""));
        out.columns[c].push_back(chunk.columns[c][i]);
      }
    }
  }
  return out;
}

}  // namespace pvtwin
