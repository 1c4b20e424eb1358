#include "core/effects/wind.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/physics/wind.h"

namespace pvtwin {

namespace {

// U_front(v) = U_front + c_wind·v^n_wind per row, W/(m²K)
// (FrontConductanceConvectiveWM2K; ln v from the run's wind driver).
void FrontLossPerRow(const Drivers&, const ParamVector& p, RunInputs* run) {
  std::vector<double>& u = run->Scratch();
  u.resize(run->n);
  const double u_front_w_m2k = ParamOf(p, Param::kUFrontWM2K);
  const double u_wind_w_m2k = ParamOf(p, Param::kUWindWM2K);
  const double n_wind = ParamOf(p, Param::kNWind);
  for (std::size_t i = 0; i < run->n; ++i) {
    u[i] = FrontConductanceConvectiveWM2K(u_front_w_m2k, u_wind_w_m2k,
                                          WindPower(run->ln_wind[i], n_wind));
  }
  run->u_front_w_m2k = u.data();
}

const ModelExtension& Extension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "wind";
    e.variant_order = 0;
    e.params = {Param::kUWindWM2K, Param::kNWind};
    e.reads_base_params = {Param::kUFrontWM2K};
    e.reads_wind = true;
    e.transform_drivers = FrontLossPerRow;
    return e;
  }();
  return kExtension;
}

bool InSpec(const ModelSpec& spec) { return spec.wind_paper || spec.Has(Extension()); }

// The paper's form 'w', unless the physical form is present.
void AddToSpec(ModelSpec* spec) {
  if (!spec->Has(Extension())) spec->wind_paper = true;
}

// The physical form "+wind" in place of the paper's 'w' (the diagnosis
// fits both: the printed form can only lower the front loss as the wind
// rises, forced convection raises it).
void AddPhysicalForm(ModelSpec* spec) {
  spec->wind_paper = false;
  spec->Add(Extension());
}

std::string DataLacks(const Series& data) {
  return data.Has(Channel::kWindMS) ? "" : "needs wind_m_s";
}

std::vector<double> Signature(const Drivers& d, const SimOutputs&) { return d.wind_m_s; }

// Other-form truth: U_front(v) per row from Test et al.'s correlation (calm
// where the wind is not measured).
void TestEtAlFront(const OtherTruthContext& ctx, const Drivers& d, RunInputs* run) {
  const double u_front_w_m2k = ParamOf(*ctx.truth, Param::kUFrontWM2K);
  std::vector<double>& u = run->Scratch();
  u.resize(run->n);
  for (std::size_t i = 0; i < run->n; ++i) {
    const double v = std::isfinite(d.wind_m_s[i]) ? std::max(0.0, d.wind_m_s[i]) : 0.0;
    u[i] = FrontConductanceTestWM2K(u_front_w_m2k, v);
  }
  run->u_front_w_m2k = u.data();
}

void RemoveSameForm(ModelSpec* spec) {
  spec->wind_paper = false;
  spec->Remove(Extension());
}

const OtherFormTruth& OtherTruth() {
  static const OtherFormTruth kTruth = [] {
    OtherFormTruth t;
    t.form =
        "The front loses U_front + h_w(v) − h_w(0) with Test et al.'s h_w = 8.55 + 2.56·v "
        "W/(m²K): convection rising linearly with the wind; the candidate is the paper's "
        "printed form 1/(1/U_front + r_refwind·v^n).";
    t.source = "Test, Lessmann & Johary 1981, J. Heat Transfer 103";
    t.remove_same_form = RemoveSameForm;
    t.run = TestEtAlFront;
    return t;
  }();
  return kTruth;
}

}  // namespace

const EffectModule& WindEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = EffectName(Effect::kWind);
    m.physics =
        "Forced convection on the uncovered front: the front loss conductance depends on "
        "the wind speed, in the paper's printed form 1/U = 1/U_front + r_refwind·v^n "
        "(paper 2.8, 'w') or in the physical form U = U_front + c_wind·v^n ('+wind', rising "
        "with the wind as forced convection does); the diagnosis fits both and keeps the "
        "one that fits the training days better.";
    m.source =
        "paper 2.8 ('w'); ISO 9806:2017 quasi-dynamic model, wind term (c6, c3·u) for '+wind'";
    // The paper's form ('w') first, then the physical form's coefficient.
    m.params = EffectParams(Effect::kWind);
    m.needs = {Channel::kWindMS};
    m.typical_truth = {{Param::kRRefWind, 0.02}, {Param::kNWind, 0.8}};
    m.signature = "wind speed, m/s";
    m.advice =
        "Use a variant with wind (the form the report's variant names: 'w' or '+wind') and "
        "keep the anemometer near the collector plane; forecasts then need a wind forecast.";
    m.extension = &Extension();
    m.in_spec = InSpec;
    m.add_to_spec = AddToSpec;
    m.form = "paper";
    m.diagnosis_forms = {{"physical", AddPhysicalForm}};
    m.data_lacks = DataLacks;
    m.signature_values = Signature;
    m.other_truth = &OtherTruth();
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
