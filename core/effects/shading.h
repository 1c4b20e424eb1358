// Effect "shading": an obstacle blocks the beam inside an azimuth window
// below its edge. A ModelExtension that removes the shaded beam from the
// absorbed irradiance and sets the P_el factor of the bypass diodes.
#pragma once

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

const EffectModule& ShadingEffect();

}  // namespace pvtwin
