#include "core/effects/shading.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "core/common/calendar.h"
#include "core/common/text.h"
#include "core/common/units.h"

namespace pvtwin {

double ShadedFraction(double sun_azimuth_rad, double sun_elevation_rad, double centre_rad,
                      double width_rad, double edge_elevation_rad) {
  if (!(sun_elevation_rad > 0.0)) return 0.0;
  constexpr double kEdgeRad = 2.0 * kPi / 180.0;
  double diff = std::fabs(std::remainder(sun_azimuth_rad - centre_rad, 2.0 * kPi));
  auto logistic = [](double x) { return 1.0 / (1.0 + std::exp(-x)); };
  return logistic((0.5 * width_rad - diff) / kEdgeRad) *
         logistic((edge_elevation_rad - sun_elevation_rad) / kEdgeRad);
}

double HorizonElevationRad(const HorizonProfile& p, double azimuth_rad) {
  const std::vector<double>& az = p.azimuth_rad;
  const std::vector<double>& el = p.elevation_rad;
  if (az.empty() || azimuth_rad < az.front() || azimuth_rad > az.back()) return 0.0;
  double best = 0.0;
  bool found = false;
  for (std::size_t k = 0; k + 1 < az.size(); ++k) {
    if (azimuth_rad < az[k] || azimuth_rad > az[k + 1]) continue;
    const double span = az[k + 1] - az[k];
    const double h = span > 0.0 ? el[k] + (el[k + 1] - el[k]) * (azimuth_rad - az[k]) / span
                                : std::max(el[k], el[k + 1]);
    best = found ? std::max(best, h) : h;
    found = true;
  }
  return found ? best : el.front();
}

double HorizonBeamShare(const HorizonProfile& p, double sun_azimuth_rad, double sun_elevation_rad,
                        double edge_width_rad) {
  if (!(sun_elevation_rad > 0.0)) return 0.0;
  const double h = HorizonElevationRad(p, sun_azimuth_rad);
  if (!(h > 0.0)) return 0.0;
  return std::clamp((h - sun_elevation_rad) / edge_width_rad + 0.5, 0.0, 1.0);
}

double HorizonDiffuseShare(const HorizonProfile& p) {
  double integral = 0.0;
  for (std::size_t k = 0; k + 1 < p.azimuth_rad.size(); ++k) {
    const double span = p.azimuth_rad[k + 1] - p.azimuth_rad[k];
    const double h0 = p.elevation_rad[k], h1 = p.elevation_rad[k + 1];
    if (!(span > 0.0)) continue;
    if (std::fabs(h1 - h0) < 1e-12) {
      integral += span * std::sin(h0) * std::sin(h0);
    } else {
      integral += 0.5 * span - span * (std::sin(2.0 * h1) - std::sin(2.0 * h0)) / (4.0 * (h1 - h0));
    }
  }
  return integral / (2.0 * kPi);
}

const HorizonObstacle& OtherTruthObstacle() {
  static const HorizonObstacle kObstacle = [] {
    HorizonObstacle o;
    for (const auto& [az_deg, el_deg] : std::vector<std::pair<double, double>>{
             {235, 0}, {245, 30}, {258, 45}, {272, 40}, {288, 22}, {300, 0}}) {
      o.profile.azimuth_rad.push_back(DegToRad(az_deg));
      o.profile.elevation_rad.push_back(DegToRad(el_deg));
    }
    o.edge_width_rad = DegToRad(1.5);
    o.day_probability = 0.5;
    return o;
  }();
  return kObstacle;
}

bool ObstacleOnDay(std::uint64_t seed, std::int64_t day) {
  return UnitDraw(seed ^ 0x5AD1A6ull, day) < OtherTruthObstacle().day_probability;
}

namespace {

// Other-form truth: on the obstacle's days I_at loses s·I_beam + f_d·I_dsky
// (the sky part from the plant's DHI, paper 2.5); P_el follows I_at (no
// bypass-diode mismatch term).
void HorizonOnSomeDays(const OtherTruthContext& ctx, Drivers* d) {
  const HorizonObstacle& o = OtherTruthObstacle();
  const double diffuse_share = HorizonDiffuseShare(o.profile);
  const double sky_view = 0.5 * (1.0 + std::cos(ctx.plant->tilt_rad));
  const bool has_dhi = ctx.physics->Has(Channel::kDhiWM2);
  for (std::size_t i = 0; i < d->size(); ++i) {
    const std::int64_t day = d->time_s[i] / kSecondsPerDay;
    if (!ObstacleOnDay(ctx.seed, day)) continue;
    const double s = HorizonBeamShare(o.profile, d->sun_azimuth_rad[i], d->sun_elevation_rad[i],
                                      o.edge_width_rad);
    const double beam = std::isfinite(d->g_beam_w_m2[i]) ? d->g_beam_w_m2[i] : 0.0;
    const double dhi = has_dhi ? (*ctx.physics)[Channel::kDhiWM2][i] : 0.0;
    const double sky = std::isfinite(dhi) ? std::max(0.0, sky_view * dhi) : 0.0;
    d->g_abs_w_m2[i] = std::max(0.0, d->g_abs_w_m2[i] - s * beam - diffuse_share * sky);
    if (std::isfinite(d->g_beam_w_m2[i])) d->g_beam_w_m2[i] -= s * beam;
  }
}

const OtherFormTruth& OtherTruth() {
  static const OtherFormTruth kTruth = [] {
    OtherFormTruth t;
    t.form =
        "A horizon profile (polygon in azimuth × elevation: 235–300°, up to 45° at 258°) "
        "with a linear penumbra of 1.5° blocks the beam, s = clamp((h(γ_sun) − α_sun)/w + "
        "1/2, 0, 1), and the share f_d = (1/2π)∫sin²h dγ of the sky diffuse, on drawn days "
        "only (probability 0.5 per day); P_el follows the absorbed irradiance.";
    t.source = "Dozier & Frew 1990 (sky view factor from the horizon angle)";
    t.drivers = HorizonOnSomeDays;
    return t;
  }();
  return kTruth;
}

// I_at loses s·I_beam; P_el is multiplied by (1 − f_mismatch·s), the power
// not converted staying as heat (RunInputs::electric_effects).
void ShadeTheBeam(const Drivers& d, const ParamVector& p, RunInputs* run) {
  const double centre = ParamOf(p, Param::kShadeAzimuthRad);
  const double width = ParamOf(p, Param::kShadeWidthRad);
  const double edge = ParamOf(p, Param::kShadeElevationRad);
  const double mismatch = ParamOf(p, Param::kShadeMismatch);
  double* g_abs = run->Own(&run->g_abs_w_m2);
  std::vector<double>& factor = run->Scratch();
  factor.resize(run->n);
  for (std::size_t i = 0; i < run->n; ++i) {
    const double s =
        ShadedFraction(d.sun_azimuth_rad[i], d.sun_elevation_rad[i], centre, width, edge);
    const double beam = std::isfinite(run->g_beam_w_m2[i]) ? run->g_beam_w_m2[i] : 0.0;
    g_abs[i] -= s * beam;
    factor[i] = 1.0 - mismatch * s;
  }
  run->pv_factor = factor.data();
  run->electric_effects = true;
}

const ModelExtension& Extension() {
  static const ModelExtension kExtension = [] {
    ModelExtension e;
    e.name = "shading";
    e.variant_order = 4;
    e.params = {Param::kShadeAzimuthRad, Param::kShadeWidthRad, Param::kShadeElevationRad,
                Param::kShadeMismatch};
    e.inputs = {
        {"beam/diffuse irradiance (shading)",
         {{Channel::kGPoaWM2, Channel::kGPoaDiffuseWM2}, {Channel::kGhiWM2, Channel::kDhiWM2}}}};
    e.transform_drivers = ShadeTheBeam;
    return e;
  }();
  return kExtension;
}

// An obstacle shades the same sun positions every day: the improvement of
// the fit lies on the rows the fitted obstacle reaches (shaded fraction ≥
// 0.1; at least half of the improvement) and recurs there on at least two
// days.
SignatureCheck RecursAtTheSameSunPosition(const SignatureData& d) {
  const ParamVector& p = *d.params;
  const Drivers& dr = *d.drivers;
  const double solar_offset_s = dr.plant.longitude_rad / (2.0 * kPi) * 86400.0;
  std::map<std::int64_t, double> by_day;
  double total = 0.0, shaded = 0.0;
  std::size_t shaded_rows = 0;
  for (std::uint32_t i : *d.rows) {
    const double gain = std::fabs(d.before->p_el_w[i] - (*d.p_el_meas_w)[i]) +
                        std::fabs(d.before->q_th_w[i] - (*d.q_th_meas_w)[i]) -
                        std::fabs(d.after->p_el_w[i] - (*d.p_el_meas_w)[i]) -
                        std::fabs(d.after->q_th_w[i] - (*d.q_th_meas_w)[i]);
    if (!std::isfinite(gain)) continue;
    total += gain;
    const double s = ShadedFraction(
        dr.sun_azimuth_rad[i], dr.sun_elevation_rad[i], ParamOf(p, Param::kShadeAzimuthRad),
        ParamOf(p, Param::kShadeWidthRad), ParamOf(p, Param::kShadeElevationRad));
    if (s < 0.1) continue;
    ++shaded_rows;
    shaded += gain;
    const auto day = static_cast<std::int64_t>(
        std::floor((static_cast<double>(dr.time_s[i]) + solar_offset_s) / 86400.0));
    by_day[day] += gain;
  }
  int days = 0;
  for (const auto& [day, gain] : by_day) days += gain > 0.0 ? 1 : 0;
  SignatureCheck c;
  const double share = total > 0.0 ? shaded / total : 0.0;
  c.shown = days >= 2 && share >= 0.5;
  c.sentence = "the fitted obstacle (azimuth " +
               FixedDecimals(RadToDeg(ParamOf(p, Param::kShadeAzimuthRad)), 0) + "° ± " +
               FixedDecimals(RadToDeg(0.5 * ParamOf(p, Param::kShadeWidthRad)), 0) + "°, up to " +
               FixedDecimals(RadToDeg(ParamOf(p, Param::kShadeElevationRad)), 0) +
               "° elevation) shades " + std::to_string(shaded_rows) + " held-out rows holding " +
               FixedDecimals(100.0 * share, 0) + " % of the improvement, better there on " +
               std::to_string(days) + " of " + std::to_string(by_day.size()) + " days" +
               (c.shown ? "" : ": the improvement does not recur at the same sun positions");
  return c;
}

std::string DataLacks(const Series& data) {
  const bool split = (data.Has(Channel::kGPoaWM2) && data.Has(Channel::kGPoaDiffuseWM2)) ||
                     (data.Has(Channel::kGhiWM2) && data.Has(Channel::kDhiWM2));
  return split ? "" : "needs beam and diffuse (g_poa_diffuse_w_m2, or ghi_w_m2 + dhi_w_m2)";
}

std::vector<double> Signature(const Drivers& d, const SimOutputs&) { return d.g_beam_w_m2; }

// A start for the shading parameters from where the base model over-predicts
// P_el under beam light: cells of sun azimuth (10°) × elevation (5°) whose
// mean relative P_el residual (predicted − measured)/predicted exceeds 15 %
// on rows with at least 200 W/m² in the plane. The obstacle's azimuth window
// spans those cells, its edge is the highest of them. A local fit started at
// the default (a shade due south) does not find an obstacle elsewhere.
// Returns false when no cell qualifies.
bool StartFromResiduals(const EffectResiduals& res, ParamVector* start) {
  const Drivers& d = *res.drivers;
  const SimOutputs& sim = *res.base;
  const std::vector<double>& p_el_meas_w = *res.p_el_meas_w;
  constexpr int kAz = 36, kEl = 18;
  std::vector<double> sum(kAz * kEl, 0.0), count(kAz * kEl, 0.0);
  for (std::uint32_t i : *res.rows) {
    const double azimuth_rad = d.sun_azimuth_rad[i];
    const double elevation_rad = d.sun_elevation_rad[i];
    if (elevation_rad <= 0.0 || d.g_poa_w_m2[i] < 200.0 || !(sim.p_el_w[i] > 0.0)) continue;
    const int a = std::clamp(static_cast<int>(RadToDeg(azimuth_rad) / 10.0), 0, kAz - 1);
    const int e = std::clamp(static_cast<int>(RadToDeg(elevation_rad) / 5.0), 0, kEl - 1);
    sum[a * kEl + e] += (sim.p_el_w[i] - p_el_meas_w[i]) / sim.p_el_w[i];
    count[a * kEl + e] += 1.0;
  }
  int az_lo = kAz, az_hi = -1, el_hi = -1;
  for (int a = 0; a < kAz; ++a) {
    for (int e = 0; e < kEl; ++e) {
      const int k = a * kEl + e;
      if (count[k] < 5 || sum[k] / count[k] < 0.15) continue;
      az_lo = std::min(az_lo, a);
      az_hi = std::max(az_hi, a);
      el_hi = std::max(el_hi, e);
    }
  }
  if (az_hi < 0) return false;
  auto set = [start](Param p, double v) { (*start)[static_cast<std::size_t>(p)] = v; };
  set(Param::kShadeAzimuthRad, DegToRad(5.0 * (az_lo + az_hi + 1)));
  set(Param::kShadeWidthRad, DegToRad(10.0 * (az_hi - az_lo + 1)));
  set(Param::kShadeElevationRad, DegToRad(5.0 * (el_hi + 1)));
  return true;
}

// "Obstacle at azimuth 230–270°, up to 25° elevation: …".
std::string ObstacleAdvice(const ParamVector& p, const Plant&) {
  const double centre = RadToDeg(ParamOf(p, Param::kShadeAzimuthRad));
  const double half = RadToDeg(0.5 * ParamOf(p, Param::kShadeWidthRad));
  return "Obstacle at azimuth " + FixedDecimals(centre - half, 0) + "–" +
         FixedDecimals(centre + half, 0) + "°, up to " +
         FixedDecimals(RadToDeg(ParamOf(p, Param::kShadeElevationRad)), 0) +
         "° elevation: look for it on site (tree, building, mast) and check the string layout.";
}
}  // namespace

const EffectModule& ShadingEffect() {
  static const EffectModule kModule = [] {
    EffectModule m;
    m.name = "shading";
    m.physics =
        "An obstacle (building, tree, row in front) blocks the beam while the sun is "
        "inside an azimuth window γ_shade ± Δγ/2 below the obstacle's edge α_shade: "
        "s = σ((Δγ/2 − |γ_sun − γ_shade|)/e)·σ((α_shade − α_sun)/e), logistic edges "
        "e = 2° so that the fit has a gradient. The absorbed irradiance loses s·I_beam, "
        "and partial shade of a string makes the bypass diodes drop whole substrings: "
        "P_el is further multiplied by (1 − f_mismatch·s), the power not converted "
        "staying as heat. P_el therefore drops much more than Q_u.";
    m.source =
        "Deline et al. 2013, A simplified model of uniform shading in large photovoltaic arrays, "
        "Solar Energy 96";
    m.params = {Param::kShadeAzimuthRad, Param::kShadeWidthRad, Param::kShadeElevationRad,
                Param::kShadeMismatch};
    m.needs = {Channel::kGhiWM2, Channel::kDhiWM2};
    m.typical_truth = {{Param::kShadeAzimuthRad, DegToRad(250.0)},
                       {Param::kShadeWidthRad, DegToRad(40.0)},
                       {Param::kShadeElevationRad, DegToRad(35.0)},
                       {Param::kShadeMismatch, 0.6}};
    m.signature = "beam irradiance in the plane, W/m² (localise by sun azimuth × elevation)";
    m.advice =
        "Look for the obstacle in the sun's path at the azimuth and elevation the fit "
        "reports; if it stays, model it with +shading and check the string layout.";
    m.extension = &Extension();
    m.advice_for = ObstacleAdvice;
    m.data_lacks = DataLacks;
    m.signature_values = Signature;
    m.shows_signature = RecursAtTheSameSunPosition;
    m.start_from_residuals = StartFromResiduals;
    m.other_truth = &OtherTruth();
    return m;
  }();
  return kModule;
}

}  // namespace pvtwin
