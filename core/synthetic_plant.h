// Synthetic operation data of a PVT field: generated weather and operation
// (weather_generator.h) run through a "truth" model variant with known
// parameters, with optional sensor noise. The basis of identification tests
// on data with a known answer, of benchmarks and of the demo.
#pragma once

#include <cstdint>

#include "core/params.h"
#include "core/series.h"
#include "core/variant.h"
#include "core/weather_generator.h"

namespace pvtwin {

// Sensor noise (1 σ, Gaussian, independent per row), as data-sheet classes of
// typical monitoring sensors: a class-A Pt100 pair on the fluid, a power
// meter on the PV, a heat meter on the fluid.
struct SensorNoise {
  double t_out_c = 0.0;   // K
  double p_el_rel = 0.0;  // fraction of the reading
  double q_th_w = 0.0;    // W
  std::uint64_t seed = 1;
};

inline SensorNoise RealisticSensorNoise(std::uint64_t seed) { return {0.05, 0.005, 5.0, seed}; }

// The plant of DESIGN.md's example [plant] section: 47.358° N, 16.128° E,
// 20° tilt facing south, 1.8 m², the paper's fluid and PV reference data.
Plant DesignExamplePlant();

// A plausible uncovered PVT collector, inside Table 3's bounds, used as the
// known answer of synthetic tests.
ParamVector ReferenceTruthParams(const Plant& plant);

// Weather and operation from `weather`, outputs p_el_w, q_th_w, t_out_c and
// t_pv_c from `truth_spec` with `truth`, then noise on p_el_w, q_th_w and
// t_out_c (q_th_w stays consistent with flow and the noisy outlet: the heat
// meter's noise is applied on q_th_w itself).
Series MakeSyntheticPlantData(const Plant& plant, const WeatherOptions& weather,
                              const ModelSpec& truth_spec, const ParamVector& truth,
                              const SensorNoise& noise);

}  // namespace pvtwin
