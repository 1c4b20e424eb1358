#include "core/effects/irradiance_bias.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "core/common/text.h"
#include "core/common/units.h"

namespace pvtwin {

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
  if (ratios.size() < 30) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
  std::nth_element(ratios.begin(), mid, ratios.end());
  return *mid;
}

namespace {

// k from the two sources; the model then uses (1 + k)·G_meas for the plane
// sensor's irradiance (and a beam derived from it).
bool CalibrateThePlaneSensor(const Series& s, Drivers* d, std::string* error) {
  const double k = EstimateIrradianceBias(*d);
  if (std::isnan(k)) {
    *error = "variant " + d->spec.Name() +
             ": irradiance_bias needs at least 30 rows where g_poa_w_m2 and the transposed "
             "ghi_w_m2 + dhi_w_m2 both exceed 300 W/m² at an angle of incidence below 60°";
    return false;
  }
  d->irradiance_bias = k;
  const bool beam_from_poa = s.Has(Channel::kGPoaDiffuseWM2);
  for (std::size_t i = 0; i < d->size(); ++i) {
    d->g_poa_w_m2[i] *= 1.0 + k;
    d->g_abs_w_m2[i] *= 1.0 + k;
    if (beam_from_poa) d->g_beam_w_m2[i] *= 1.0 + k;
  }
  return true;
}

const ModelExtension& Extension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "irradiance_bias";
    e.variant_order = 7;
    // k is calibrated from the two irradiance sources when the drivers are
    // prepared, not fitted: P_el and Q_u alone cannot separate it from
    // η_PV·F_th.
    e.params = {};
    e.inputs = {{"plane-of-array and a second irradiance source (irradiance_bias)",
                 {{Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2}}}};
    e.prepare_drivers = CalibrateThePlaneSensor;
    return e;
  }();
  return kExtension;
}

std::string DataLacks(const Series& data) {
  if (!data.Has(Channel::kGhiWM2) || !data.Has(Channel::kDhiWM2)) {
    return "not identifiable without a second irradiance source (ghi_w_m2 + dhi_w_m2)";
  }
  if (!data.Has(Channel::kGPoaWM2)) {
    return "no plane-of-array pyranometer (g_poa_w_m2) whose scale could be in error";
  }
  return "";
}

// Transposed GHI/DHI minus the measured plane-of-array irradiance, W/m².
std::vector<double> Signature(const Drivers& d, const SimOutputs&) {
  std::vector<double> out(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    out[i] = d.g_ref_w_m2[i] - d.g_poa_w_m2[i] / (1.0 + d.irradiance_bias);
  }
  return out;
}

std::string SensorEvidence(double k, double p, int days) {
  std::ostringstream p_text;
  p_text.precision(2);
  p_text << p;
  std::ostringstream ev;
  ev << "against GHI/DHI transposed to the plane, the plane-of-array pyranometer reads "
     << FixedDecimals(100.0 * std::fabs(k), 1) << " % " << (k > 0 ? "low" : "high")
     << " (median over " << days << " days, two-sided Wilcoxon p = " << p_text.str()
     << "); η_PV and F_th absorb such a scale error, so "
     << "the held-out error barely moves; ";
  return ev.str();
}

// The faulty sensor reads G_true / (1 + k) in the plane.
void ApplySensorError(const ParamVector& truth, Series* s) {
  const double k = ParamOf(truth, Param::kIrradianceBias);
  for (Channel c : {Channel::kGPoaWM2, Channel::kGPoaDiffuseWM2}) {
    if (!s->Has(c)) continue;
    for (double& g : (*s)[c]) g /= 1.0 + k;
  }
}

// Other-form truth: the plane-of-array pyranometer reads (f(θ)·B + D)/(1 + k)
// + a, the shaded in-plane diffuse sensor D/(1 + k) + a (no beam).
void CosineOffsetAndScale(const OtherTruthContext& ctx, const Drivers& d, Series* s) {
  const double k = ParamOf(*ctx.truth, Param::kIrradianceBias);
  const PyranometerErrors& e = kOtherTruthPyranometer;
  if (!s->Has(Channel::kGPoaWM2)) return;
  const bool has_diffuse = s->Has(Channel::kGPoaDiffuseWM2);
  for (std::size_t i = 0; i < s->size(); ++i) {
    const double global = (*s)[Channel::kGPoaWM2][i];
    const double diffuse = has_diffuse ? (*s)[Channel::kGPoaDiffuseWM2][i] : 0.0;
    if (!std::isfinite(global) || !std::isfinite(diffuse)) continue;
    const double beam = std::max(0.0, global - diffuse);
    (*s)[Channel::kGPoaWM2][i] = PyranometerReadingWM2(beam, global - beam, d.aoi_rad[i], k, e);
    if (has_diffuse) {
      (*s)[Channel::kGPoaDiffuseWM2][i] = PyranometerReadingWM2(0.0, diffuse, 0.0, k, e);
    }
  }
}

const OtherFormTruth& OtherTruth() {
  static const OtherFormTruth kTruth = [] {
    OtherFormTruth t;
    t.form =
        "The plane-of-array pyranometer reads G_meas = (f(θ)·B + D)/(1 + k) + a with a "
        "cosine error f(θ) = 1 − 0.11·(θ/80°)³ on the beam and a zero offset a = −8 W/m² "
        "by day besides the scale error k = 6 %; the candidate is the scale error alone.";
    t.source = "ISO 9060:2018 (directional response at 80°, zero offset a)";
    t.measured = CosineOffsetAndScale;
    return t;
  }();
  return kTruth;
}

// "The in-plane pyranometer reads 6 % high: …".
std::string PyranometerAdvice(const ModelSpec&, const ParamVector& p, const Plant&) {
  const double k = ParamOf(p, Param::kIrradianceBias);
  return "The in-plane pyranometer reads " + FixedDecimals(100.0 * std::fabs(k), 1) + " % " +
         (k >= 0.0 ? "high" : "low") + " against GHI/DHI: clean, level and recalibrate it.";
}
}  // namespace

const EffectModule& IrradianceBiasEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = EffectName(Effect::kIrradianceBias);
    m.physics =
        "The plane-of-array pyranometer reads with a scale error, G_true = G_meas·(1 + k) "
        "(calibration drift, soiled dome, misalignment). From P_el and Q_u alone k is "
        "indistinguishable from η_PV·F_th; with the weather station's GHI and DHI "
        "transposed to the plane (isotropic sky, paper 2.5) as a second source, k is the "
        "median of G_ref/G_meas − 1 over bright rows at moderate incidence, and the model "
        "uses (1 + k)·G_meas, keeping the plane sensor's time resolution. The fit then "
        "returns unbiased η_PV and F_th.";
    m.source = "paper 2.5 (isotropic-sky transposition of GHI/DHI as the second source)";
    m.params = EffectParams(Effect::kIrradianceBias);
    m.needs = {Channel::kGhiWM2, Channel::kDhiWM2};
    m.typical_truth = {{Param::kIrradianceBias, 0.06}};
    // A pyranometer knocked out of level, soiled or exchanged.
    m.begins_in_operation = true;
    m.signature = "transposed GHI/DHI minus measured plane-of-array irradiance, W/m²";
    m.advice =
        "Clean, level and recalibrate the plane-of-array pyranometer (or compare it with a "
        "reference); until then the fitted η_PV and F_th carry its scale error.";
    m.extension = &Extension();
    m.advice_for = PyranometerAdvice;
    m.data_lacks = DataLacks;
    m.signature_values = Signature;
    m.sensor_estimate = EstimateIrradianceBias;
    m.sensor_evidence = SensorEvidence;
    m.apply_sensor_error = ApplySensorError;
    m.other_truth = &OtherTruth();
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
