#include "core/effects/soiling.h"

namespace pvtwin {

namespace {

// I_at · τ_soil.
void SoilTheCover(const Drivers& d, const ParamVector& p, RunInputs* run) {
  const double rate_per_day = ParamOf(p, Param::kSoilingPerDay);
  double* g_abs = run->Own(&run->g_abs_w_m2);
  for (std::size_t i = 0; i < run->n; ++i) {
    g_abs[i] *= SoilingTransmittance(rate_per_day, d.days_since_clean[i]);
  }
}

const ModelExtension& Extension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "soiling";
    e.variant_order = 5;
    e.params = {Param::kSoilingPerDay};
    e.transform_drivers = SoilTheCover;
    return e;
  }();
  return kExtension;
}

std::vector<double> Signature(const Drivers& d, const SimOutputs&) { return d.days_since_clean; }

}  // namespace

const EffectModule& SoilingEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = "soiling";
    m.physics =
        "Dust and pollen on the front cover reduce its transmittance roughly linearly "
        "with the days since the last rain or cleaning: τ_soil = max(0, 1 − r_soil·d) "
        "multiplies the absorbed irradiance, so P_el and Q_u both drift down over the "
        "weeks (Kimber et al. 2006, linear soiling rate). Cleanings reset d "
        "(SetCleaningTimes); without a known cleaning d counts from the first row.";
    m.source =
        "Kimber et al. 2006, the effects of soiling on large grid-connected PV systems (linear "
        "soiling rate)";
    m.params = {Param::kSoilingPerDay};
    m.typical_truth = {{Param::kSoilingPerDay, 0.004}};
    m.signature = "days since the last cleaning";
    m.advice =
        "Clean the collector front and log cleanings and heavy rain; the loss grows by "
        "r_soil per day until then.";
    m.extension = &Extension();
    m.signature_values = Signature;
    // A drift over days is not seen within fewer than three training days.
    m.min_train_days = 3;
    m.min_train_days_why = "to see a drift over days";
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
