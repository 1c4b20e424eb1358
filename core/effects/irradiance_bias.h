// Effect "irradiance_bias": the plane-of-array pyranometer reads with a
// scale error. A sensor fault: a ModelExtension whose prepare_drivers hook
// calibrates the plane sensor against GHI/DHI transposed to the plane.
#pragma once

#include "core/effects/effect_module.h"

namespace pvtwin {

// Scale error k of the plane-of-array pyranometer (G_true = G_meas·(1 + k))
// from the second irradiance source: the median of G_ref/G_meas − 1 over rows
// where both exceed 300 W/m² and the beam angle of incidence is below 60°
// (transposition errors grow towards grazing angles), G_ref = GHI/DHI
// transposed to the plane (isotropic sky, paper 2.5). NaN when fewer than 30
// such rows exist.
double EstimateIrradianceBias(const Drivers& drivers);

const EffectModule& IrradianceBiasEffect();

}  // namespace pvtwin
