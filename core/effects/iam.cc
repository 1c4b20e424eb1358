#include "core/effects/iam.h"

#include <algorithm>
#include <cmath>

#include "core/common/units.h"
#include "core/physics/irradiance.h"

namespace pvtwin {

double FresnelCoverTransmittance(double aoi_rad, const FresnelCover& c) {
  const double theta = std::fabs(aoi_rad);
  const double n = c.refractive_index;
  const double kl = c.extinction_per_m * c.thickness_m;
  if (!(theta < 0.5 * kPi)) return 0.0;
  if (theta < 1e-6) {
    const double r = (n - 1.0) / (n + 1.0);
    return std::exp(-kl) * (1.0 - r * r);
  }
  const double theta_r = std::asin(std::sin(theta) / n);
  const double s_minus = std::sin(theta_r - theta), s_plus = std::sin(theta_r + theta);
  const double t_minus = std::tan(theta_r - theta), t_plus = std::tan(theta_r + theta);
  const double r_perp = s_minus * s_minus / (s_plus * s_plus);
  const double r_par = t_minus * t_minus / (t_plus * t_plus);
  return std::exp(-kl / std::cos(theta_r)) * (1.0 - 0.5 * (r_perp + r_par));
}

double FresnelIam(double aoi_rad, const FresnelCover& c) {
  return FresnelCoverTransmittance(aoi_rad, c) / FresnelCoverTransmittance(0.0, c);
}

namespace {

// Other-form truth: I_at = K(θ)·beam + K(θ_sky)·I_dsky + K(θ_gnd)·I_dgd with the
// Fresnel cover's K, the parts from the plant's irradiance (paper 2.5's split)
// and Brandemuehl & Beckman's effective diffuse angles.
void FresnelCoverIam(const OtherTruthContext& ctx, Drivers* d) {
  const Series& s = *ctx.physics;
  const EffectiveDiffuseAngles angles = BrandemuehlBeckmanAngles(ctx.plant->tilt_rad);
  const double k_sky = FresnelIam(angles.sky_rad, kOtherTruthCover);
  const double k_gnd = FresnelIam(angles.ground_rad, kOtherTruthCover);
  const double nan = std::nan("");
  auto at = [&s, nan](Channel c, std::size_t i) { return s.Has(c) ? s[c][i] : nan; };
  for (std::size_t i = 0; i < d->size(); ++i) {
    MeasuredPoaInput in;
    in.g_poa_w_m2 = at(Channel::kGPoaWM2, i);
    in.g_poa_diffuse_w_m2 = at(Channel::kGPoaDiffuseWM2, i);
    in.ghi_w_m2 = at(Channel::kGhiWM2, i);
    in.dhi_w_m2 = at(Channel::kDhiWM2, i);
    in.tilt_rad = ctx.plant->tilt_rad;
    in.ground_albedo = ctx.plant->ground_albedo;
    if (!std::isfinite(in.g_poa_w_m2)) continue;
    const PoaComponents poa = SplitMeasuredPoa(in);
    const double beam =
        poa.beam_w_m2 > 0.0 ? FresnelIam(d->aoi_rad[i], kOtherTruthCover) * poa.beam_w_m2 : 0.0;
    d->g_abs_w_m2[i] = beam + k_sky * poa.sky_diffuse_w_m2 + k_gnd * poa.ground_diffuse_w_m2;
    d->g_beam_w_m2[i] = beam;
  }
}

void RemoveSameForm(ModelSpec* spec) { spec->iam = false; }

const OtherFormTruth& OtherTruth() {
  static const OtherFormTruth kTruth = [] {
    OtherFormTruth t;
    t.form =
        "A glass cover by Snell's and Fresnel's laws with absorption, K(θ) = τ(θ)/τ(0), "
        "τ(θ) = exp(−K·L/cos θ_r)·(1 − (r_⊥ + r_∥)/2), n = 1.526, K = 4 /m, L = 2 mm, "
        "for beam, sky and ground parts at their angles; the candidate is the paper's "
        "Souka & Safwat (ASHRAE b0) form.";
    t.source = "Duffie & Beckman 5.1–5.3; De Soto et al. 2006 eq. 14 (pvlib iam.physical)";
    t.remove_same_form = RemoveSameForm;
    t.drivers = FresnelCoverIam;
    return t;
  }();
  return kTruth;
}

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
    m.other_truth = &OtherTruth();
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
