#include "core/synth/synthetic_plant.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <random>
#include <utility>

#include "core/common/units.h"
#include "core/effects/effects.h"
#include "core/model/thermal_model.h"

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

ParamVector TruthParamsFor(const Plant& plant, const ModelSpec& spec) {
  ParamVector p = ReferenceTruthParams(plant);
  for (const EffectModule* m : EffectRegistry()) {
    if (!HasEffect(spec, *m)) continue;
    for (const auto& [param, value] : m->typical_truth) {
      p[static_cast<std::size_t>(param)] = value;
    }
  }
  return p;
}

AbsorberSensorParams SensorParamsFromTruth(const ModelSpec& truth_spec, const ParamVector& truth) {
  auto get = [&truth](Param name) { return truth[static_cast<std::size_t>(name)]; };
  AbsorberSensorParams a;
  a.absorbed_fraction = (1.0 - get(Param::kEtaPvRef)) * get(Param::kFTh);
  a.u_front_w_m2k = get(Param::kUFrontWM2K);
  a.u_back_w_m2k = get(Param::kUBackWM2K);
  // The physical wind form's coefficient, when the truth uses it.
  a.u_wind_w_m2k = UsedParams(truth_spec).test(static_cast<std::size_t>(Param::kUWindWM2K))
                       ? get(Param::kUWindWM2K)
                       : 0.0;
  a.n_wind = get(Param::kNWind);
  a.eps_lw = truth_spec.sky ? get(Param::kEpsPvt) : 0.0;
  a.r_internal_m2k_w = truth_spec.nodes == 2 ? 1.0 / get(Param::kUCollWM2K) : 0.0;
  a.r0_fluid_m2k_w = get(Param::kR0FluidM2KW);
  a.r1_fluid = get(Param::kR1Fluid);
  a.c_j_m2k = (truth_spec.c_pv ? get(Param::kCPvJM2K) : 0.0) +
              (truth_spec.c_coll ? get(Param::kCCollJM2K) : 0.0);
  if (a.c_j_m2k <= 0.0) a.c_j_m2k = get(Param::kCCollJM2K);  // a static truth: the sensor's own lag
  return a;
}

std::string_view DisturbanceName(DisturbanceKind kind) {
  switch (kind) {
    case DisturbanceKind::kFailingPump:
      return "failing_pump";
    case DisturbanceKind::kStuckFlowReading:
      return "stuck_flow_reading";
    case DisturbanceKind::kSnowCover:
      return "snow_cover";
    case DisturbanceKind::kInletSensorOffset:
      return "inlet_sensor_offset";
    case DisturbanceKind::kOutletSensorOffset:
      return "outlet_sensor_offset";
    case DisturbanceKind::kFlowMeterScale:
      return "flow_meter_scale";
  }
  return "?";
}

bool DefaultSyntheticOptions(const Plant& plant, std::string_view truth_variant, int days,
                             std::uint64_t seed, SyntheticOptions* options, std::string* error) {
  SyntheticOptions o;
  if (!ParseVariant(truth_variant, &o.truth_spec, error)) return false;
  o.weather.num_days = days;
  o.weather.step_s = 60.0;
  o.weather.seed = seed;
  o.weather.flow_mode = FlowMode::kVariable;
  o.truth = TruthParamsFor(plant, o.truth_spec);
  o.noise = RealisticSensorNoise(seed + 1000);
  o.defects = PaperDataDefects(seed + 2000);
  *options = o;
  return true;
}

namespace {

bool InWindow(const Disturbance& d, std::int64_t t_s) { return t_s >= d.start_s && t_s < d.end_s; }

// Applies the data defects in place (own random stream: the outputs' noise
// does not depend on them).
void InjectDefects(const DataDefects& defects, Series* s) {
  std::mt19937_64 rng(defects.seed);
  const std::size_t n = s->size();
  if (n == 0) return;
  auto uniform = [&rng](double a, double b) {
    return a + (b - a) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
  };
  auto row = [&rng, n]() { return static_cast<std::size_t>(rng() % n); };
  auto& g_poa = (*s)[Channel::kGPoaWM2];
  for (int k = 0, tries = 0; k < defects.irradiance_glitches && tries < 10000; ++tries) {
    const std::size_t i = row();
    if (g_poa[i] != 0.0) continue;  // only at night, as in the paper
    g_poa[i] = uniform(5001.0, 9999.0);
    ++k;
  }
  if (defects.negative_flow_at_rest) {
    auto& flow = (*s)[Channel::kMdotKgS];
    for (double& f : flow) {
      if (f == 0.0) f = -uniform(0.0, 0.8e-3);
    }
  }
  auto block = [&](std::size_t len, auto&& apply) {
    const std::size_t i0 = row();
    for (std::size_t i = i0; i < std::min(n, i0 + len); ++i) apply(i);
  };
  auto& valid = s->Ensure(Channel::kValid);
  for (int k = 0; k < defects.invalid_blocks; ++k) {
    block(30, [&valid](std::size_t i) { valid[i] = 0.0; });
  }
  const double nan = std::nan("");
  for (int k = 0; k < defects.dropout_blocks; ++k) {
    block(10, [s, nan](std::size_t i) {
      (*s)[Channel::kTOutC][i] = nan;
      (*s)[Channel::kQThW][i] = nan;
    });
  }
}

}  // namespace

std::string_view TruthFormName(TruthForm form) {
  return form == TruthForm::kOtherForm ? "other-form" : "same-form";
}

bool UsesOtherForm(const SyntheticOptions& options, const EffectModule& effect) {
  const std::vector<const EffectModule*>& listed = options.other_form_effects;
  return options.truth_form == TruthForm::kOtherForm && effect.other_truth != nullptr &&
         std::find(listed.begin(), listed.end(), &effect) != listed.end() &&
         HasEffect(options.truth_spec, effect);
}

namespace {

// The plant's physics: the real flow and irradiance under disturbances.
Series DisturbedPhysics(const Series& s, const SyntheticOptions& options) {
  Series physics = s;
  const std::size_t n = s.size();
  for (const Disturbance& d : options.disturbances) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!InWindow(d, s.time_s[i])) continue;
      switch (d.kind) {
        case DisturbanceKind::kFailingPump:
          physics[Channel::kMdotKgS][i] *= d.severity;
          break;
        case DisturbanceKind::kStuckFlowReading:
          physics[Channel::kMdotKgS][i] = 0.0;
          break;
        case DisturbanceKind::kSnowCover:
          for (Channel c :
               {Channel::kGPoaWM2, Channel::kGPoaDiffuseWM2, Channel::kGhiWM2, Channel::kDhiWM2}) {
            if (physics.Has(c)) physics[c][i] *= d.severity;
          }
          break;
        case DisturbanceKind::kInletSensorOffset:
        case DisturbanceKind::kOutletSensorOffset:
        case DisturbanceKind::kFlowMeterScale:
          break;  // a sensor fault: the physics is untouched (SensorDisturbances)
      }
    }
  }
  return physics;
}

// The readings of the sensor disturbances: a logged inlet offset and the
// heat meter's reading computed from it (flow × c_p × (T_out − T_in) as
// logged); a logged outlet offset (the heat meter's own pair reads right); a
// flow meter scale and the heat meter's reading from that flow.
void SensorDisturbances(const Plant& plant, const std::vector<Disturbance>& disturbances,
                        Series* s) {
  auto& t_in = (*s)[Channel::kTInC];
  auto& t_out = (*s)[Channel::kTOutC];
  auto& q_th = (*s)[Channel::kQThW];
  auto& flow = (*s)[Channel::kMdotKgS];
  for (const Disturbance& d : disturbances) {
    for (std::size_t i = 0; i < s->size(); ++i) {
      if (!InWindow(d, s->time_s[i])) continue;
      if (d.kind == DisturbanceKind::kInletSensorOffset) {
        t_in[i] += d.severity;
        if (flow[i] > 0.0) q_th[i] -= flow[i] * plant.fluid_cp_j_kgk * d.severity;
      } else if (d.kind == DisturbanceKind::kOutletSensorOffset) {
        t_out[i] += d.severity;
      } else if (d.kind == DisturbanceKind::kFlowMeterScale) {
        flow[i] *= d.severity;
        q_th[i] *= d.severity;
      }
    }
  }
}

// The modules whose other form the truth runs (UsesOtherForm).
std::vector<const EffectModule*> OtherForms(const SyntheticOptions& options) {
  std::vector<const EffectModule*> out;
  for (const EffectModule* m : EffectRegistry()) {
    if (UsesOtherForm(options, *m)) out.push_back(m);
  }
  return out;
}

// The truth's spec for its physics: without the sensor errors (they act on
// the measurements) and without the same form of each other-form effect.
ModelSpec PhysicsSpec(const SyntheticOptions& options,
                      const std::vector<const EffectModule*>& other) {
  ModelSpec spec = options.truth_spec;
  for (const EffectModule* m : EffectRegistry()) {
    if (m->apply_sensor_error != nullptr && m->extension != nullptr) spec.Remove(*m->extension);
  }
  for (const EffectModule* m : other) {
    if (m->other_truth->remove_same_form != nullptr) {
      m->other_truth->remove_same_form(&spec);
    } else if (m->extension != nullptr) {
      spec.Remove(*m->extension);
    }
  }
  return spec;
}

// Runs the truth: the other forms' drivers hooks, then `passes` runs with
// their run hooks (each seeing the previous pass), then their outputs hooks.
void RunTruth(const std::vector<const EffectModule*>& other, OtherTruthContext ctx,
              const ParamVector& truth, Drivers* drivers, SimOutputs* out) {
  int passes = 1;
  bool any_run_hook = false;
  for (const EffectModule* m : other) {
    if (m->other_truth->drivers != nullptr) m->other_truth->drivers(ctx, drivers);
    if (m->other_truth->run != nullptr) {
      any_run_hook = true;
      passes = std::max(passes, m->other_truth->passes);
    }
  }
  SimOutputs previous;
  for (int pass = 0; pass < passes; ++pass) {
    ctx.previous = pass > 0 ? &previous : nullptr;
    SimOptions sim;
    if (any_run_hook) {
      sim.after_extensions = [&other, &ctx](const Drivers& d, RunInputs* run) {
        for (const EffectModule* m : other) {
          if (m->other_truth->run != nullptr) m->other_truth->run(ctx, d, run);
        }
      };
    }
    Simulate(*drivers, truth, out, sim);
    if (pass + 1 < passes) {
      previous.p_el_w = out->p_el_w;
      previous.q_th_w = out->q_th_w;
      previous.t_pv_c = out->t_pv_c;
      previous.t_coll_c = out->t_coll_c;
      previous.t_out_c = out->t_out_c;
    }
  }
  ctx.previous = nullptr;
  for (const EffectModule* m : other) {
    if (m->other_truth->outputs != nullptr) m->other_truth->outputs(ctx, *drivers, out);
  }
}

// The meters' readings of the truth's outputs with noise; the heat meter of
// a disturbed flow multiplies its flow reading by the real temperature rise.
void WriteMeasuredOutputs(const Plant& plant, const SensorNoise& noise, const Drivers& drivers,
                          const SimOutputs& out, Series* s) {
  std::mt19937_64 rng(noise.seed);
  auto& p_el = s->Ensure(Channel::kPElW);
  auto& q_th = s->Ensure(Channel::kQThW);
  auto& t_out = s->Ensure(Channel::kTOutC);
  auto& t_pv = s->Ensure(Channel::kTPvC);
  const auto& flow_read = (*s)[Channel::kMdotKgS];
  for (std::size_t i = 0; i < s->size(); ++i) {
    p_el[i] = out.p_el_w[i] * (1.0 + noise.p_el_rel * Normal(rng));
    // A heat meter reads zero without flow.
    const double q_noise = noise.q_th_w * Normal(rng);
    q_th[i] = out.q_th_w[i] + (drivers.mdot_kg_s[i] > 0.0 ? q_noise : 0.0);
    t_out[i] = out.t_out_c[i] + noise.t_out_c * Normal(rng);
    t_pv[i] = out.t_pv_c[i];
    if (flow_read[i] != drivers.mdot_kg_s[i]) {
      q_th[i] = flow_read[i] > 0.0
                    ? flow_read[i] * plant.fluid_cp_j_kgk * (t_out[i] - (*s)[Channel::kTInC][i])
                    : 0.0;
    }
  }
}

}  // namespace

Series MakeSyntheticPlantData(const Plant& plant, const SyntheticOptions& options) {
  return MakeSyntheticPlantData(plant, options, nullptr);
}

Series MakeSyntheticPlantData(const Plant& plant, const SyntheticOptions& options,
                              SimOutputs* truth_outputs) {
  WeatherOptions weather = options.weather;
  weather.absorber = SensorParamsFromTruth(options.truth_spec, options.truth);
  Series s = GenerateWeather(plant, weather);
  const std::vector<const EffectModule*> other = OtherForms(options);
  OtherTruthContext ctx;
  ctx.plant = &plant;
  ctx.truth = &options.truth;
  ctx.seed = options.weather.seed;
  // The true irradiance (irradiance_bias is a sensor error, applied below).
  Series physics = DisturbedPhysics(s, options);
  for (const EffectModule* m : other) {
    if (m->other_truth->weather != nullptr) m->other_truth->weather(ctx, &physics);
  }
  ctx.physics = &physics;
  Drivers drivers;
  std::string error;
  if (!PrepareDrivers(physics, plant, PhysicsSpec(options, other), &drivers, &error)) {
    std::cerr << "MakeSyntheticPlantData: " << error << "\n";
    std::abort();  // the generator provides every channel: a bug
  }
  if (!options.cleaning_times_s.empty()) SetCleaningTimes(options.cleaning_times_s, &drivers);
  SimOutputs out;
  RunTruth(other, ctx, options.truth, &drivers, &out);
  WriteMeasuredOutputs(plant, options.noise, drivers, out, &s);
  SensorDisturbances(plant, options.disturbances, &s);
  for (const EffectModule* m : EffectRegistry()) {
    const bool other_form = std::find(other.begin(), other.end(), m) != other.end();
    if (other_form && m->other_truth->measured != nullptr) {
      m->other_truth->measured(ctx, drivers, &s);
    } else if (!other_form && m->apply_sensor_error != nullptr &&
               HasEffect(options.truth_spec, *m)) {
      m->apply_sensor_error(options.truth, &s);
    }
  }
  InjectDefects(options.defects, &s);
  if (truth_outputs != nullptr) *truth_outputs = std::move(out);
  return s;
}

Series MakeSyntheticPlantData(const Plant& plant, const WeatherOptions& weather,
                              const ModelSpec& truth_spec, const ParamVector& truth,
                              const SensorNoise& noise) {
  SyntheticOptions options;
  options.weather = weather;
  options.truth_spec = truth_spec;
  options.truth = truth;
  options.noise = noise;
  return MakeSyntheticPlantData(plant, options);
}

}  // namespace pvtwin
