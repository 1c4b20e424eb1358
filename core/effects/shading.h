// Effect "shading": an obstacle blocks the beam inside an azimuth window
// below its edge. A ModelExtension that removes the shaded beam from the
// absorbed irradiance and sets the P_el factor of the bypass diodes.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "core/effects/effect_module.h"

namespace pvtwin {

// Fraction of the beam blocked by the obstacle,
//   s = σ((Δγ/2 − |γ_sun − γ_shade|)/e) · σ((α_shade − α_sun)/e),  α_sun > 0,
// σ the logistic function, e = 2° edge width (so that the fit has a
// gradient), |·| the azimuth difference wrapped to [0, π]. Angles in rad:
// sun azimuth from north clockwise, elevations above the horizon; centre
// γ_shade, full width Δγ, edge elevation α_shade. 0 with the sun down.
double ShadedFraction(double sun_azimuth_rad, double sun_elevation_rad, double centre_rad,
                      double width_rad, double edge_elevation_rad);

// Share of the isotropic sky diffuse that the box of ShadedFraction hides: a
// horizon at the constant angle α_shade over the azimuth width Δγ (Dozier &
// Frew 1990, the sky view factor from the horizon angle, as in
// HorizonDiffuseShare): f_d = (Δγ/2π)·sin²α_shade; Δγ clamped to [0, 2π],
// α_shade to [0, π/2].
double BoxDiffuseShare(double width_rad, double edge_elevation_rad);

// An obstacle that stands on some days only (scaffolding, a parked vehicle,
// a crown in leaf) shows in the measured yield y = P_el/I_gt, relative to the
// upper quartile of y on the same solar day (rows with I_gt ≥ 200 W/m² and
// the sun up; y of rows with I_gt ≥ 100 W/m², NaN elsewhere, and on days
// with fewer than 10 such rows). Per row of the series, in its order.
std::vector<double> ShadingRelativeYield(const std::vector<std::int64_t>& time_s,
                                         const std::vector<double>& p_el_w,
                                         const std::vector<double>& g_poa_w_m2,
                                         const std::vector<double>& sun_elevation_rad,
                                         std::int64_t solar_offset_s);

// The obstacle hides a share of the sky on every row of its days, so a day
// without beam on the obstacle shows it in the yield of its diffuse-lit
// rows: per solar day, Y = Σ P_el / Σ I_gt over the rows with I_gt ≥ 100
// W/m², the beam below half of I_gt and the sun up; NaN on days with fewer
// than 10 such rows. Per row, in its order; b_i = beam_w_m2/g_poa_w_m2.
std::vector<double> ShadingDiffuseYield(const std::vector<std::int64_t>& time_s,
                                        const std::vector<double>& p_el_w,
                                        const std::vector<double>& g_poa_w_m2,
                                        const std::vector<double>& beam_w_m2,
                                        const std::vector<double>& sun_elevation_rad,
                                        std::int64_t solar_offset_s);

// What one solar day shows of the obstacle. On the rows it shades the
// measured relative-yield deficit is nearer the modelled one than none,
//   Σ (1 − y_i) ≥ ½·Σ (1 − (1 − s_i·b_i)·(1 − f_mismatch·s_i)),
// over the day's rows with s_i ≥ 0.5 and a relative yield y_i (b_i =
// I_beam/I_gt); fewer than 3 such rows give no verdict.
struct ObstacleDayEvidence {
  double measured_deficit = 0.0;
  double modelled_deficit = 0.0;
  int rows = 0;
  double diffuse_yield = std::numeric_limits<double>::quiet_NaN();  // Y, ShadingDiffuseYield
  void Add(double relative_yield, double shaded_fraction, double beam_share, double mismatch);
  // +1 the obstacle stands, −1 it does not, 0 no verdict.
  int BeamVerdict() const;
};

// Whether the obstacle stands on each day (1) or not (0). A day with a beam
// verdict keeps it. A day without one is judged by its diffuse-lit yield
// against the obstacle-free one, Y_free = the median Y of the days whose
// beam shows no obstacle: it stands when its deficit D = 1 − Y/Y_free is
// nearer the hidden sky share f_d (BoxDiffuseShare) than 0 and no further
// above it than below, ½·f_d ≤ D ≤ 3/2·f_d (a larger loss is not the
// obstacle's: snow, a fault). Every other day follows the beam verdicts'
// majority (the obstacle stands on a tie, and when no day has one).
std::vector<std::uint8_t> ObstacleDays(const std::vector<ObstacleDayEvidence>& days,
                                       double diffuse_share);

// --- Other-form truth: an obstacle's horizon profile, on some days ---

// The upper edge of an obstacle seen from the collector: vertices (γ_k, h_k),
// sun azimuth from north clockwise and elevation above the horizon in rad,
// γ non-decreasing (a repeated γ is a vertical edge); no obstacle outside
// [γ_first, γ_last].
struct HorizonProfile {
  std::vector<double> azimuth_rad;
  std::vector<double> elevation_rad;
};

// Horizon elevation h(γ): linear between vertices, the higher side at a
// vertical edge, 0 outside the profile.
double HorizonElevationRad(const HorizonProfile& profile, double azimuth_rad);

// Share of the beam that the obstacle blocks, with a soft edge of width w
// (the sun's disc, 0.53°, and the leaves or the edge's blur):
//   s = clamp((h(γ_sun) − α_sun)/w + 1/2, 0, 1),  0 with the sun down,
// i.e. a linear penumbra across h ± w/2 (the candidate's box has logistic
// edges on a rectangle in azimuth × elevation).
double HorizonBeamShare(const HorizonProfile& profile, double sun_azimuth_rad,
                        double sun_elevation_rad, double edge_width_rad);

// Share of the isotropic sky diffuse on a horizontal plane that the obstacle
// hides, from the horizon-angle form of the sky view factor (Dozier & Frew
// 1990, IEEE TGRS 28(5), eq. for a horizontal surface, V = (1/2π)∫cos²h dγ):
//   f_d = 1 − V = (1/2π)·∫ sin² h(γ) dγ,
// integrated exactly on each linear segment (∫ sin²h dγ = Δγ/2 −
// Δγ·(sin 2h₁ − sin 2h₀)/(4·(h₁ − h₀))). Used for the tilted plane too (an
// approximation for the usual tilts ≤ 30°).
double HorizonDiffuseShare(const HorizonProfile& profile);

// The other-form truth's obstacle: a tree or a building to the
// west-south-west, up to 45°, soft edge 1.5°, present on a day with
// probability `day_probability` (scaffolding, a parked vehicle, a crown in
// leaf: drawn per UTC day from the truth's seed).
struct HorizonObstacle {
  HorizonProfile profile;
  double edge_width_rad = 0.0;
  double day_probability = 0.0;
};
const HorizonObstacle& OtherTruthObstacle();

// Whether the obstacle stands on the UTC day `day` (unix s / 86400) for seed.
bool ObstacleOnDay(std::uint64_t seed, std::int64_t day);

const EffectModule& ShadingEffect();

}  // namespace pvtwin
