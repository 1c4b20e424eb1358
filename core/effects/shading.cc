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

namespace {

// Calls f(lo, hi) for each solar day's rows [lo, hi) of a time-ordered
// series.
template <class F>
void ForEachSolarDay(const std::vector<std::int64_t>& time_s, std::int64_t solar_offset_s, F&& f) {
  for (std::size_t lo = 0; lo < time_s.size();) {
    const std::int64_t day = SolarDayStartS(time_s[lo], solar_offset_s);
    std::size_t hi = lo + 1;
    while (hi < time_s.size() && SolarDayStartS(time_s[hi], solar_offset_s) == day) ++hi;
    f(lo, hi);
    lo = hi;
  }
}

}  // namespace

double ShadedFraction(double sun_azimuth_rad, double sun_elevation_rad, double centre_rad,
                      double width_rad, double edge_elevation_rad) {
  if (!(sun_elevation_rad > 0.0)) return 0.0;
  constexpr double kEdgeRad = 2.0 * kPi / 180.0;
  double diff = std::fabs(std::remainder(sun_azimuth_rad - centre_rad, 2.0 * kPi));
  auto logistic = [](double x) { return 1.0 / (1.0 + std::exp(-x)); };
  return logistic((0.5 * width_rad - diff) / kEdgeRad) *
         logistic((edge_elevation_rad - sun_elevation_rad) / kEdgeRad);
}

double BoxDiffuseShare(double width_rad, double edge_elevation_rad) {
  const double width = std::clamp(width_rad, 0.0, 2.0 * kPi);
  const double edge = std::clamp(edge_elevation_rad, 0.0, 0.5 * kPi);
  return width / (2.0 * kPi) * std::sin(edge) * std::sin(edge);
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

std::vector<double> ShadingRelativeYield(const std::vector<std::int64_t>& time_s,
                                         const std::vector<double>& p_el_w,
                                         const std::vector<double>& g_poa_w_m2,
                                         const std::vector<double>& sun_elevation_rad,
                                         std::int64_t solar_offset_s) {
  const std::size_t n = time_s.size();
  std::vector<double> out(n, std::nan(""));
  std::vector<double> y;
  ForEachSolarDay(time_s, solar_offset_s, [&](std::size_t lo, std::size_t hi) {
    y.clear();
    for (std::size_t i = lo; i < hi; ++i) {
      const double r = p_el_w[i] / g_poa_w_m2[i];
      if (g_poa_w_m2[i] >= 200.0 && sun_elevation_rad[i] > 0.0 && std::isfinite(r)) {
        y.push_back(r);
      }
    }
    if (y.size() < 10) return;
    const auto q = y.begin() + static_cast<std::ptrdiff_t>(3 * y.size() / 4);
    std::nth_element(y.begin(), q, y.end());
    const double reference = *q;
    for (std::size_t i = lo; reference > 0.0 && i < hi; ++i) {
      const double r = p_el_w[i] / g_poa_w_m2[i];
      if (g_poa_w_m2[i] >= 100.0 && sun_elevation_rad[i] > 0.0 && std::isfinite(r)) {
        out[i] = r / reference;
      }
    }
  });
  return out;
}

std::vector<double> ShadingDiffuseYield(const std::vector<std::int64_t>& time_s,
                                        const std::vector<double>& p_el_w,
                                        const std::vector<double>& g_poa_w_m2,
                                        const std::vector<double>& beam_w_m2,
                                        const std::vector<double>& sun_elevation_rad,
                                        std::int64_t solar_offset_s) {
  const std::size_t n = time_s.size();
  std::vector<double> out(n, std::nan(""));
  ForEachSolarDay(time_s, solar_offset_s, [&](std::size_t lo, std::size_t hi) {
    double p_sum = 0.0, g_sum = 0.0;
    int rows = 0;
    for (std::size_t i = lo; i < hi; ++i) {
      const double g = g_poa_w_m2[i];
      const double beam = std::isfinite(beam_w_m2[i]) ? beam_w_m2[i] : 0.0;
      if (g >= 100.0 && beam < 0.5 * g && sun_elevation_rad[i] > 0.0 && std::isfinite(p_el_w[i])) {
        p_sum += p_el_w[i];
        g_sum += g;
        ++rows;
      }
    }
    if (rows < 10) return;
    std::fill(out.begin() + static_cast<std::ptrdiff_t>(lo),
              out.begin() + static_cast<std::ptrdiff_t>(hi), p_sum / g_sum);
  });
  return out;
}

void ObstacleDayEvidence::Add(double relative_yield, double shaded_fraction, double beam_share,
                              double mismatch) {
  if (!(shaded_fraction >= 0.5) || !std::isfinite(relative_yield) || !std::isfinite(beam_share)) {
    return;
  }
  measured_deficit += 1.0 - relative_yield;
  modelled_deficit += 1.0 - (1.0 - shaded_fraction * std::clamp(beam_share, 0.0, 1.0)) *
                                (1.0 - mismatch * shaded_fraction);
  ++rows;
}

int ObstacleDayEvidence::BeamVerdict() const {
  if (rows < 3) return 0;
  return measured_deficit >= 0.5 * modelled_deficit ? 1 : -1;
}

std::vector<std::uint8_t> ObstacleDays(const std::vector<ObstacleDayEvidence>& days,
                                       double diffuse_share) {
  int present = 0, absent = 0;
  std::vector<double> free_yield;
  for (const ObstacleDayEvidence& day : days) {
    const int verdict = day.BeamVerdict();
    present += verdict > 0 ? 1 : 0;
    absent += verdict < 0 ? 1 : 0;
    if (verdict < 0 && std::isfinite(day.diffuse_yield)) free_yield.push_back(day.diffuse_yield);
  }
  double y_free = std::nan("");
  if (!free_yield.empty()) {
    const auto mid = free_yield.begin() + static_cast<std::ptrdiff_t>(free_yield.size() / 2);
    std::nth_element(free_yield.begin(), mid, free_yield.end());
    y_free = *mid;
  }
  const std::uint8_t majority = present >= absent ? 1 : 0;
  std::vector<std::uint8_t> out(days.size(), majority);
  for (std::size_t k = 0; k < days.size(); ++k) {
    const int verdict = days[k].BeamVerdict();
    if (verdict != 0) {
      out[k] = verdict > 0 ? 1 : 0;
      continue;
    }
    const double deficit = 1.0 - days[k].diffuse_yield / y_free;
    if (!(y_free > 0.0) || !std::isfinite(deficit) || deficit > 1.5 * diffuse_share) continue;
    out[k] = deficit >= 0.5 * diffuse_share ? 1 : 0;
  }
  return out;
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

// I_at loses s·I_beam and the share f_d (BoxDiffuseShare) of its diffuse
// part, I_at − I_beam; P_el is multiplied by (1 − f_mismatch·s), the power
// not converted staying as heat (RunInputs::electric_effects). On the solar
// days whose measured yield does not show the obstacle (ObstacleDays) it
// does not stand: s = 0 and no diffuse loss there.
void ShadeTheBeam(const Drivers& d, const ParamVector& p, RunInputs* run) {
  const double centre = ParamOf(p, Param::kShadeAzimuthRad);
  const double width = ParamOf(p, Param::kShadeWidthRad);
  const double edge = ParamOf(p, Param::kShadeElevationRad);
  const double mismatch = ParamOf(p, Param::kShadeMismatch);
  const double diffuse_share = BoxDiffuseShare(width, edge);
  const std::int64_t solar_offset_s = SolarDayOffsetS(d.plant);
  const bool has_yield = d.relative_yield.size() == run->n;
  const bool has_diffuse_yield = d.diffuse_yield.size() == run->n;
  double* g_abs = run->Own(&run->g_abs_w_m2);
  std::vector<double>& shaded = run->Scratch();
  shaded.resize(run->n);
  std::vector<double>& factor = run->Scratch();
  factor.resize(run->n);
  std::vector<ObstacleDayEvidence> evidence;
  std::vector<std::size_t> day_end;  // end row of each solar day
  ForEachSolarDay(d.time_s, solar_offset_s, [&](std::size_t lo, std::size_t hi) {
    ObstacleDayEvidence& e = evidence.emplace_back();
    if (has_diffuse_yield) e.diffuse_yield = d.diffuse_yield[lo];
    for (std::size_t i = lo; i < hi; ++i) {
      shaded[i] = ShadedFraction(d.sun_azimuth_rad[i], d.sun_elevation_rad[i], centre, width, edge);
      if (has_yield) {
        e.Add(d.relative_yield[i], shaded[i], run->g_beam_w_m2[i] / run->g_poa_w_m2[i], mismatch);
      }
    }
    day_end.push_back(hi);
  });
  const std::vector<std::uint8_t> stands = ObstacleDays(evidence, diffuse_share);
  std::size_t i = 0;
  for (std::size_t k = 0; k < day_end.size(); ++k) {
    for (; i < day_end[k]; ++i) {
      const double s = stands[k] != 0 ? shaded[i] : 0.0;
      const double beam = std::isfinite(run->g_beam_w_m2[i]) ? run->g_beam_w_m2[i] : 0.0;
      const double diffuse = stands[k] != 0 ? std::max(0.0, g_abs[i] - beam) : 0.0;
      g_abs[i] -= s * beam + diffuse_share * diffuse;
      // Multiplies a factor set before (iam's "+iam_thermal").
      factor[i] = (run->pv_factor != nullptr ? run->pv_factor[i] : 1.0) * (1.0 - mismatch * s);
    }
  }
  run->pv_factor = factor.data();
  run->electric_effects = true;
}

// The measured relative yields of every row (ShadingRelativeYield,
// ShadingDiffuseYield), for the days on which the obstacle stands.
bool PrepareRelativeYield(const Series& s, Drivers* d, std::string*) {
  if (!s.Has(Channel::kPElW)) {
    d->relative_yield.clear();
    d->diffuse_yield.clear();
    return true;
  }
  d->relative_yield = ShadingRelativeYield(d->time_s, s[Channel::kPElW], d->g_poa_w_m2,
                                           d->sun_elevation_rad, SolarDayOffsetS(d->plant));
  d->diffuse_yield =
      ShadingDiffuseYield(d->time_s, s[Channel::kPElW], d->g_poa_w_m2, d->g_beam_w_m2,
                          d->sun_elevation_rad, SolarDayOffsetS(d->plant));
  return true;
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
    e.prepare_drivers = PrepareRelativeYield;
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
// on at least two solar days (at least 3 rows a day, with at least 200 W/m²
// in the plane): an obstacle recurs at the same sun positions, if not on
// every day. The obstacle's azimuth window spans those cells, its edge is
// the highest of them. A local fit started at the default (a shade due
// south) does not find an obstacle elsewhere. Returns false when no cell
// qualifies.
bool StartFromResiduals(const EffectResiduals& res, ParamVector* start) {
  const Drivers& d = *res.drivers;
  const SimOutputs& sim = *res.base;
  const std::vector<double>& p_el_meas_w = *res.p_el_meas_w;
  constexpr int kAz = 36, kEl = 18;
  const std::int64_t solar_offset_s = SolarDayOffsetS(d.plant);
  // (cell, solar day) → sum and count of the relative residual.
  std::map<std::pair<int, std::int64_t>, std::pair<double, int>> cell_days;
  for (std::uint32_t i : *res.rows) {
    const double azimuth_rad = d.sun_azimuth_rad[i];
    const double elevation_rad = d.sun_elevation_rad[i];
    if (elevation_rad <= 0.0 || d.g_poa_w_m2[i] < 200.0 || !(sim.p_el_w[i] > 0.0)) continue;
    const int a = std::clamp(static_cast<int>(RadToDeg(azimuth_rad) / 10.0), 0, kAz - 1);
    const int e = std::clamp(static_cast<int>(RadToDeg(elevation_rad) / 5.0), 0, kEl - 1);
    auto& [sum, count] = cell_days[{a * kEl + e, SolarDayStartS(d.time_s[i], solar_offset_s)}];
    sum += (sim.p_el_w[i] - p_el_meas_w[i]) / sim.p_el_w[i];
    ++count;
  }
  std::vector<int> days_over(kAz * kEl, 0);
  for (const auto& [key, sum_count] : cell_days) {
    const auto& [sum, count] = sum_count;
    if (count >= 3 && sum / count >= 0.15) ++days_over[static_cast<std::size_t>(key.first)];
  }
  int az_lo = kAz, az_hi = -1, el_hi = -1;
  for (int a = 0; a < kAz; ++a) {
    for (int e = 0; e < kEl; ++e) {
      if (days_over[static_cast<std::size_t>(a * kEl + e)] < 2) continue;
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
std::string ObstacleAdvice(const ModelSpec&, const ParamVector& p, const Plant&) {
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
    m.name = EffectName(Effect::kShading);
    m.physics =
        "An obstacle (building, tree, row in front) blocks the beam while the sun is "
        "inside an azimuth window γ_shade ± Δγ/2 below the obstacle's edge α_shade: "
        "s = σ((Δγ/2 − |γ_sun − γ_shade|)/e)·σ((α_shade − α_sun)/e), logistic edges "
        "e = 2° so that the fit has a gradient. The absorbed irradiance loses s·I_beam "
        "and, on every row, the share of the sky the obstacle hides from the diffuse "
        "part, f_d = (Δγ/2π)·sin²α_shade (sky view factor from the horizon angle, "
        "Dozier & Frew 1990); partial shade of a string makes the bypass diodes drop "
        "whole substrings: P_el is further multiplied by (1 − f_mismatch·s), the power "
        "not converted staying as heat. P_el therefore drops much more than Q_u. An "
        "obstacle may stand on some days only (scaffolding, a vehicle, a crown in leaf): "
        "it is taken to stand on a solar day when the measured yield P_el/I_gt on the "
        "rows it shades falls by at least half of what it would remove; a day without "
        "such rows is judged by the yield of its diffuse-lit rows against the days shown "
        "free of it (a deficit within f_d ± f_d/2), else follows the majority of the "
        "days judged (every day where P_el is not measured).";
    m.source =
        "Deline et al. 2013, A simplified model of uniform shading in large photovoltaic arrays, "
        "Solar Energy 96";
    m.params = EffectParams(Effect::kShading);
    m.needs = {Channel::kGhiWM2, Channel::kDhiWM2};
    m.typical_truth = {{Param::kShadeAzimuthRad, DegToRad(250.0)},
                       {Param::kShadeWidthRad, DegToRad(40.0)},
                       {Param::kShadeElevationRad, DegToRad(35.0)},
                       {Param::kShadeMismatch, 0.6}};
    // Scaffolding, a parked vehicle, a new building or a crown in leaf.
    m.begins_in_operation = true;
    // The window's far edge is not determined by summer data; the mismatch is.
    m.compared_param = Param::kShadeMismatch;
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
