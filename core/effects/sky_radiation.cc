#include "core/effects/sky_radiation.h"

#include <cmath>
#include <vector>

namespace pvtwin {

namespace {

// T_sky⁴ per row with the cloud offset (SkyK4WithCloudOffset).
void OffsetTheSky(const Drivers& d, const ParamVector& p, RunInputs* run) {
  const double offset = ParamOf(p, Param::kSkyCloudOffset);
  double* t_sky_k4 = run->Own(&run->t_sky_k4);
  for (std::size_t i = 0; i < run->n; ++i) {
    t_sky_k4[i] = SkyK4WithCloudOffset(t_sky_k4[i], CToK(d.t_amb_c[i]), offset);
  }
}

// The broader form's part beyond the letter 'r' (its name is the module's,
// so that "…r+sky_radiation" names and parses to it).
const ModelExtension& OffsetExtension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "sky_radiation";
    e.variant_order = 8;
    e.params = {Param::kSkyCloudOffset};
    e.transform_drivers = OffsetTheSky;
    return e;
  }();
  return kExtension;
}

bool InSpec(const ModelSpec& spec) { return spec.sky; }

// 'r'; on a spec that has it, the broader form (so that "1N1Cwr+sky_radiation"
// parses to the form the diagnosis names so).
void AddToSpec(ModelSpec* spec) {
  if (spec->sky) spec->Add(OffsetExtension());
  spec->sky = true;
}

// The diagnosis's second form: 'r' with the cloud offset.
void AddBroaderForm(ModelSpec* spec) {
  spec->sky = true;
  spec->Add(OffsetExtension());
}

std::string DataLacks(const Series& data) {
  return !data.Has(Channel::kTSkyC) && !data.Has(Channel::kLwDownWM2)
             ? "needs t_sky_c or lw_down_w_m2"
             : "";
}

// T_amb − T_sky, K.
std::vector<double> Signature(const Drivers& d, const SimOutputs&) {
  std::vector<double> out(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) out[i] = d.t_amb_c[i] - d.t_sky_c[i];
  return out;
}

// Other-form truth: the sky the collector exchanges with is Swinbank's clear
// sky with Crawford & Duchon's cloud correction, the cloud fraction from the
// diffuse fraction while GHI > 50 W/m² and held through the night (0.5
// before the first daylight); the logged lw_down_w_m2 / t_sky_c keep the
// weather station's (another model's) values.
void SwinbankCrawfordDuchonSky(const OtherTruthContext& ctx, Series* physics) {
  if (!physics->Has(Channel::kTAmbC) || !physics->Has(Channel::kGhiWM2) ||
      !physics->Has(Channel::kDhiWM2)) {
    return;
  }
  const std::vector<double>& t_amb = (*physics)[Channel::kTAmbC];
  const std::vector<double>& ghi = (*physics)[Channel::kGhiWM2];
  const std::vector<double>& dhi = (*physics)[Channel::kDhiWM2];
  const bool has_lw = physics->Has(Channel::kLwDownWM2);
  const bool has_t_sky = physics->Has(Channel::kTSkyC);
  double cover = 0.5;
  for (std::size_t i = 0; i < physics->size(); ++i) {
    if (ghi[i] > 50.0 && std::isfinite(dhi[i])) {
      cover = CloudFractionFromDiffuseFraction(dhi[i] / ghi[i]);
    }
    const double t_amb_k = CToK(t_amb[i]);
    const double eps = CloudySkyEmissivity(SwinbankClearSkyEmissivity(t_amb_k), cover);
    const double lw_w_m2 = LongWaveOnPlaneWM2(eps, KToC(t_amb_k), ctx.plant->tilt_rad);
    if (has_lw) (*physics)[Channel::kLwDownWM2][i] = lw_w_m2;
    if (has_t_sky) {
      (*physics)[Channel::kTSkyC][i] =
          std::sqrt(std::sqrt(lw_w_m2 / kStefanBoltzmannW_m2k4)) - CToK(0.0);
    }
  }
}

// The long-wave exchange itself ('r') stays.
void KeepTheLetter(ModelSpec*) {}

const OtherFormTruth& OtherTruth() {
  static const OtherFormTruth kTruth = [] {
    OtherFormTruth t;
    t.form =
        "The collector exchanges long-wave with Swinbank's clear sky, ε_clr = 5.31e-13·T_a²/σ, "
        "made cloudy by Crawford & Duchon's ε = c + (1 − c)·ε_clr (c from the diffuse "
        "fraction), on the plane with the ground at air temperature; the logged long-wave "
        "channel, which the candidate reads, follows Brunt's humidity-based sky.";
    t.source = "Swinbank 1963; Crawford & Duchon 1999";
    t.remove_same_form = KeepTheLetter;
    t.weather = SwinbankCrawfordDuchonSky;
    return t;
  }();
  return kTruth;
}

}  // namespace

const EffectModule& SkyRadiationEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = EffectName(Effect::kSkyRadiation);
    m.physics =
        "Long-wave exchange of the front with the sky: ε·σ·(T_PV⁴ − T_sky⁴) (paper "
        "2.9, 'r'). Clear nights and clear days with a cold sky cool the collector below "
        "ambient; the loss scales with the sky temperature deficit. The diagnosis also "
        "fits a broader form, a sky cloudier by Δc_sky than the logged long-wave says "
        "(another sky model or cloud correction; Crawford & Duchon's ε' = ε + Δc·(1 − ε)): "
        "T_sky,eff⁴ = T_sky⁴ + Δc_sky·(T_a⁴ − T_sky⁴).";
    m.source =
        "paper 2.9 (long-wave exchange with the sky); cloudy sky: Crawford & Duchon 1999; "
        "sky models' spread: Flerchinger et al. 2009, Water Resour. Res. 45";
    m.params = EffectParams(Effect::kSkyRadiation);
    m.needs = {Channel::kTSkyC};
    m.typical_truth = {{Param::kEpsPvt, 0.12}};
    m.signature = "ambient minus sky temperature, K";
    m.advice =
        "Use a variant with sky radiation ('r') and log the long-wave irradiance or the "
        "sky temperature; clear nights then cool the model as they cool the collector.";
    m.in_spec = InSpec;
    m.add_to_spec = AddToSpec;
    m.form = "paper";
    m.diagnosis_forms = {{"cloud_offset", AddBroaderForm}};
    m.data_lacks = DataLacks;
    m.signature_values = Signature;
    m.other_truth = &OtherTruth();
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
