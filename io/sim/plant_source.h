// The plant behind `pvtwin sim`: what its sensors read at any simulated time,
// either generated (weather and operation from core/weather_generator.h run
// through a truth model variant with known parameters and realistic sensor
// noise, core/synthetic_plant.h) or replayed from a canonical CSV.
//
// Generated data comes in UTC-day chunks at 5 s: chunk d covers
// [d·86400, (d+1)·86400) and is generated with seed Mix(seed, d), so any time
// can be served without generating the days before it, and the served values,
// `sim --export` and a test that builds the same source all agree bit for bit.
// The model states and the weather's slow processes restart at 00:00 UTC
// (night in Europe: the pump is off, little changes). That is the
// irradiance-threshold operation (PumpControl::kIrradiance), kept as it was
// because recorded tests and the diagnosis self-test rely on its data.
//
// The thermostat operations (kDifferential, kHeatPumpSource) are one
// continuous run instead: from run_start_s on, weather, tank or brine, pump
// and the truth model's nodes carry across midnight. The run is generated in
// one piece up to one day past the latest time asked for and regenerated
// longer when a later time is asked for (GenerateWeather reproduces a shorter
// run's rows bit for bit, so served values never change); times before
// run_start_s have no data (all NaN). A month at 5 s is ~0.5 M rows, a few
// seconds to generate and ~100 MB held.
//
// Timestamp convention: a row holds instantaneous sensor values at its start
// time; At(t) answers the row whose 5 s interval contains t.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/diagnostic.h"
#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/sample.h"
#include "core/common/series.h"
#include "core/model/variant.h"
#include "core/synth/weather_generator.h"

namespace pvtwin {

// The richest truth model the variant parser accepts: two nodes, both
// capacitances, sky radiation, IAM, the physical wind form, transport delay
// (ReferenceTruthParams). Effects added to it act at their modules' typical
// magnitudes (EffectModule::typical_truth).
inline constexpr const char* kDefaultTruthVariant = "2N2CrI+wind+transport_delay";

inline constexpr double kPlantSourceStepS = 5.0;

struct PlantSourceOptions {
  Plant plant;
  std::string truth_variant = kDefaultTruthVariant;  // any name ParseVariant accepts
  std::uint64_t seed = 1;                            // weather, operation and noise
  std::string replay_csv;                            // non-empty: replay this canonical CSV
  std::vector<DayType> day_types;  // sky of every day, cycled; empty: drawn (weather_generator.h)
  // Operation of the solar loop (weather_generator.h) and its thermostat
  // settings; anything but kIrradiance makes the plant one continuous run.
  PumpControl pump_control = PumpControl::kIrradiance;
  double pump_dt_on_k = 5.0;
  double pump_dt_off_k = 2.0;
  double brine_below_ambient_k = 5.0;
  double brine_min_c = 0.0;
  double brine_max_c = 10.0;
  std::int64_t run_start_s = 0;  // start of the continuous run, unix s UTC

  bool Continuous() const { return pump_control != PumpControl::kIrradiance; }
};

// The day type spelled as DayTypeName spells it ("clear", "broken_clouds",
// "overcast"); nullopt for any other text.
std::optional<DayType> DayTypeFromName(std::string_view name);

class PlantSource {
 public:
  // Parses the variant, loads the replay file. Problems go to *errors.
  static std::unique_ptr<PlantSource> Create(const PlantSourceOptions& options,
                                             Diagnostics* errors);

  // Every channel at simulated time t_s (ts_s = start of the row containing
  // t_s; all NaN outside a replayed file). Thread-safe.
  Sample At(double t_s);

  // Rows [start_s, start_s + days·86400) at 5 s (generated) or the replayed
  // rows in that span.
  Series History(std::int64_t start_s, int days);

 private:
  explicit PlantSource(const PlantSourceOptions& options) : options_(options) {}
  const Series& Chunk(std::int64_t day);  // generated UTC day; caller holds mutex_
  // The continuous run, covering at least [run_start_s, until_s); caller
  // holds mutex_.
  const Series& Run(std::int64_t until_s);
  WeatherOptions Weather(std::int64_t start_s, int days, std::uint64_t seed) const;

  PlantSourceOptions options_;
  ModelSpec spec_;
  ParamVector truth_;
  Series replay_;
  std::mutex mutex_;
  std::map<std::int64_t, Series> chunks_;  // a few recent days
  Series run_;                             // the continuous run
};

}  // namespace pvtwin
