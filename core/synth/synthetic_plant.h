// Synthetic operation data of a PVT field: generated weather and operation
// (weather_generator.h) run through a "truth" model variant with known
// parameters, with optional sensor noise. The basis of identification tests
// on data with a known answer, of benchmarks and of the demo.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/model_data.h"
#include "core/common/params.h"
#include "core/common/series.h"
#include "core/effects/effect_module.h"
#include "core/model/variant.h"
#include "core/synth/weather_generator.h"

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

// The plant of doc/contracts.md's example [plant] section: 47.358° N, 16.128° E,
// 20° tilt facing south, 1.8 m², the paper's fluid and PV reference data.
Plant DesignExamplePlant();

// A plausible uncovered PVT collector, inside Table 3's bounds, used as the
// known answer of synthetic tests.
ParamVector ReferenceTruthParams(const Plant& plant);

// The absorber sensor of the plant's controller (absorber_sensor.h) with the
// truth's parameters: (1 − η_PV,ref)·F_th, U_front, U_back, the physical wind
// form if the truth has it (the paper's 'w' form is left out: the sensor is
// a close estimate, not the truth), ε if it has sky radiation, the fluid
// coupling r0/r1 with 1/U_coll in series for two nodes, C_PV + C_coll.
AbsorberSensorParams SensorParamsFromTruth(const ModelSpec& truth_spec, const ParamVector& truth);

// Weather and operation from `weather`, outputs p_el_w, q_th_w, t_out_c and
// t_pv_c from `truth_spec` with `truth`, then noise on p_el_w, q_th_w and
// t_out_c (q_th_w stays consistent with flow and the noisy outlet: the heat
// meter's noise is applied on q_th_w itself).
Series MakeSyntheticPlantData(const Plant& plant, const WeatherOptions& weather,
                              const ModelSpec& truth_spec, const ParamVector& truth,
                              const SensorNoise& noise);

// ---------------------------------------------------------------------------
// The truth model for the gap diagnosis: any variant with effects
// ("1N1Cwr+pv_clipping+shading") at a chosen magnitude, realistic operation,
// noise, the paper's data defects and uncatalogued disturbances.

// ReferenceTruthParams with EffectInfo::typical_truth of every effect that
// spec has (HasEffect), letters included.
ParamVector TruthParamsFor(const Plant& plant, const ModelSpec& spec);

// Plant faults that no catalogued effect explains (the diagnosis's
// `unknown` cases). Each acts on rows with start_s ≤ time < end_s.
enum class DisturbanceKind {
  // The pump fails: the real flow is `severity` × the reading (a clogged
  // strainer, a dying pump). The heat meter multiplies the (normal) flow
  // reading by the real temperature rise, so q_th_w and t_out_c run high.
  kFailingPump,
  // The pump stands still while the flow meter keeps its last reading (a
  // stuck sensor): the collector stagnates; t_out_c is the stagnant fluid.
  kStuckFlowReading,
  // Snow (or a tarpaulin) covers the field: the pyranometers, mounted apart,
  // still see the sun, the collector absorbs `severity` × the irradiance
  // (0 = total cover), so P_el and Q_u are near zero.
  kSnowCover,
  // The inlet temperature sensor reads `severity` K high (a drifted or
  // re-mounted Pt100) on the rows of the window, typically from one day to
  // the end of the data. The physics is untouched; the logged t_in_c is
  // high and the heat meter, which multiplies flow by the logged
  // T_out − T_in, reads ṁ·c_p·severity less while the pump runs.
  kInletSensorOffset,
  // The logged outlet temperature reads `severity` K high (negative: low)
  // on the rows of the window; the heat meter has its own sensor pair and
  // reads right. The physics is untouched.
  kOutletSensorOffset,
  // The flow meter reads `severity` × the true flow (a clogged or re-mounted
  // meter, a wrong pulse value); the heat meter multiplies that reading by
  // the (right) temperature rise, so q_th_w reads `severity` × the truth.
  // The physics is untouched.
  kFlowMeterScale,
};

std::string_view DisturbanceName(DisturbanceKind kind);

struct Disturbance {
  DisturbanceKind kind = DisturbanceKind::kFailingPump;
  std::int64_t start_s = 0;  // unix s UTC
  std::int64_t end_s = 0;
  double severity = 0.0;  // kFailingPump: real/read flow; kSnowCover: transmitted fraction;
                          // sensor offsets: K; kFlowMeterScale: read/real flow
};

// The paper's data defects (Tables 1 and 2, core/data/qc.h), injected so that the
// data path's corrections are exercised: consumers run ApplyPaperCorrections
// (qc.h) as the CSV import and the poller do.
struct DataDefects {
  // Night rows whose short-wave irradiance reads above 5000 W/m² (Table 2).
  int irradiance_glitches = 0;
  // While the pump stands, the magnetic-inductive meter reads small negative
  // flows in [−0.8e-3, 0) kg/s (Table 1; corrected to 0).
  bool negative_flow_at_rest = false;
  // Blocks of 30 rows marked valid = 0 (maintenance, logger restarts).
  int invalid_blocks = 0;
  // Blocks of 10 rows where t_out_c and q_th_w are missing (sensor dropout).
  int dropout_blocks = 0;
  std::uint64_t seed = 7;
};

inline DataDefects PaperDataDefects(std::uint64_t seed) { return {6, true, 4, 4, seed}; }

// Which form the truth gives the effects under test (issue 11, item 2).
enum class TruthForm {
  // The candidate's own equations (the effect's extension or letter with its
  // typical_truth): a present candidate can fit the truth exactly.
  kSameForm,
  // The effects listed in SyntheticOptions::other_form_effects in another
  // functional form (EffectModule::other_truth: a horizon profile on some
  // days for an obstacle box, a soft inverter knee for a hard clip, …), so
  // that their candidates cannot fit exactly.
  kOtherForm,
};

std::string_view TruthFormName(TruthForm form);  // "same-form", "other-form"

struct SyntheticOptions {
  TruthForm truth_form = TruthForm::kSameForm;
  // With kOtherForm: the effects of truth_spec that run in their other form
  // (typically the one a diagnosis withholds; the base model's own letters
  // keep the form the base model has).
  std::vector<const EffectModule*> other_form_effects;
  WeatherOptions weather;
  ModelSpec truth_spec;
  ParamVector truth{};
  SensorNoise noise;
  std::vector<Disturbance> disturbances;
  DataDefects defects;
  // soiling: cleanings (rain) that reset the loss; none = soiling from the
  // first row (SetCleaningTimes).
  std::vector<std::int64_t> cleaning_times_s;
};

// Multi-week data as a real plant delivers it: `days` days of 1-min rows
// from 2024-06-01 with drawn clear/broken/overcast days, variable flow with
// pump starts and stops, the inlet drifting with the tank, realistic sensor
// noise and the paper's data defects, truth = TruthParamsFor(variant). False
// (with *error) when the variant does not parse.
bool DefaultSyntheticOptions(const Plant& plant, std::string_view truth_variant, int days,
                             std::uint64_t seed, SyntheticOptions* options, std::string* error);

// The data of SyntheticOptions. The truth model is options.truth_spec with
// options.truth; irradiance_bias is a sensor error: the physics sees the true
// irradiance and g_poa_w_m2 (and g_poa_diffuse_w_m2) are written divided by
// (1 + k). Aborts on a bad weather option (a caller bug, as GenerateWeather).
// With options.truth_form == kOtherForm, each effect of other_form_effects
// that truth_spec has and that has an other-form truth runs in that form
// instead (its hooks, seeded by options.weather.seed). *truth_outputs (may be null) receives the
// truth's noise-free outputs (what the meters would read without noise and defects).
Series MakeSyntheticPlantData(const Plant& plant, const SyntheticOptions& options);
Series MakeSyntheticPlantData(const Plant& plant, const SyntheticOptions& options,
                              SimOutputs* truth_outputs);

// Whether the effect runs in its other form under options (options ask for
// it, the truth has it and the module has one).
bool UsesOtherForm(const SyntheticOptions& options, const EffectModule& effect);

}  // namespace pvtwin
