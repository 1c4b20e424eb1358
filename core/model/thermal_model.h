// The PVT grey-box model of the paper (sections 2.1–2.10): one or two
// temperature nodes, optional capacitances, wind and sky long-wave losses,
// beam/diffuse split with an IAM, PV efficiency with temperature and
// irradiance correction; plus the hooks of the effects beyond the paper's
// letters (ModelExtension, core/common/model_spec.h), which the model runs
// without knowing them by name.
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

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/common/model_data.h"
#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/model/variant.h"
#include "core/physics/solar_position.h"

namespace pvtwin {

inline constexpr double kNodeToleranceK = 1e-4;
inline constexpr int kMaxNodeIterations = 8;

// Builds the drivers of `spec` from measured data. Fails (false, *error says
// which inputs are missing) when the series lacks a channel the variant needs.
// Gaps longer than max_gap_s restart the states.
bool PrepareDrivers(const Series& series, const Plant& plant, const ModelSpec& spec,
                    Drivers* drivers, std::string* error);

// The same with the sun positions at the rows' middles given: SunAtRowMiddles
// of `series` (core/model/irradiance_drivers.h), or the part of a longer
// series' positions that `series` slices (a row's position depends on its
// time and the step alone). A caller that prepares many slices of one series
// for several variants (the backtest) computes them once. Fails when `sun`
// does not have one position per row.
bool PrepareDrivers(const Series& series, const Plant& plant, const ModelSpec& spec,
                    std::span<const SolarPosition> sun, Drivers* drivers, std::string* error);

// The measured sky temperature of row i, °C: t_sky_c, else the equivalent of
// lw_down_w_m2 (paper 3.1); NaN without either.
double MeasuredSkyTemperatureC(const Series& series, std::size_t i);

// The sky temperature of every row, °C, as plant.sky says: the measured
// t_sky_c (else the equivalent of lw_down_w_m2, paper 3.1), or an estimate:
// where the row has rh_pct (Series' air channels), the clear sky of Berdahl
// & Martin from the dew point (with p_air_hpa's pressure correction where
// given; core/physics/sky_radiation.h), else Swinbank's from t_amb_c alone.
// kAuto uses the measured channel unless it is
// implausible: among at least 30 rows in full sun (in-plane or global
// irradiance ≥ 600 W/m²) more than half put the sky more than 2 K above the
// air, which no clear sky does (the same rule as the sensor check
// sky_warmer_than_air, core/monitor/monitoring.h). *note (may be null) says
// why when the estimate is used, "" otherwise; *used (may be null) which
// sky it is. NaN where the source is.
std::vector<double> SkyTemperaturesC(const Series& series, const Plant& plant, std::string* note,
                                     SkyUsed* used = nullptr);

// soiling: cleanings (rain or washing) at these unix times reset the soiling
// loss; recomputes drivers->days_since_clean. Times need not be sorted.
void SetCleaningTimes(const std::vector<std::int64_t>& cleaning_times_s, Drivers* drivers);

// A cleaning the measured data show: the start of the solar day on which
// the performance index recovered, and by how much (a fraction).
struct Cleaning {
  std::int64_t time_s = 0;
  double recovered = 0.0;
};

// Cleanings (rain, washing) seen in the data, the way a soiling analysis
// finds them (Deceglie et al. 2018, stochastic rate and recovery, RdTools):
// a daily performance index PI = median over the rows with g_poa ≥ 500 W/m²
// (at least 20) of P_el / (g_poa·(1 + f_corr_T·(T_PV − T_PVref))), T_PV the
// measured t_pv_c, else T_amb + 0.025·g_poa (the module 25 K per kW/m² above
// the air; a PVT module's fluid makes that rough, but much the same from one
// day to the next); a day whose PI rises over the
// previous PI day's by more than max(2 %, 4 robust standard deviations of
// the day-to-day changes), and that the next PI day does not undo (it keeps
// at least half of the rise), is a cleaning that recovered PI_d/PI_prev − 1.
// None without P_el or g_poa, or with fewer than 6 PI days.
std::vector<Cleaning> DetectCleanings(const Series& series, const Plant& plant);

// drivers->soiling_recovered from the cleanings: their recoveries summed up
// to each row.
void SetCleanings(const std::vector<Cleaning>& cleanings, Drivers* drivers);

// Consecutive groups of rows, group g being rows [begin[g], begin[g + 1]),
// each averaged to one row of a coarsened copy of the data (identification's
// coarse stage). The averages go channel by channel over all groups: one
// input stream at a time, each output written once.
struct RowGroups {
  std::vector<std::size_t> begin;  // one more than the groups: the last is the end
  std::vector<double> dt_s;        // each group's length, its rows' dt_s summed in order

  std::size_t size() const { return dt_s.size(); }
  // Adds the group of rows [begin.back(), end); row_dt_s: the rows' dt_s.
  void Add(std::size_t end, const std::vector<double>& row_dt_s);
  // *out[g]: the mean of v over group g weighted by row_dt_s (Σ v·dt / Σ dt).
  void Means(const std::vector<double>& v, const std::vector<double>& row_dt_s,
             std::vector<double>* out) const;
  // *out[g]: v at group g's middle row.
  void Middles(const std::vector<double>& v, std::vector<double>* out) const;
};

// The effect modules' raw drivers of d averaged over `groups` into *coarse
// (time-weighted means; sun angles of the middle row), for a coarsened copy
// of d such as identification's coarse stage builds.
void CoarsenEffectDrivers(const Drivers& d, const RowGroups& groups, Drivers* coarse);

// Runs the model. `out` is resized to the drivers' length; reusing it between
// calls avoids any allocation.
void Simulate(const Drivers& drivers, const ParamVector& params, SimOutputs* out,
              const SimOptions& options = {});

}  // namespace pvtwin
