#include "core/synthetic_plant.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <random>

#include "core/thermal_model.h"
#include "core/units.h"

namespace pvtwin {

namespace {

// Standard normal deviate (Box–Muller), independent of the standard
// library's distribution implementations.
double Normal(std::mt19937_64& rng) {
  constexpr double kScale = 1.0 / 18446744073709551616.0;  // 2^-64
  const double u1 = (static_cast<double>(rng()) + 0.5) * kScale;
  const double u2 = (static_cast<double>(rng()) + 0.5) * kScale;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
}

}  // namespace

Plant DesignExamplePlant() {
  Plant plant;  // fluid and PV defaults are the example's values
  plant.latitude_rad = DegToRad(47.358);
  plant.longitude_rad = DegToRad(16.128);
  plant.tilt_rad = DegToRad(20.0);
  plant.azimuth_rad = DegToRad(180.0);
  plant.area_m2 = 1.8;
  return plant;
}

ParamVector ReferenceTruthParams(const Plant& plant) {
  ParamVector p = StartParams(plant);
  auto set = [&p](Param name, double v) { p[static_cast<std::size_t>(name)] = v; };
  set(Param::kEtaPvRef, 0.17);
  set(Param::kFTh, 0.92);
  set(Param::kEpsPvt, 0.12);
  set(Param::kUFrontWM2K, 14.0);
  set(Param::kUBackWM2K, 1.5);
  set(Param::kUCollWM2K, 45.0);
  set(Param::kR0FluidM2KW, 0.01);
  set(Param::kR1Fluid, 1.2);
  set(Param::kCPvJM2K, 1.2e4);
  set(Param::kCCollJM2K, 3.5e4);
  set(Param::kRRefWind, 0.02);
  set(Param::kNWind, 0.8);
  set(Param::kUWindWM2K, 3.0);
  set(Param::kTransportDelayS, 45.0);
  return p;
}

Series MakeSyntheticPlantData(const Plant& plant, const WeatherOptions& weather,
                              const ModelSpec& truth_spec, const ParamVector& truth,
                              const SensorNoise& noise) {
  Series s = GenerateWeather(plant, weather);
  Drivers drivers;
  std::string error;
  if (!PrepareDrivers(s, plant, truth_spec, &drivers, &error)) {
    std::cerr << "MakeSyntheticPlantData: " << error << "\n";
    std::abort();  // the generator provides every channel: a bug
  }
  SimOutputs out;
  Simulate(drivers, truth, &out);
  std::mt19937_64 rng(noise.seed);
  const std::size_t n = s.size();
  auto& p_el = s.Ensure(Channel::kPElW);
  auto& q_th = s.Ensure(Channel::kQThW);
  auto& t_out = s.Ensure(Channel::kTOutC);
  auto& t_pv = s.Ensure(Channel::kTPvC);
  for (std::size_t i = 0; i < n; ++i) {
    p_el[i] = out.p_el_w[i] * (1.0 + noise.p_el_rel * Normal(rng));
    // A heat meter reads zero without flow.
    const double q_noise = noise.q_th_w * Normal(rng);
    q_th[i] = out.q_th_w[i] + (drivers.mdot_kg_s[i] > 0.0 ? q_noise : 0.0);
    t_out[i] = out.t_out_c[i] + noise.t_out_c * Normal(rng);
    t_pv[i] = out.t_pv_c[i];
  }
  return s;
}

}  // namespace pvtwin
