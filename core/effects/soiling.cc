#include "core/effects/soiling.h"

#include "core/common/calendar.h"
#include "core/common/text.h"

namespace pvtwin {

bool RainOnDay(std::uint64_t seed, std::int64_t day, const SoilingWithRain& soiling) {
  return UnitDraw(seed ^ 0x4A1Bull, day) < soiling.rain_probability_per_day;
}

std::vector<double> SoilingTransmittanceWithRain(const std::vector<std::int64_t>& time_s,
                                                 const SoilingWithRain& soiling,
                                                 std::uint64_t seed) {
  std::vector<double> tau(time_s.size(), 1.0);
  if (time_s.empty()) return tau;
  double loss = 0.0;  // at `since_s`
  std::int64_t since_s = time_s.front();
  std::int64_t day = time_s.front() / kSecondsPerDay;
  auto advance = [&](std::int64_t to_s) {
    const double days = static_cast<double>(to_s - since_s) / kSecondsPerDay;
    loss = SaturatingSoilingLoss(loss, days, soiling.max_loss, soiling.time_constant_days);
    since_s = to_s;
  };
  for (std::size_t i = 0; i < time_s.size(); ++i) {
    while (time_s[i] / kSecondsPerDay > day) {
      ++day;
      if (!RainOnDay(seed, day, soiling)) continue;
      advance(day * kSecondsPerDay);
      loss = SoilingLossAfterRain(loss, soiling.cleaned_share);
    }
    advance(time_s[i]);
    tau[i] = 1.0 - loss;
  }
  return tau;
}

namespace {

// Other-form truth: I_at·τ_soil(t) with the saturating, rain-washed loss.
void SoilAndRain(const OtherTruthContext& ctx, Drivers* d) {
  const std::vector<double> tau =
      SoilingTransmittanceWithRain(d->time_s, kOtherTruthSoiling, ctx.seed);
  for (std::size_t i = 0; i < d->size(); ++i) {
    d->g_abs_w_m2[i] *= tau[i];
    d->g_beam_w_m2[i] *= tau[i];
  }
}

const OtherFormTruth& OtherTruth() {
  static const OtherFormTruth kTruth = [] {
    OtherFormTruth t;
    t.form =
        "Soiling saturates, L(d) = L_max − (L_max − L0)·exp(−d/τ_s) with L_max = 10 %, "
        "τ_s = 8 d, and a rain at the start of a drawn day (probability 0.1 per day) washes "
        "off 60 % of it, L ← 0.4·L; τ_soil = 1 − L multiplies the absorbed irradiance. The "
        "candidate's loss is linear in the days since the last known cleaning.";
    t.source = "Hegazy 2001 (saturating dust deposit); Kimber et al. 2006 (rain cleaning)";
    t.drivers = SoilAndRain;
    return t;
  }();
  return kTruth;
}

// I_at · τ_soil.
void SoilTheCover(const Drivers& d, const ParamVector& p, RunInputs* run) {
  const double rate_per_day = ParamOf(p, Param::kSoilingPerDay);
  double* g_abs = run->Own(&run->g_abs_w_m2);
  const bool recovered = d.soiling_recovered.size() == run->n;
  for (std::size_t i = 0; i < run->n; ++i) {
    g_abs[i] *= SoilingTransmittance(rate_per_day, d.days_since_clean[i],
                                     recovered ? d.soiling_recovered[i] : 0.0);
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

// "The front loses 0.4 % of its transmittance per day: …".
std::string SoilingAdvice(const ModelSpec&, const ParamVector& p, const Plant&) {
  return "The front loses " + FixedDecimals(100.0 * ParamOf(p, Param::kSoilingPerDay), 2) +
         " % of its transmittance per day: clean it, and log cleanings and heavy rain.";
}
}  // namespace

const EffectModule& SoilingEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = EffectName(Effect::kSoiling);
    m.physics =
        "Dust and pollen on the front cover reduce its transmittance roughly linearly "
        "with the days since the last rain or cleaning: τ_soil = max(0, 1 − r_soil·d) "
        "multiplies the absorbed irradiance, so P_el and Q_u both drift down over the "
        "weeks (Kimber et al. 2006, linear soiling rate). Cleanings reset d "
        "(SetCleaningTimes); without a known cleaning d counts from the first row. A rain "
        "or a washing that the data show (the daily performance index P_el/I_gt at the "
        "measured module temperature recovers by more than 2 % and four robust standard "
        "deviations of its day-to-day changes, and stays up) lowers the loss by the "
        "recovery measured: τ_soil = 1 − max(0, r_soil·d − Σ recoveries).";
    m.source =
        "Kimber et al. 2006, the effects of soiling on large grid-connected PV systems (linear "
        "soiling rate); Deceglie et al. 2018, IEEE J. Photovolt. 8 (stochastic rate and "
        "recovery: cleanings from the performance index)";
    m.params = EffectParams(Effect::kSoiling);
    m.typical_truth = {{Param::kSoilingPerDay, 0.004}};
    // Dust after a dry spell, pollen, a nearby building site.
    m.begins_in_operation = true;
    m.signature = "days since the last cleaning";
    m.advice =
        "Clean the collector front and log cleanings and heavy rain; the loss grows by "
        "r_soil per day until then.";
    m.extension = &Extension();
    m.advice_for = SoilingAdvice;
    m.signature_values = Signature;
    // A drift over days is not seen within fewer than three training days.
    m.min_train_days = 3;
    m.min_train_days_why = "to see a drift over days";
    m.other_truth = &OtherTruth();
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
