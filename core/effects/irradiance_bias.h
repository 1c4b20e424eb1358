// Effect "irradiance_bias": the plane-of-array pyranometer reads with a
// scale error. A sensor fault: a ModelExtension whose prepare_drivers hook
// calibrates the plane sensor against GHI/DHI transposed to the plane.
#pragma once

#include <cmath>

#include "core/common/units.h"
#include "core/effects/effect_module.h"

namespace pvtwin {

// Scale error k of the plane-of-array pyranometer (G_true = G_meas·(1 + k))
// from the second irradiance source: the median of G_ref/G_meas − 1 over rows
// where both exceed 300 W/m² and the beam angle of incidence is below 60°
// (transposition errors grow towards grazing angles), G_ref = GHI/DHI
// transposed to the plane (isotropic sky, paper 2.5). NaN when fewer than 30
// such rows exist.
double EstimateIrradianceBias(const Drivers& drivers);

// --- Other-form truth: a cosine error and a zero offset besides the scale ---

// The pyranometer's directional response to the beam, f(θ) = 1 −
// e80·(θ/80°)³ for θ < 90° (0 beyond): a smooth error growing towards
// grazing incidence, e80 the error at 80° (ISO 9060:2018 specifies the
// directional response at 80°: ±20 W/m² of a 1000 W/m² beam, whose in-plane
// part is 174 W/m², i.e. ≈ 11 %, for a class-B "first class" sensor).
inline double PyranometerCosineResponse(double aoi_rad, double error_at_80deg) {
  const double theta = std::fabs(aoi_rad);
  if (!(theta < 0.5 * kPi)) return 0.0;
  const double x = theta / (80.0 * kPi / 180.0);
  return 1.0 - error_at_80deg * x * x * x;
}

struct PyranometerErrors {
  double cosine_error_at_80deg = 0.11;  // e80
  double zero_offset_w_m2 = -8.0;       // a: thermal zero offset (ISO 9060 "zero offset a")
};

inline constexpr PyranometerErrors kOtherTruthPyranometer{};

// What the faulty sensor reads of beam B and diffuse D (W/m², in its plane)
// at beam incidence θ, scale error k and zero offset a, while exposed to the
// day sky (B + D > 0; 0 at night):
//   G_meas = (f(θ)·B + D)/(1 + k) + a.
inline double PyranometerReadingWM2(double beam_w_m2, double diffuse_w_m2, double aoi_rad,
                                    double scale_error, const PyranometerErrors& e) {
  if (!(beam_w_m2 + diffuse_w_m2 > 0.0)) return beam_w_m2 + diffuse_w_m2;
  return (PyranometerCosineResponse(aoi_rad, e.cosine_error_at_80deg) * beam_w_m2 + diffuse_w_m2) /
             (1.0 + scale_error) +
         e.zero_offset_w_m2;
}

const EffectModule& IrradianceBiasEffect();

}  // namespace pvtwin
