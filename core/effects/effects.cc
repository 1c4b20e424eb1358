#include "core/effects/effects.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "core/common/units.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<EffectInfo> BuildTable() {
  using P = Param;
  using C = Channel;
  std::vector<EffectInfo> t;
  t.push_back({Effect::kCapacitance,
               "capacitance",
               "Thermal mass of the PV laminate, absorber and fluid content: the collector "
               "temperature lags behind changes of irradiance, inlet temperature and flow, "
               "storing heat on rising irradiance and releasing it afterwards (paper 2.2, "
               "C·dT/dt in the node balance). Without it the model answers cloud edges and pump "
               "starts instantly.",
               {P::kCPvJM2K, P::kCCollJM2K},
               {{P::kCPvJM2K, 1.2e4}, {P::kCCollJM2K, 3.5e4}},
               "rate of change of the absorbed irradiance, W/m² per minute",
               {}});
  t.push_back({Effect::kSecondNode,
               "second_node",
               "A finite conductance U_coll between the PV laminate and the absorber/fluid "
               "channel: the cells run warmer than the fluid-side node by Q/U_coll, which lowers "
               "P_el at high heat flux (paper 2.10, two-node network).",
               {P::kUCollWM2K},
               // A PVT module without lamination of the cells onto the absorber.
               {{P::kUCollWM2K, 12.0}},
               "inlet minus ambient temperature, K",
               {}});
  t.push_back({Effect::kWind,
               "wind",
               "Forced convection on the uncovered front: the front loss conductance grows with "
               "wind speed, U_front(v) with 1/U = 1/U_front + r_refwind/v^n (paper 2.8, 'w').",
               {P::kRRefWind, P::kNWind},
               {{P::kRRefWind, 0.02}, {P::kNWind, 0.8}},
               "wind speed, m/s",
               {C::kWindMS}});
  t.push_back({Effect::kSkyRadiation,
               "sky_radiation",
               "Long-wave exchange of the front with the sky: ε·σ·(T_PV⁴ − T_sky⁴) (paper "
               "2.9, 'r'). Clear nights and clear days with a cold sky cool the collector below "
               "ambient; the loss scales with the sky temperature deficit.",
               {P::kEpsPvt},
               {{P::kEpsPvt, 0.12}},
               "ambient minus sky temperature, K",
               {C::kTSkyC}});
  t.push_back({Effect::kIam,
               "iam",
               "Incidence-angle modifier: reflection at the glass rises at grazing angles, so "
               "the absorbed irradiance is the beam weighted by K(θ) = 1 − b0·(1/cos θ − 1) "
               "plus sky and ground diffuse at their effective angles (Souka & Safwat; "
               "Brandemuehl & Beckman; paper 2.5, 'I').",
               {},
               {},
               "beam angle of incidence, rad",
               {}});
  t.push_back({Effect::kFlowDependentU,
               "flow_dependent_u",
               "The absorber-to-fluid heat transfer coefficient depends on the flow regime: "
               "constant Nusselt number in laminar flow, h ∝ Re^0.8 in turbulent flow "
               "(Dittus–Boelter). The model keeps the paper's 1/U_fluid = r1/(2w) + r0 "
               "(eq. 2.7, the fluid's own temperature rise r1/(2w) already depends on flow) and "
               "lets the convective part follow the flow: r0(w) = r0·(w_ref/w)^n_flow, "
               "w = ṁ·c_p/A, w_ref = 0.02 kg/(s·m²)·c_p; n_flow = 0 is the paper's laminar "
               "form. Visible when the flow varies: Q_u falls faster than the base model "
               "predicts at low flow.",
               {P::kNFlow},
               // Turbulent flow in a sheet-and-tube absorber with a poor bond,
               // where the convective resistance matters.
               {{P::kNFlow, 0.8}, {P::kR0FluidM2KW, 0.08}},
               "mass flow relative to the nominal 0.02 kg/(s·m²)",
               {}});
  t.push_back({Effect::kTransportDelay,
               "transport_delay",
               "The outlet sensor sits behind a pipe: it sees the fluid that left the collector "
               "τ earlier (plug flow dead time), cooled towards ambient on the way, "
               "T_sensor = T_amb + (T_out(t − τ) − T_amb)·exp(−U_pipe·A/(ṁ·c_p)) "
               "(exponential decay of a plug in a pipe of loss UA, Duffie & Beckman 10.3). "
               "Q_u is then ṁ·c_p·(T_sensor − T_in): lagging at pump starts and irradiance "
               "steps, lower than the collector's output at low flow.",
               {P::kTransportDelayS, P::kUPipeWM2K},
               {{P::kTransportDelayS, 120.0}, {P::kUPipeWM2K, 1.0}},
               "rate of change of the base model's outlet temperature, K per minute",
               {}});
  t.push_back({Effect::kPvClipping,
               "pv_clipping",
               "The inverter or MPPT limits the AC power: P_el = min(P_dc, P_limit). A PVT "
               "module whose electricity is clipped moves its operating point away from the "
               "maximum power point, so the unconverted power stays in the laminate as heat: "
               "the node balance gets Q_abs = F_th·(A·I_at − P_el), which raises T_PV and Q_u "
               "while clipping.",
               {P::kPLimitWM2},
               {{P::kPLimitWM2, 120.0}},
               "base model P_el per m² (evidence above the limit)",
               {}});
  t.push_back({Effect::kShading,
               "shading",
               "An obstacle (building, tree, row in front) blocks the beam while the sun is "
               "inside an azimuth window γ_shade ± Δγ/2 below the obstacle's edge α_shade: "
               "s = σ((Δγ/2 − |γ_sun − γ_shade|)/e)·σ((α_shade − α_sun)/e), logistic edges "
               "e = 2° so that the fit has a gradient. The absorbed irradiance loses s·I_beam, "
               "and partial shade of a string makes the bypass diodes drop whole substrings: "
               "P_el is further multiplied by (1 − f_mismatch·s), the power not converted "
               "staying as heat. P_el therefore drops much more than Q_u.",
               {P::kShadeAzimuthRad, P::kShadeWidthRad, P::kShadeElevationRad, P::kShadeMismatch},
               {{P::kShadeAzimuthRad, DegToRad(250.0)},
                {P::kShadeWidthRad, DegToRad(40.0)},
                {P::kShadeElevationRad, DegToRad(35.0)},
                {P::kShadeMismatch, 0.6}},
               "beam irradiance in the plane, W/m² (localise by sun azimuth × elevation)",
               {C::kGhiWM2, C::kDhiWM2}});
  t.push_back({Effect::kSoiling,
               "soiling",
               "Dust and pollen on the front cover reduce its transmittance roughly linearly "
               "with the days since the last rain or cleaning: τ_soil = max(0, 1 − r_soil·d) "
               "multiplies the absorbed irradiance, so P_el and Q_u both drift down over the "
               "weeks (Kimber et al. 2006, linear soiling rate). Cleanings reset d "
               "(SetCleaningTimes); without a known cleaning d counts from the first row.",
               {P::kSoilingPerDay},
               {{P::kSoilingPerDay, 0.004}},
               "days since the last cleaning",
               {}});
  t.push_back({Effect::kClockOffset,
               "clock_offset",
               "The weather station's logger clock differs from the collector logger's: the "
               "weather the collector saw at time t is the weather row stamped t + Δt. The "
               "model interpolates the weather drivers (irradiance, ambient and back "
               "temperature, wind, sky) linearly at t + Δt; sun geometry follows the "
               "collector clock. Residuals follow the rate of change of irradiance with a sign "
               "that flips between morning and afternoon.",
               {P::kClockOffsetS},
               {{P::kClockOffsetS, 300.0}},
               "rate of change of the absorbed irradiance, W/m² per minute",
               {}});
  t.push_back({Effect::kIrradianceBias,
               "irradiance_bias",
               "The plane-of-array pyranometer reads with a scale error, G_true = G_meas·(1 + k) "
               "(calibration drift, soiled dome, misalignment). From P_el and Q_u alone k is "
               "indistinguishable from η_PV·F_th; with the weather station's GHI and DHI "
               "transposed to the plane (isotropic sky, paper 2.5) as a second source, k is the "
               "median of G_ref/G_meas − 1 over bright rows at moderate incidence, and the model "
               "uses (1 + k)·G_meas, keeping the plane sensor's time resolution. The fit then "
               "returns unbiased η_PV and F_th.",
               {P::kIrradianceBias},
               {{P::kIrradianceBias, 0.06}},
               "transposed GHI/DHI minus measured plane-of-array irradiance, W/m²",
               {C::kGhiWM2, C::kDhiWM2}});
  return t;
}

Extension ExtensionOf(Effect e) {
  switch (e) {
    case Effect::kFlowDependentU:
      return Extension::kFlowDependentU;
    case Effect::kTransportDelay:
      return Extension::kTransportDelay;
    case Effect::kPvClipping:
      return Extension::kPvClipping;
    case Effect::kShading:
      return Extension::kShading;
    case Effect::kSoiling:
      return Extension::kSoiling;
    case Effect::kClockOffset:
      return Extension::kClockOffset;
    case Effect::kIrradianceBias:
      return Extension::kIrradianceBias;
    default:
      break;
  }
  return Extension::kCount;
}

// Central difference per minute of a driver, NaN across restarts and gaps.
std::vector<double> RatePerMinute(const Drivers& d, const std::vector<double>& v) {
  const std::size_t n = d.size();
  std::vector<double> out(n, kNaN);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (d.restart[i] || d.restart[i + 1]) continue;
    const double dt_s = static_cast<double>(d.time_s[i + 1] - d.time_s[i - 1]);
    if (dt_s > 0.0) out[i] = (v[i + 1] - v[i - 1]) / dt_s * 60.0;
  }
  return out;
}

}  // namespace

const std::vector<EffectInfo>& EffectTable() {
  static const std::vector<EffectInfo> kTable = BuildTable();
  return kTable;
}

const EffectInfo& Info(Effect e) {
  const auto& table = EffectTable();
  assert(static_cast<std::size_t>(e) < table.size() && "Info: Effect out of range");
  return table[static_cast<std::size_t>(e)];
}

std::optional<Effect> EffectFromName(std::string_view name) {
  for (const EffectInfo& info : EffectTable()) {
    if (info.name == name) return info.effect;
  }
  return std::nullopt;
}

bool HasEffect(const ModelSpec& spec, Effect e) {
  switch (e) {
    case Effect::kCapacitance:
      return spec.c_pv || spec.c_coll;
    case Effect::kSecondNode:
      return spec.nodes == 2;
    case Effect::kWind:
      return spec.wind_paper || spec.Has(Extension::kWind);
    case Effect::kSkyRadiation:
      return spec.sky;
    case Effect::kIam:
      return spec.iam;
    case Effect::kCount:
      return false;
    default:
      return spec.Has(ExtensionOf(e));
  }
}

bool CanAddEffect(const ModelSpec& spec, Effect e, std::string* why_not) {
  std::string reason;
  if (e == Effect::kCapacitance) {
    const bool full = spec.c_pv && (spec.nodes == 1 || spec.c_coll);
    if (full) reason = "every node of " + spec.Name() + " already has a capacitance";
  } else if (HasEffect(spec, e)) {
    reason = spec.Name() + " already has " + std::string(Info(e).name);
  }
  if (reason.empty()) return true;
  if (why_not != nullptr) *why_not = reason;
  return false;
}

bool CanAddEffect(const ModelSpec& spec, Effect e, const Series& data, std::string* why_not) {
  if (!CanAddEffect(spec, e, why_not)) return false;
  std::string reason;
  if (e == Effect::kIrradianceBias) {
    if (!data.Has(Channel::kGhiWM2) || !data.Has(Channel::kDhiWM2)) {
      reason = "not identifiable without a second irradiance source (ghi_w_m2 + dhi_w_m2)";
    } else if (!data.Has(Channel::kGPoaWM2)) {
      reason = "no plane-of-array pyranometer (g_poa_w_m2) whose scale could be in error";
    }
  } else if (e == Effect::kShading) {
    const bool split = (data.Has(Channel::kGPoaWM2) && data.Has(Channel::kGPoaDiffuseWM2)) ||
                       (data.Has(Channel::kGhiWM2) && data.Has(Channel::kDhiWM2));
    if (!split) reason = "needs beam and diffuse (g_poa_diffuse_w_m2, or ghi_w_m2 + dhi_w_m2)";
  } else if (e == Effect::kWind && !data.Has(Channel::kWindMS)) {
    reason = "needs wind_m_s";
  } else if (e == Effect::kSkyRadiation && !data.Has(Channel::kTSkyC) &&
             !data.Has(Channel::kLwDownWM2)) {
    reason = "needs t_sky_c or lw_down_w_m2";
  }
  if (reason.empty()) return true;
  if (why_not != nullptr) *why_not = reason;
  return false;
}

ModelSpec WithEffect(ModelSpec spec, Effect e) {
  switch (e) {
    case Effect::kCapacitance:
      if (spec.nodes == 1) {
        spec.c_pv = true;
      } else if (!spec.c_coll) {
        spec.c_coll = true;
      } else {
        spec.c_pv = true;
      }
      break;
    case Effect::kSecondNode:
      spec.nodes = 2;
      break;
    case Effect::kWind:
      if (!spec.Has(Extension::kWind)) spec.wind_paper = true;
      break;
    case Effect::kSkyRadiation:
      spec.sky = true;
      break;
    case Effect::kIam:
      spec.iam = true;
      break;
    case Effect::kCount:
      break;
    default:
      spec.extensions.set(static_cast<std::size_t>(ExtensionOf(e)));
      break;
  }
  return spec;
}

std::vector<double> EffectSignature(Effect e, const Drivers& d, const SimOutputs& base) {
  const std::size_t n = d.size();
  std::vector<double> out(n, kNaN);
  const double area_m2 = d.plant.area_m2;
  switch (e) {
    case Effect::kCapacitance:
    case Effect::kClockOffset:
      return RatePerMinute(d, d.g_abs_w_m2);
    case Effect::kSecondNode:
      for (std::size_t i = 0; i < n; ++i) out[i] = d.t_in_c[i] - d.t_amb_c[i];
      break;
    case Effect::kWind:
      return d.wind_m_s;
    case Effect::kSkyRadiation:
      for (std::size_t i = 0; i < n; ++i) out[i] = d.t_amb_c[i] - d.t_sky_c[i];
      break;
    case Effect::kIam:
      return d.aoi_rad;
    case Effect::kFlowDependentU:
      for (std::size_t i = 0; i < n; ++i) {
        if (d.mdot_kg_s[i] > 0.0) out[i] = d.mdot_kg_s[i] / (kFlowReferenceKgSM2 * area_m2);
      }
      break;
    case Effect::kTransportDelay:
      if (base.t_out_c.size() == n) return RatePerMinute(d, base.t_out_c);
      break;
    case Effect::kPvClipping:
      if (base.p_el_w.size() == n) {
        for (std::size_t i = 0; i < n; ++i) out[i] = base.p_el_w[i] / area_m2;
      }
      break;
    case Effect::kShading:
      return d.g_beam_w_m2;
    case Effect::kSoiling:
      return d.days_since_clean;
    case Effect::kIrradianceBias:
      for (std::size_t i = 0; i < n; ++i) {
        out[i] = d.g_ref_w_m2[i] - d.g_poa_w_m2[i] / (1.0 + d.irradiance_bias);
      }
      break;
    case Effect::kCount:
      break;
  }
  return out;
}

double EstimateIrradianceBias(const Drivers& d) {
  constexpr double kMinWM2 = 300.0;
  const double max_aoi_rad = DegToRad(60.0);
  std::vector<double> ratios;
  for (std::size_t i = 0; i < d.size(); ++i) {
    // The measured plane-of-array value, before any correction by k.
    const double meas = d.g_poa_w_m2[i] / (1.0 + d.irradiance_bias);
    const double ref = d.g_ref_w_m2[i];
    if (!(meas > kMinWM2 && ref > kMinWM2 && d.aoi_rad[i] < max_aoi_rad)) continue;
    ratios.push_back(ref / meas - 1.0);
  }
  if (ratios.size() < 30) return kNaN;
  const auto mid = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
  std::nth_element(ratios.begin(), mid, ratios.end());
  return *mid;
}

}  // namespace pvtwin
