#include "core/model/irradiance_drivers.h"

#include <cassert>
#include <cmath>
#include <limits>
#include <span>

#include "core/common/threads.h"
#include "core/common/units.h"
#include "core/physics/iam.h"
#include "core/physics/irradiance.h"
#include "core/physics/solar_position.h"

namespace pvtwin {

std::vector<SolarPosition> SunAtRowMiddles(const Series& s, const Plant& plant) {
  const std::size_t n = s.size();
  std::vector<double> mid_s(n);
  for (std::size_t i = 0; i < n; ++i) {
    mid_s[i] = static_cast<double>(s.time_s[i]) + 0.5 * s.step_s;
  }
  SolarPositionInput site;
  site.latitude_rad = plant.latitude_rad;
  site.longitude_rad = plant.longitude_rad;
  site.elevation_m = plant.elevation_m;
  std::vector<SolarPosition> sun(n);
  // Each row's position depends on its time alone (ComputeSolarPositions),
  // so a long series is split between two threads with the same result: the
  // positions are the largest part of `pvtwin calibrate --timing`'s prepare.
  const std::span<const double> times(mid_s);
  const std::span<SolarPosition> out(sun);
  ForRowHalves(n, kSunRowsToSplit, [&](std::size_t begin, std::size_t end) {
    ComputeSolarPositions(times.subspan(begin, end - begin), site, out.subspan(begin, end - begin));
  });
  return sun;
}

PoaComponents TransposeRowIsotropicSky(const Series& s, const Plant& plant, std::size_t i,
                                       const SolarPosition& sun, double aoi_rad) {
  IsotropicSkyInput h;
  h.ghi_w_m2 = s[Channel::kGhiWM2][i];
  h.dhi_w_m2 = s[Channel::kDhiWM2][i];
  h.zenith_rad = sun.zenith_rad;
  h.aoi_rad = aoi_rad;
  h.tilt_rad = plant.tilt_rad;
  h.ground_albedo = plant.ground_albedo;
  return TransposeIsotropicSky(h);
}

std::vector<double> AoiAtRows(const Series& s, const Plant& plant,
                              std::span<const SolarPosition> sun) {
  assert(sun.size() == s.size());
  std::vector<double> aoi_rad(s.size());
  ForRowHalves(s.size(), kRowsToSplit, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      aoi_rad[i] = s.At(Channel::kAoiRad, i);
      if (std::isnan(aoi_rad[i])) {
        aoi_rad[i] = AngleOfIncidenceRad(sun[i].zenith_rad, sun[i].azimuth_rad, plant.tilt_rad,
                                         plant.azimuth_rad);
      }
    }
  });
  return aoi_rad;
}

void ComputeIrradianceDrivers(const Series& s, const Plant& plant, const ModelSpec& spec,
                              std::span<const SolarPosition> sun, std::span<const double> aoi,
                              std::vector<double>* g_poa_w_m2, std::vector<double>* g_abs_w_m2,
                              Drivers::IamParts* parts) {
  const std::size_t n = s.size();
  const bool measured_poa = s.Has(Channel::kGPoaWM2);
  const bool have_horizontal = s.Has(Channel::kGhiWM2) && s.Has(Channel::kDhiWM2);
  assert(sun.size() == n && aoi.size() == n);
  const EffectiveDiffuseAngles diffuse_angles = BrandemuehlBeckmanAngles(plant.tilt_rad);
  g_poa_w_m2->assign(n, std::nan(""));
  g_abs_w_m2->assign(n, std::nan(""));
  if (parts != nullptr) *parts = {};
  if (parts != nullptr && spec.iam) {
    for (std::vector<double>* v : {&parts->beam_w_m2, &parts->sky_w_m2, &parts->ground_w_m2,
                                   &parts->beam_excess, &parts->paper_k_beam}) {
      v->assign(n, std::nan(""));
    }
  }
  // Each row reads its own inputs only: a long series is split between
  // two threads (ForRowHalves), with the same drivers.
  ForRowHalves(n, kRowsToSplit, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const double aoi_rad = aoi[i];
      PoaComponents poa;
      const double measured = measured_poa ? s[Channel::kGPoaWM2][i] : std::nan("");
      if (!std::isnan(measured)) {
        MeasuredPoaInput m;
        m.g_poa_w_m2 = measured;
        m.g_poa_diffuse_w_m2 = s.At(Channel::kGPoaDiffuseWM2, i);
        m.ghi_w_m2 = s.At(Channel::kGhiWM2, i);
        m.dhi_w_m2 = s.At(Channel::kDhiWM2, i);
        m.tilt_rad = plant.tilt_rad;
        m.ground_albedo = plant.ground_albedo;
        poa = SplitMeasuredPoa(m);
        (*g_poa_w_m2)[i] = measured;
      } else if (have_horizontal) {
        poa = TransposeRowIsotropicSky(s, plant, i, sun[i], aoi_rad);
        (*g_poa_w_m2)[i] = poa.global_w_m2();
      } else {
        continue;  // no irradiance for this row
      }
      (*g_abs_w_m2)[i] = spec.iam
                             ? AbsorbedIrradianceWM2(poa, aoi_rad, diffuse_angles, plant.iam_b0)
                             : (*g_poa_w_m2)[i];
      if (parts != nullptr && spec.iam) {
        parts->beam_w_m2[i] = poa.beam_w_m2;
        parts->sky_w_m2[i] = poa.sky_diffuse_w_m2;
        parts->ground_w_m2[i] = poa.ground_diffuse_w_m2;
        const double theta = std::fabs(aoi_rad);
        parts->beam_excess[i] = theta < 0.5 * kPi ? 1.0 / std::cos(theta) - 1.0
                                                  : std::numeric_limits<double>::infinity();
        parts->paper_k_beam[i] = IamSoukaSafwat(aoi_rad, plant.iam_b0);
      }
    }
  });
}

}  // namespace pvtwin
