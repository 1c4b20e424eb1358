// The effect library: every physical or sensor effect of DESIGN.md's effect
// vocabulary as a composable model extension, with its parameters, a
// paragraph of physics for reports, the driver its residual evidence
// correlates with, and a realistic magnitude for synthetic truth data.
//
// The gap diagnosis builds its candidate models with WithEffect() and fits
// them with Identify(); the synthetic truth model (synthetic_plant.h) switches
// effects on through variant names ("1N1Cwr+pv_clipping+shading") with the
// magnitudes of EffectInfo::typical_truth.
//
// The equations of each effect live where the model evaluates them
// (thermal_model.cc, drivers.cc) and are summarised in EffectInfo::explanation;
// sources are cited there.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/common/channels.h"
#include "core/common/params.h"
#include "core/model/thermal_model.h"
#include "core/model/variant.h"

namespace pvtwin {

enum class Effect : std::size_t {
  kCapacitance,
  kSecondNode,
  kWind,
  kSkyRadiation,
  kIam,
  kFlowDependentU,
  kTransportDelay,
  kPvClipping,
  kShading,
  kSoiling,
  kClockOffset,
  kIrradianceBias,
  kCount
};

inline constexpr std::size_t kNumEffects = static_cast<std::size_t>(Effect::kCount);

struct EffectInfo {
  Effect effect;
  std::string_view name;         // DESIGN.md vocabulary, e.g. "pv_clipping"
  std::string_view explanation;  // one paragraph of physics for the report
  std::vector<Param> params;     // parameters the effect adds (bounds/units in kParamTable)
  // A realistic magnitude for synthetic truth data (applied on top of
  // ReferenceTruthParams).
  std::vector<std::pair<Param, double>> typical_truth;
  // What the residual evidence correlates with (EffectSignature's values).
  std::string_view signature;
  // Extra input channels the effect needs beyond the base variant's.
  std::vector<Channel> needs;
};

// One entry per Effect, in enum order.
const std::vector<EffectInfo>& EffectTable();
const EffectInfo& Info(Effect e);
std::optional<Effect> EffectFromName(std::string_view name);

// Whether spec contains the effect. capacitance: at least one node has a
// capacitance; second_node: two nodes; wind: 'w' or "+wind".
bool HasEffect(const ModelSpec& spec, Effect e);

// Whether adding e to spec makes sense: false when already present (for
// capacitance: when every node has one), with the reason in *why_not
// (may be null).
bool CanAddEffect(const ModelSpec& spec, Effect e, std::string* why_not);
// The same, also checking that the data provide the channels the effect
// needs (e.g. irradiance_bias: "not identifiable without a second irradiance
// source (ghi_w_m2 + dhi_w_m2)").
bool CanAddEffect(const ModelSpec& spec, Effect e, const Series& data, std::string* why_not);

// spec with e added: capacitance 1N → 1N1C, 2N → 2N1Ccol, 2N1Cpv/2N1Ccol →
// 2N2C; second_node 1N → 2N (1N1C → 2N1Cpv); wind 'w' (the paper's form,
// unless "+wind" is present); sky_radiation 'r'; iam 'I'; the others their
// "+name" extension. Adding a present effect returns spec unchanged.
ModelSpec WithEffect(ModelSpec spec, Effect e);

// Per-row value of the effect's signature driver (EffectInfo::signature),
// for residual evidence; NaN where undefined. drivers may belong to a model
// without the effect (PrepareDrivers fills the raw channels it needs for every
// spec); base_outputs are the base model's outputs on the same rows.
std::vector<double> EffectSignature(Effect e, const Drivers& drivers,
                                    const SimOutputs& base_outputs);

// irradiance_bias: scale error k of the plane-of-array pyranometer
// (G_true = G_meas·(1 + k)) from the second irradiance source: the median of
// G_ref/G_meas − 1 over rows where both exceed 300 W/m² and the beam angle of
// incidence is below 60° (transposition errors grow towards grazing angles),
// G_ref = GHI/DHI transposed to the plane (isotropic sky, paper 2.5). NaN when
// fewer than 30 such rows exist.
double EstimateIrradianceBias(const Drivers& drivers);

}  // namespace pvtwin
