// The PVT grey-box model of the paper (sections 2.1–2.10): one or two
// temperature nodes, optional capacitances, wind and sky long-wave losses,
// beam/diffuse split with an IAM, PV efficiency with temperature and
// irradiance correction; plus the extensions of variant.h.
//
// Network (Fig. 1 of the paper; per m² values × A_PVT):
//   PV node T_PV:   Q_abs(T_PV) + U_front,w·(T_amb − T_PV) + U_rad·(T_sky − T_PV)
//                   [+ U_coll·(T_coll − T_PV)]                = C_PV·dT_PV/dt
//   collector node T_coll (2N):
//                   U_back·(T_back − T_coll) + U_fluid·(T_in − T_coll)
//                   + U_coll·(T_PV − T_coll)                  = C_coll·dT_coll/dt
//   In the one-node model the back and fluid links attach to T_PV (paper 2.10).
//   Q_abs = (1 − η_PV)·F_th·A_PVT·I_at (eq. 2.3), P_el = η_PV·A_PVT·I_at,
//   Q_u = U_fluid·(T_fluid-node − T_in).
//
// Time convention: row k of the input is the mean over [t_k, t_k + dt_k); the
// model holds row k's inputs constant over that interval, advances the
// capacitive nodes exactly (rc_network.h) and reports interval means, so an
// output row is comparable with a logged average. The states start (first
// row, after a gap or a row with missing inputs) at the steady state of that
// row's inputs (paper 2.2).
//
// Non-linear terms: η_PV is linear in T_PV and sky radiation ε·σ·(T_PV⁴ −
// T_sky⁴) is linearised about the step-mean T_PV (Newton); the linearisation
// point is updated until the remaining linearisation error moves T_PV by less
// than kNodeToleranceK (at most kMaxNodeIterations passes). The step is exact
// for the linear part at any step length, so every variant is stable for any
// parameter within Table 3's bounds and any step from 5 s to 15 min.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/model/variant.h"

namespace pvtwin {

inline constexpr double kNodeToleranceK = 1e-4;
inline constexpr int kMaxNodeIterations = 8;

// Inputs of one model run, precomputed once per data set and variant so that
// the simulation loop (called thousands of times by identification) only does
// the parameter-dependent arithmetic.
struct Drivers {
  ModelSpec spec;
  Plant plant;
  std::vector<std::int64_t> time_s;
  std::vector<double> dt_s;           // length of the row's interval
  std::vector<std::uint8_t> restart;  // 1: initialise the states at this row
  std::vector<std::uint8_t> usable;   // 0: an input is missing, outputs are NaN
  std::vector<double> t_in_c;
  std::vector<double> mdot_kg_s;
  std::vector<double> capacity_flow_w_k;  // ṁ·c_p
  std::vector<double> g_poa_w_m2;         // I_gt, global in plane (efficiency correction)
  std::vector<double> g_abs_w_m2;         // I_at, IAM-weighted in plane (= I_gt without 'I')
  std::vector<double> t_amb_c;
  std::vector<double> t_back_c;  // T_back (= T_amb when not measured)
  std::vector<double> ln_wind;   // ln(v), −inf for calm; 0 when unused
  std::vector<double> t_sky_k4;  // T_sky⁴ in K⁴; 0 when unused

  // Raw drivers of the effect library (core/effects/effects.h), filled for every
  // spec so that a base model's drivers also carry the effects' signatures;
  // NaN where the data lack the channel.
  std::vector<double> wind_m_s;           // measured wind speed
  std::vector<double> t_sky_c;            // sky temperature (t_sky_c, else from lw_down)
  std::vector<double> sun_azimuth_rad;    // at the row's middle, from north clockwise
  std::vector<double> sun_elevation_rad;  // refraction-corrected
  std::vector<double> aoi_rad;            // beam angle of incidence (measured or computed)
  // Beam part of g_abs_w_m2 (IAM-weighted for 'I'): g_poa − g_poa_diffuse
  // when measured, else the transposed GHI/DHI beam.
  std::vector<double> g_beam_w_m2;
  // GHI/DHI transposed to the plane (isotropic sky): the second irradiance
  // source of irradiance_bias.
  std::vector<double> g_ref_w_m2;
  // soiling: days since the last cleaning (since the first row when none is
  // known; see SetCleaningTimes).
  std::vector<double> days_since_clean;
  // irradiance_bias: the pyranometer scale error k estimated from the two
  // sources (EstimateIrradianceBias); g_poa_w_m2, g_abs_w_m2 and a beam from
  // the plane-of-array sensors are already multiplied by (1 + k). 0 without
  // the effect.
  double irradiance_bias = 0.0;

  std::size_t size() const { return time_s.size(); }
};

// Builds the drivers of `spec` from measured data. Fails (false, *error says
// which inputs are missing) when the series lacks a channel the variant needs.
// Gaps longer than max_gap_s restart the states.
bool PrepareDrivers(const Series& series, const Plant& plant, const ModelSpec& spec,
                    Drivers* drivers, std::string* error);

// soiling: cleanings (rain or washing) at these unix times reset the soiling
// loss; recomputes drivers->days_since_clean. Times need not be sorted.
void SetCleaningTimes(const std::vector<std::int64_t>& cleaning_times_s, Drivers* drivers);

// Appends to *coarse the effect library's drivers of rows [begin, end) of d
// averaged to one row (time-weighted means; sun angles of the middle row),
// for a coarsened copy of d such as identification's coarse stage builds.
void AppendCoarseEffectDrivers(const Drivers& d, std::size_t begin, std::size_t end,
                               Drivers* coarse);

// flow_dependent_u: the specific capacity flow at which the fluid-side
// resistance equals r0_fluid, w_ref = 0.02 kg/(s·m²) · c_p (the nominal
// specific flow of the paper's plant and of the weather generator).
inline constexpr double kFlowReferenceKgSM2 = 0.02;

struct SimOutputs {
  std::vector<double> p_el_w;    // electrical power
  std::vector<double> q_th_w;    // useful heat to the fluid, Q_u
  std::vector<double> t_pv_c;    // PV node temperature (interval mean)
  std::vector<double> t_coll_c;  // collector node (2N) or = t_pv_c (1N)
  std::vector<double> t_out_c;   // predicted outlet temperature
  // Energy terms (interval means, W), filled when SimOptions::energy_terms:
  // q_abs = q_th + q_front + q_back + q_rad + q_store.
  std::vector<double> q_abs_w, q_front_w, q_back_w, q_rad_w, q_store_w;
  // Work space of the effects shading, soiling, clock_offset and
  // transport_delay (modified weather drivers, the undelayed outlet), kept
  // here so that repeated runs do not allocate.
  std::array<std::vector<double>, 9> effect_work;
};

struct SimOptions {
  bool energy_terms = false;
};

// Runs the model. `out` is resized to the drivers' length; reusing it between
// calls avoids any allocation.
void Simulate(const Drivers& drivers, const ParamVector& params, SimOutputs* out,
              const SimOptions& options = {});

}  // namespace pvtwin
