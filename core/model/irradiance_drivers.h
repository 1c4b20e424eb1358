// Irradiance inputs of the model for each row: the global irradiance in the
// collector plane I_gt (used by the PV efficiency correction) and the
// absorbed irradiance I_at (paper 2.5; equal to I_gt without the 'I' option).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "core/common/model_data.h"
#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/model/variant.h"
#include "core/physics/irradiance.h"
#include "core/physics/solar_position.h"

namespace pvtwin {

// Rows from which PrepareDrivers splits its row-local work between two
// threads (ForRowHalves). The sun's positions (some 0.4 µs a row) from
// kSunRowsToSplit; the other loops (tens of ns a row) from kRowsToSplit,
// below which they gain less than the helper thread's start costs: with
// them split from 8192 rows (a build not committed) the prepare stage of
// `pvtwin calibrate --timing` on 14 days at 1 min took 8.8 ms against
// 8.3 ms (medians of 15, alternated); split from this, 14 days at 5 s took
// 76.6 against 87.5 ms (of 25).
inline constexpr std::size_t kSunRowsToSplit = 8192;
inline constexpr std::size_t kRowsToSplit = 65536;

// Sun position at the middle of each row (a row is the mean over
// [t_k, t_k + step)), at the plant's site.
std::vector<SolarPosition> SunAtRowMiddles(const Series& s, const Plant& plant);

// Row i's GHI and DHI transposed to the collector plane (isotropic sky,
// paper 2.5) with the sun `sun` and the angle of incidence `aoi_rad`; the
// series must have both columns.
PoaComponents TransposeRowIsotropicSky(const Series& s, const Plant& plant, std::size_t i,
                                       const SolarPosition& sun, double aoi_rad);

// Angle of incidence on the collector per row: the measured aoi where the
// series has one, else from `sun` (SunAtRowMiddles).
std::vector<double> AoiAtRows(const Series& s, const Plant& plant,
                              std::span<const SolarPosition> sun);

// Sources, in order of preference:
//  * I_gt: measured g_poa_w_m2; else transposed from ghi_w_m2 + dhi_w_m2
//    (isotropic sky, paper 2.5) with the sun at the middle of the row.
//  * I_at ('I' variants): beam and diffuse parts from g_poa_diffuse_w_m2
//    when measured, else from the transposition; each part weighted with the
//    Souka & Safwat IAM at its angle (aoi_deg when measured, else computed;
//    Brandemuehl & Beckman angles for sky and ground diffuse).
// Rows whose inputs are missing get NaN. With 'I' and parts non-null, also
// the parts before the IAM (Drivers::IamParts). `sun` and `aoi_rad` are
// SunAtRowMiddles and AoiAtRows, computed once by the caller, who needs them
// too.
void ComputeIrradianceDrivers(const Series& s, const Plant& plant, const ModelSpec& spec,
                              std::span<const SolarPosition> sun, std::span<const double> aoi_rad,
                              std::vector<double>* g_poa_w_m2, std::vector<double>* g_abs_w_m2,
                              Drivers::IamParts* parts = nullptr);

}  // namespace pvtwin
