// The model parameters: one table with name, unit, start value and the range
// searched by identification (paper Table 3). Everything that needs to know a
// parameter (the model, identification, params.json, the CLI) reads it here.
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

#include "core/common/plant.h"

namespace pvtwin {

enum class Param : std::size_t {
  kAreaM2,           // A_PVT
  kEpsPvt,           // ε_PVT, long-wave emittance
  kEtaPvRef,         // η_PVref
  kFTh,              // F_th, thermal efficiency factor
  kUFrontWM2K,       // U_front
  kUBackWM2K,        // U_back
  kUCollWM2K,        // U_coll (2-node only)
  kR0FluidM2KW,      // r0_fluid
  kR1Fluid,          // r1_fluid (dimensionless, see above)
  kCPvJM2K,          // C_PV
  kCCollJM2K,        // C_coll
  kRRefWind,         // r_refwind, (m²K/W)/(m/s)^n
  kNWind,            // n_wind
  kUWindWM2K,        // physical wind form: W/(m²K)/(m/s)^n
  kPvTempCoeffPerK,  // f_corr_T (fixed by default, from the plant config)
  kPvIrrCoeffM2W,    // f_corr_I (fixed by default, from the plant config)
  kTransportDelayS,  // effect transport_delay: inlet-to-outlet dead time
  // Parameters of the effect modules (core/effects/<effect>.h, which list
  // them in EffectModule::params); appended so that the indices above keep
  // their meaning. Each is a slot of the fixed-size ParamVector, so that the
  // simulation loop never allocates: a new effect's parameter adds a slot
  // here and a row in params.cc.
  kUPipeWM2K,          // transport_delay: pipe loss to ambient, W/(m²K) of collector
  kNFlow,              // flow_dependent_u: exponent of the fluid-side resistance on flow
  kPLimitWM2,          // pv_clipping: inverter AC limit per m² of collector, W/m²
  kShadeAzimuthRad,    // shading: centre of the obstacle's azimuth window
  kShadeWidthRad,      // shading: full width of the azimuth window
  kShadeElevationRad,  // shading: elevation of the obstacle's upper edge
  kShadeMismatch,      // shading: extra P_el loss per shaded fraction (bypass diodes)
  kSoilingPerDay,      // soiling: transmittance loss per day since cleaning
  kClockOffsetS,       // clock_offset: weather clock behind the collector clock
  kIrradianceBias,     // irradiance_bias: pyranometer scale error k
  kSkyCloudOffset,     // sky_radiation (broader form): cloud fraction beyond the logged sky's
  kPipePlugKgM2,       // transport_delay (pipe_volume form): plug-flow fluid mass per m²
  kPipeMixKgM2,        // transport_delay (pipe_volume form): mixed fluid mass per m²
  kIamB0Fit,           // iam (fitted form "+iam"): ASHRAE coefficient b0
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

}  // namespace pvtwin
