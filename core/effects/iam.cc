#include "core/effects/iam.h"

namespace pvtwin {

namespace {

bool InSpec(const ModelSpec& spec) { return spec.iam; }

void AddToSpec(ModelSpec* spec) { spec->iam = true; }

std::vector<double> Signature(const Drivers& d, const SimOutputs&) { return d.aoi_rad; }

}  // namespace

const EffectModule& IamEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = "iam";
    m.physics =
        "Incidence-angle modifier: reflection at the glass rises at grazing angles, so "
        "the absorbed irradiance is the beam weighted by K(θ) = 1 − b0·(1/cos θ − 1) "
        "plus sky and ground diffuse at their effective angles (Souka & Safwat; "
        "Brandemuehl & Beckman; paper 2.5, 'I').";
    m.source = "Souka & Safwat (IAM); Brandemuehl & Beckman (effective diffuse angles); paper 2.5";
    m.signature = "beam angle of incidence, rad";
    m.advice =
        "Use a variant with the incidence-angle modifier ('I') and log diffuse irradiance "
        "(g_poa_diffuse_w_m2, or GHI and DHI) so that beam and diffuse can be weighted.";
    m.in_spec = InSpec;
    m.add_to_spec = AddToSpec;
    m.signature_values = Signature;
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
