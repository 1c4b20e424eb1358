#include "core/common/params.h"

#include <cmath>

namespace pvtwin {

namespace {
constexpr auto kLin = ParamScale::kLinear;
constexpr auto kLog = ParamScale::kLog;
}  // namespace

// Table 3 of the paper; see params.h for the normalisation of each entry.
// The r0_fluid lower bound is 1e-4 instead of 0 so that it can be searched on
// a log scale (the paper found it always near zero: 1e-4 m²K/W is already a
// negligible resistance next to any U_fluid below 1e3 W/m²K).
const std::array<ParamInfo, kNumParams> kParamTable = {{
    {Param::kAreaM2, "area_m2", "m²", "A_PVT", 1.0, 0.5, 1.5, kLin, true},
    {Param::kEpsPvt, "eps_pvt", "-", "ε_PVT", 0.15, 0.075, 0.225, kLin, false},
    {Param::kEtaPvRef, "eta_pv_ref", "-", "η_PVref", 0.15, 0.075, 0.225, kLin, false},
    {Param::kFTh, "f_th", "-", "F_th", 1.0, 0.5, 1.2, kLin, false},
    {Param::kUFrontWM2K, "u_front_w_m2k", "W/(m²K)", "U_front", 10.0, 1e-3, 1e3, kLog, false},
    {Param::kUBackWM2K, "u_back_w_m2k", "W/(m²K)", "U_back", 10.0, 1e-3, 1e3, kLog, false},
    {Param::kUCollWM2K, "u_coll_w_m2k", "W/(m²K)", "U_coll", 10.0, 1e-3, 1e3, kLog, false},
    {Param::kR0FluidM2KW, "r0_fluid_m2k_w", "m²K/W", "r0_fluid", 0.1, 1e-4, 1e3, kLog, false},
    {Param::kR1Fluid, "r1_fluid", "-", "r1_fluid", 1.0, 1e-2, 1e2, kLog, false},
    {Param::kCPvJM2K, "c_pv_j_m2k", "J/(m²K)", "C_PV", 1e5, 1e3, 1e7, kLog, false},
    {Param::kCCollJM2K, "c_coll_j_m2k", "J/(m²K)", "C_coll", 1e5, 1e3, 1e7, kLog, false},
    {Param::kRRefWind, "r_refwind", "(m²K/W)/(m/s)^n", "r_refwind", 1.0, 1e-2, 1e2, kLog, false},
    {Param::kNWind, "n_wind", "-", "n_wind", 0.6, 0.3, 1.2, kLin, false},
    {Param::kUWindWM2K, "u_wind_w_m2k", "W/(m²K)/(m/s)^n", "c_wind", 3.0, 1e-2, 1e2, kLog, false},
    {Param::kPvTempCoeffPerK, "pv_temp_coeff_per_k", "1/K", "f_corr_T", 1.0, 0.5, 1.5, kLin, true},
    {Param::kPvIrrCoeffM2W, "pv_irr_coeff_m2_w", "m²/W", "f_corr_I", 1.0, 0.5, 1.5, kLin, true},
    {Param::kTransportDelayS, "transport_delay_s", "s", "τ_transport", 30.0, 0.0, 900.0, kLin,
     false},
    // Effect modules (core/effects/). Bounds: the physically plausible range
    // of each effect; starts: inside the range where the effect acts on
    // typical data, so that identification sees a gradient.
    // UA of the collector loop's piping per m² of collector: insulated pipes
    // lose 0.1 … 0.5 W/(m·K); 0 … 10 m per m² of collector.
    {Param::kUPipeWM2K, "u_pipe_w_m2k", "W/(m²K)", "U_pipe", 0.5, 0.0, 5.0, kLin, false},
    // 0 = laminar (Nusselt number independent of flow), 0.8 = turbulent
    // Dittus–Boelter (h ∝ Re^0.8).
    {Param::kNFlow, "n_flow", "-", "n_flow", 0.4, 0.0, 1.2, kLin, false},
    {Param::kPLimitWM2, "p_limit_w_m2", "W/m²", "P_limit", 100.0, 30.0, 300.0, kLin, false},
    // The sun's azimuth spans about 50–310° over a year at the plant's
    // latitudes: the obstacle's centre may lie anywhere from 30° to 330°.
    {Param::kShadeAzimuthRad, "shade_azimuth_rad", "rad", "γ_shade", 3.14159265358979323846,
     0.5235987755982988, 5.759586531581287, kLin, false},
    // The start window (240° wide, up to 20° elevation) shades the low sun
    // of mornings and evenings in every season, so the fit starts with a
    // gradient in every shading parameter.
    {Param::kShadeWidthRad, "shade_width_rad", "rad", "Δγ_shade", 4.1887902047863905,
     0.08726646259971647, 5.235987755982989, kLin, false},
    {Param::kShadeElevationRad, "shade_elevation_rad", "rad", "α_shade", 0.3490658503988659, 0.0,
     1.0471975511965976, kLin, false},
    {Param::kShadeMismatch, "shade_mismatch", "-", "f_mismatch", 0.5, 0.0, 1.0, kLin, false},
    {Param::kSoilingPerDay, "soiling_per_day", "1/d", "r_soil", 0.002, 0.0, 0.02, kLin, false},
    {Param::kClockOffsetS, "clock_offset_s", "s", "Δt_clock", 0.0, -1800.0, 1800.0, kLin, false},
    {Param::kIrradianceBias, "irradiance_bias", "-", "k_pyr", 0.0, -0.3, 0.3, kLin, false},
    // The sky the front sees may be cloudier (> 0) or clearer (< 0) than the
    // logged long-wave's: sky models and their cloud corrections differ that
    // much (Flerchinger et al. 2009, Water Resour. Res. 45, W03423).
    {Param::kSkyCloudOffset, "sky_cloud_offset", "-", "Δc_sky", 0.0, -0.5, 0.9, kLin, false},
    // Fluid between the collector outlet and its sensor, per m² of collector:
    // the part that moves as a plug (a dead time ∝ 1/flow) and the part that
    // is mixed (bends, a sensor well, a manifold: a first-order lag ∝ 1/flow).
    // 10 kg/m² is 18 L for a 1.8 m² collector, 60 m of DN 20 pipe.
    {Param::kPipePlugKgM2, "pipe_plug_kg_m2", "kg/m²", "M_plug", 0.5, 0.0, 10.0, kLin, false},
    {Param::kPipeMixKgM2, "pipe_mix_kg_m2", "kg/m²", "M_mix", 0.5, 0.0, 10.0, kLin, false},
    // ASHRAE's b0 of a glazed collector: 0.04–0.2 (Duffie & Beckman 5.6;
    // ISO 9806 test reports); 0.05 is the paper's Table 3 value.
    {Param::kIamB0Fit, "iam_b0_fit", "-", "b0", 0.05, 0.0, 0.3, kLin, false},
}};

ParamInfo ResolvedInfo(Param p, const Plant& plant) {
  ParamInfo info = Info(p);
  if (!info.relative_to_plant) return info;
  double reference = 0.0;
  switch (p) {
    case Param::kAreaM2:
      reference = plant.area_m2;
      break;
    case Param::kPvTempCoeffPerK:
      reference = plant.pv_temp_coeff_per_k;
      break;
    case Param::kPvIrrCoeffM2W:
      reference = plant.pv_irr_coeff_m2_w;
      break;
    default:
      break;
  }
  info.start *= reference;
  const double a = info.lower * reference;
  const double b = info.upper * reference;
  info.lower = std::fmin(a, b);  // a negative reference flips the interval
  info.upper = std::fmax(a, b);
  return info;
}

ParamVector StartParams(const Plant& plant) {
  ParamVector v{};
  for (std::size_t i = 0; i < kNumParams; ++i) {
    v[i] = ResolvedInfo(static_cast<Param>(i), plant).start;
  }
  return v;
}

std::optional<Param> ParamFromName(std::string_view name) {
  for (const ParamInfo& info : kParamTable) {
    if (info.name == name) return info.param;
  }
  return std::nullopt;
}

}  // namespace pvtwin
