#include "core/effects/sky_radiation.h"

namespace pvtwin {

namespace {

bool InSpec(const ModelSpec& spec) { return spec.sky; }

void AddToSpec(ModelSpec* spec) { spec->sky = true; }

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

}  // namespace

const EffectModule& SkyRadiationEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = "sky_radiation";
    m.physics =
        "Long-wave exchange of the front with the sky: ε·σ·(T_PV⁴ − T_sky⁴) (paper "
        "2.9, 'r'). Clear nights and clear days with a cold sky cool the collector below "
        "ambient; the loss scales with the sky temperature deficit.";
    m.source = "paper 2.9 (long-wave exchange with the sky)";
    m.params = {Param::kEpsPvt};
    m.needs = {Channel::kTSkyC};
    m.typical_truth = {{Param::kEpsPvt, 0.12}};
    m.signature = "ambient minus sky temperature, K";
    m.advice =
        "Use a variant with sky radiation ('r') and log the long-wave irradiance or the "
        "sky temperature; clear nights then cool the model as they cool the collector.";
    m.in_spec = InSpec;
    m.add_to_spec = AddToSpec;
    m.data_lacks = DataLacks;
    m.signature_values = Signature;
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
