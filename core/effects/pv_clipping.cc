#include "core/effects/pv_clipping.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/common/text.h"
#include "core/physics/pv_efficiency.h"

namespace pvtwin {

namespace {

// P_el = min(P_dc, P_limit·A); the model keeps the clipped power as heat
// (RunInputs::electric_effects).
void InverterLimit(const Drivers&, const ParamVector& p, RunInputs* run) {
  run->p_limit_w = ParamOf(p, Param::kPLimitWM2) * ParamOf(p, Param::kAreaM2);
  run->electric_effects = true;
}

const ModelExtension& Extension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "pv_clipping";
    e.variant_order = 3;
    e.params = {Param::kPLimitWM2};
    e.reads_base_params = {Param::kAreaM2};
    e.transform_drivers = InverterLimit;
    return e;
  }();
  return kExtension;
}

// Other-form truth: P_el = SoftKnee(P_dc, P_lim(T_amb)) with P_dc = η(T_PV)·A·I_at
// at the previous pass's T_PV (a fixed point over the passes); the power not
// converted stays as heat (RunInputs::electric_effects), as in the candidate.
void SoftKneeAndDerating(const OtherTruthContext& ctx, const Drivers& d, RunInputs* run) {
  if (ctx.previous == nullptr) return;  // the first pass finds P_dc
  const ParamVector& p = *ctx.truth;
  const PvEfficiencyParams pv{ParamOf(p, Param::kEtaPvRef), ParamOf(p, Param::kPvTempCoeffPerK),
                              ParamOf(p, Param::kPvIrrCoeffM2W), d.plant.pv_t_ref_c,
                              d.plant.pv_g_ref_w_m2};
  const double area_m2 = ParamOf(p, Param::kAreaM2);
  const SoftInverter& inv = kOtherTruthInverter;
  std::vector<double>& factor = run->Scratch();
  factor.assign(run->n, 1.0);
  for (std::size_t i = 0; i < run->n; ++i) {
    const double t_pv_c = ctx.previous->t_pv_c[i];
    if (!std::isfinite(t_pv_c)) continue;
    const double base = run->pv_factor != nullptr ? run->pv_factor[i] : 1.0;
    const double p_dc_w =
        PvEfficiencyAt(pv, run->g_poa_w_m2[i]).At(t_pv_c) * area_m2 * run->g_abs_w_m2[i] * base;
    const double limit_w = DeratedLimitW(inv.limit_w_m2 * area_m2, run->t_amb_c[i],
                                         inv.derate_from_c, inv.derate_per_k);
    factor[i] =
        base * (p_dc_w > 0.0 ? SoftKneeAcPowerW(p_dc_w, limit_w, inv.sharpness) / p_dc_w : 1.0);
  }
  run->pv_factor = factor.data();
  run->electric_effects = true;
}

const OtherFormTruth& OtherTruth() {
  static const OtherFormTruth kTruth = [] {
    OtherFormTruth t;
    t.form =
        "A soft knee instead of a hard clip, P_ac = P_dc/(1 + (P_dc/P_lim)^m)^(1/m) with "
        "m = 8, and a limit derated with the ambient temperature, P_lim(T) = 120 W/m²·A·"
        "(1 − 0.01/K·max(0, T_amb − 25 °C)); the power not converted stays as heat.";
    t.source = "p-norm smooth minimum (soft limiter); inverter data sheets' linear derating";
    t.run = SoftKneeAndDerating;
    t.passes = 3;
    return t;
  }();
  return kTruth;
}

// Base model P_el per m².
std::vector<double> Signature(const Drivers& d, const SimOutputs& base) {
  std::vector<double> out(d.size(), std::numeric_limits<double>::quiet_NaN());
  if (base.p_el_w.size() == d.size()) {
    for (std::size_t i = 0; i < d.size(); ++i) out[i] = base.p_el_w[i] / d.plant.area_m2;
  }
  return out;
}

// A clipping inverter shows a plateau: on the rows the fitted model clips
// (at least 30 and 1 % of the rows),
// the measured P_el sits at the fitted limit (median deviation ≤ 5 % of it,
// room for a soft knee and temperature derating), and the measured P_el
// hardly ever exceeds it (≤ 2 % of the rows above 1.05 × the limit).
SignatureCheck Plateau(const SignatureData& d) {
  SignatureCheck c;
  const double limit_w = ParamOf(*d.params, Param::kPLimitWM2) * d.drivers->plant.area_m2;
  std::vector<double> deviation;
  std::size_t above = 0;
  for (std::uint32_t i : *d.rows) {
    const double meas = (*d.p_el_meas_w)[i];
    if (meas > 1.05 * limit_w) ++above;
    if (d.after->p_el_w[i] >= 0.999 * limit_w) deviation.push_back(std::fabs(meas - limit_w));
  }
  const double share_above = static_cast<double>(above) / std::max<std::size_t>(1, d.rows->size());
  if (deviation.size() < std::max<std::size_t>(30, d.rows->size() / 100)) {
    c.shown = false;
    c.sentence = "the fitted limit " + FixedDecimals(limit_w, 0) + " W is reached on " +
                 std::to_string(deviation.size()) + " held-out rows only: no plateau to see";
    return c;
  }
  std::nth_element(deviation.begin(), deviation.begin() + deviation.size() / 2, deviation.end());
  const double median_share = deviation[deviation.size() / 2] / limit_w;
  c.shown = median_share <= 0.05 && share_above <= 0.02;
  c.sentence = std::string(c.shown ? "" : "no ") + "plateau of measured P_el at the fitted limit " +
               FixedDecimals(limit_w, 0) + " W: median |P_el − limit| " +
               FixedDecimals(100.0 * median_share, 1) + " % of it on the " +
               std::to_string(deviation.size()) + " clipped rows, " +
               FixedDecimals(100.0 * share_above, 1) + " % of all rows above 1.05 × the limit";
  return c;
}

// "Inverter limit ≈ 216 W (120 W/m²): …".
std::string LimitAdvice(const ModelSpec&, const ParamVector& p, const Plant& plant) {
  const double limit_w_m2 = ParamOf(p, Param::kPLimitWM2);
  return "Inverter limit ≈ " + FixedDecimals(limit_w_m2 * plant.area_m2, 0) + " W (" +
         FixedDecimals(limit_w_m2, 0) + " W/m²): check the inverter's AC rating against the array.";
}
}  // namespace

const EffectModule& PvClippingEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = EffectName(Effect::kPvClipping);
    m.physics =
        "The inverter or MPPT limits the AC power: P_el = min(P_dc, P_limit). A PVT "
        "module whose electricity is clipped moves its operating point away from the "
        "maximum power point, so the unconverted power stays in the laminate as heat: "
        "the node balance gets Q_abs = F_th·(A·I_at − P_el), which raises T_PV and Q_u "
        "while clipping.";
    m.source =
        "Dobos 2014, PVWatts Version 5 Manual (NREL/TP-6A20-62641): P_ac = min(P_dc·η, P_ac0)";
    m.params = EffectParams(Effect::kPvClipping);
    m.typical_truth = {{Param::kPLimitWM2, 120.0}};
    // An inverter replaced, re-rated or set to a feed-in limit.
    m.begins_in_operation = true;
    m.signature = "base model P_el per m² (evidence above the limit)";
    m.advice =
        "Check the inverter's AC limit against the array: clipped electricity stays in "
        "the collector as heat; model it with +pv_clipping.";
    m.extension = &Extension();
    m.advice_for = LimitAdvice;
    m.signature_values = Signature;
    m.shows_signature = Plateau;
    m.other_truth = &OtherTruth();
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
