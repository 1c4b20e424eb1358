// The model parameters: one table with name, unit, start value and the range
// searched by identification (paper Table 3). Everything that needs to know a
// parameter (the model, identification, params.json, the CLI, the effect
// modules) reads it here; the table, the slots and the effect each slot
// belongs to derive from one list, core/common/param_list.inc.
//
// Normalisation (per m² of collector, as in Table 3):
//  * Conductances U are W/(m²·K) and capacitances C are J/(m²·K); the model
//    multiplies by A_PVT.
//  * The fluid coupling (paper 2.7, Koschenz & Lehmann) is written per m² with
//    the specific heat-capacity flow w = ṁ·c_p / A_PVT in W/(m²·K):
//        1 / U_fluid = r1_fluid / (2·w) + r0_fluid
//    r1_fluid is dimensionless: 1 makes the node temperature the mean of inlet
//    and outlet (the outlet then sits at 2·T_node − T_in when r0 = 0); values
//    above 1 model a fluid that leaves cooler than that. r0_fluid (m²·K/W) is
//    the flow-independent resistance from absorber to fluid. The paper's units
//    for these two are garbled in Table 3; this form keeps the paper's start
//    values meaningful (r1 = 1, r0 = 0.1 m²K/W → U_fluid ≈ 9 W/m²K at the
//    paper's flows) and gives U_fluid = 0 at ṁ = 0.
//  * C_PV's start value and range are missing from Table 3 ("0 [0 0]"); the
//    variants that place a capacitance on the PV node use C_coll's values.
//  * The paper's wind form (2.8) uses r_refwind in (m²·K/W)/(m/s)^n_wind. The
//    physical alternative (effect "wind", ISO 9806 style) adds
//    u_wind_w_m2k·v^n_wind to the front conductance.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

#include "core/common/effect_list.h"
#include "core/common/plant.h"

namespace pvtwin {

// One slot per row of core/common/param_list.inc, in its order.
enum class Param : std::size_t {
#define PVTWIN_PARAM(id, ...) id,
#include "core/common/param_list.inc"
  kCount
};

inline constexpr std::size_t kNumParams = static_cast<std::size_t>(Param::kCount);

using ParamVector = std::array<double, kNumParams>;

enum class ParamScale { kLinear, kLog };

struct ParamInfo {
  Param param;
  std::string_view name;  // params.json key
  std::string_view unit;
  std::string_view symbol;  // paper symbol
  double start;             // reference start value (Table 3)
  double lower;             // identification bounds (Table 3)
  double upper;
  ParamScale scale;        // how identification scales the search variable
  bool relative_to_plant;  // start/bounds are factors of the plant config value
};

// Bounds for A_PVT, f_corr_T and f_corr_I are factors of the plant config's
// value (Table 3's "±50 %"); use ResolvedInfo() to get absolute numbers.
extern const std::array<ParamInfo, kNumParams> kParamTable;

// The value of parameter `name` in p.
inline double ParamOf(const ParamVector& p, Param name) {
  return p[static_cast<std::size_t>(name)];
}

inline const ParamInfo& Info(Param p) { return kParamTable[static_cast<std::size_t>(p)]; }

// Start value and bounds for parameter p at this plant (absolute values).
ParamInfo ResolvedInfo(Param p, const Plant& plant);

// All start values for this plant.
ParamVector StartParams(const Plant& plant);

std::optional<Param> ParamFromName(std::string_view name);

namespace param_owner {
// The owner column of param_list.inc: Base, or an effect's CamelCase name.
inline constexpr std::optional<Effect> Base = std::nullopt;
#define PVTWIN_PARAM_OWNER(name, Name) \
  inline constexpr std::optional<Effect> Name = Effect::k##Name;
PVTWIN_EFFECTS(PVTWIN_PARAM_OWNER)
#undef PVTWIN_PARAM_OWNER
}  // namespace param_owner

// The effect whose module adds each parameter (param_list.inc's owner
// column); nullopt: the base model's own.
inline constexpr std::array<std::optional<Effect>, kNumParams> kParamEffect = {
#define PVTWIN_PARAM(id, owner, ...) param_owner::owner,
#include "core/common/param_list.inc"
};

inline constexpr std::optional<Effect> EffectOfParam(Param p) {
  return kParamEffect[static_cast<std::size_t>(p)];
}

// The parameters effect e adds, in slot order: its module's
// EffectModule::params.
std::vector<Param> EffectParams(Effect e);

}  // namespace pvtwin
