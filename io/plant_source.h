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
// (night in Europe: the pump is off, little changes).
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

#include "core/diagnostic.h"
#include "core/params.h"
#include "core/plant.h"
#include "core/sample.h"
#include "core/series.h"
#include "core/variant.h"
#include "core/weather_generator.h"

namespace pvtwin {

// The richest truth model the variant parser accepts: two nodes, both
// capacitances, sky radiation, IAM, the physical wind form, transport delay.
inline constexpr const char* kDefaultTruthVariant = "2N2CrI+wind+transport_delay";

inline constexpr double kPlantSourceStepS = 5.0;

struct PlantSourceOptions {
  Plant plant;
  std::string truth_variant = kDefaultTruthVariant;  // any name ParseVariant accepts
  std::uint64_t seed = 1;                            // weather, operation and noise
  std::string replay_csv;                            // non-empty: replay this canonical CSV
  std::vector<DayType> day_types;  // sky of every day, cycled; empty: drawn (weather_generator.h)
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

  PlantSourceOptions options_;
  ModelSpec spec_;
  ParamVector truth_;
  Series replay_;
  std::mutex mutex_;
  std::map<std::int64_t, Series> chunks_;  // a few recent days
};

}  // namespace pvtwin
