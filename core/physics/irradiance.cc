#include "core/physics/irradiance.h"

#include <algorithm>
#include <cmath>

#include "core/common/units.h"

namespace pvtwin {

PoaComponents TransposeIsotropicSky(const IsotropicSkyInput& in) {
  if (!std::isfinite(in.ghi_w_m2) || !std::isfinite(in.dhi_w_m2) || !std::isfinite(in.zenith_rad) ||
      !std::isfinite(in.aoi_rad) || !std::isfinite(in.tilt_rad) ||
      !std::isfinite(in.ground_albedo)) {
    const double nan = std::nan("");
    return {nan, nan, nan};
  }
  const double ghi_w_m2 = std::max(0.0, in.ghi_w_m2);
  const double dhi_w_m2 = std::max(0.0, in.dhi_w_m2);
  const double cos_tilt = std::cos(in.tilt_rad);
  const double cos_zenith = std::cos(in.zenith_rad);
  const double cos_aoi = std::cos(in.aoi_rad);

  PoaComponents poa;
  const double beam_horizontal_w_m2 = std::max(0.0, ghi_w_m2 - dhi_w_m2);
  if (cos_zenith >= kMinCosZenithForBeam && cos_aoi > 0.0) {
    const double beam_normal_w_m2 = beam_horizontal_w_m2 / cos_zenith;
    poa.beam_w_m2 = beam_normal_w_m2 * cos_aoi;
  }
  poa.sky_diffuse_w_m2 = 0.5 * (1.0 + cos_tilt) * dhi_w_m2;
  poa.ground_diffuse_w_m2 = in.ground_albedo * 0.5 * (1.0 - cos_tilt) * ghi_w_m2;
  return poa;
}

PoaComponents SplitMeasuredPoa(const MeasuredPoaInput& in) {
  if (!std::isfinite(in.g_poa_w_m2)) {
    const double nan = std::nan("");
    return {nan, nan, nan};
  }
  const double global_w_m2 = std::max(0.0, in.g_poa_w_m2);
  if (!std::isfinite(in.g_poa_diffuse_w_m2)) {
    if (std::isfinite(in.ghi_w_m2) && std::isfinite(in.dhi_w_m2)) {
      // Paper 2.5 with the measured horizontal global and diffuse.
      PoaComponents poa;
      poa.sky_diffuse_w_m2 = 0.5 * (1.0 + std::cos(in.tilt_rad)) * std::max(0.0, in.dhi_w_m2);
      poa.ground_diffuse_w_m2 =
          in.ground_albedo * 0.5 * (1.0 - std::cos(in.tilt_rad)) * std::max(0.0, in.ghi_w_m2);
      const double diffuse_w_m2 = poa.sky_diffuse_w_m2 + poa.ground_diffuse_w_m2;
      if (diffuse_w_m2 > global_w_m2) {
        const double scale = diffuse_w_m2 > 0.0 ? global_w_m2 / diffuse_w_m2 : 0.0;
        poa.sky_diffuse_w_m2 *= scale;
        poa.ground_diffuse_w_m2 *= scale;
      }
      poa.beam_w_m2 = std::max(0.0, global_w_m2 - diffuse_w_m2);
      return poa;
    }
    // Not observable without an in-plane diffuse: everything is beam.
    return {global_w_m2, 0.0, 0.0};
  }
  const double diffuse_w_m2 = std::clamp(in.g_poa_diffuse_w_m2, 0.0, global_w_m2);
  const double ground_view_factor = 0.5 * (1.0 - std::cos(in.tilt_rad));
  const double reference_w_m2 =
      std::isfinite(in.ghi_w_m2) ? std::max(0.0, in.ghi_w_m2) : global_w_m2;
  PoaComponents poa;
  poa.ground_diffuse_w_m2 =
      std::min(diffuse_w_m2, in.ground_albedo * ground_view_factor * reference_w_m2);
  poa.sky_diffuse_w_m2 = diffuse_w_m2 - poa.ground_diffuse_w_m2;
  poa.beam_w_m2 = global_w_m2 - diffuse_w_m2;
  return poa;
}

EffectiveDiffuseAngles BrandemuehlBeckmanAngles(double tilt_rad) {
  const double tilt_deg = RadToDeg(tilt_rad);
  const double sky_deg = 59.68 - 0.1388 * tilt_deg + 0.001497 * tilt_deg * tilt_deg;
  const double ground_deg = 90.0 - 0.5788 * tilt_deg + 0.002693 * tilt_deg * tilt_deg;
  return {DegToRad(sky_deg), DegToRad(ground_deg)};
}

}  // namespace pvtwin
