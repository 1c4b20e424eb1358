// Synthetic weather and plant operation for a PVT collector field: a
// reproducible multi-day Series with irradiance (horizontal and in the
// collector plane), ambient temperature, wind, long-wave irradiance, pump
// flow and inlet temperature, for tests, demos and identification on
// synthetic data. The model outputs (p_el_w, q_th_w, t_out_c, t_pv_c) are
// left empty; the collector model fills them.
//
// Reproducibility: all randomness comes from std::mt19937_64 engines seeded
// from WeatherOptions::seed and turned into normal deviates by the Box–Muller
// transform written here (no std:: distributions, whose output differs
// between standard libraries). Same options ⇒ bit-identical Series on the
// same platform and libm.
//
// Timestamp convention: row i starts at start_time_s + i·step_s (unix s UTC)
// and carries instantaneous values at that time (the sun position at the
// row's start, not an interval mean).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/physics/clear_sky.h"
#include "core/synth/absorber_sensor.h"

namespace pvtwin {

// ---------------------------------------------------------------------------
// Building blocks (pure functions, also used by the tests).

// Diffuse fraction k_d = DHI/GHI as a function of the clearness index
// k_t = GHI / (I0 · cos θ_z), Erbs, Klein & Duffie (1982):
//
//   k_d = 1 − 0.09·k_t                                          k_t ≤ 0.22
//   k_d = 0.9511 − 0.1604·k_t + 4.388·k_t² − 16.638·k_t³ + 12.336·k_t⁴
//                                                               0.22 < k_t ≤ 0.80
//   k_d = 0.165                                                 k_t > 0.80
double ErbsDiffuseFraction(double clearness_index);

// ---------------------------------------------------------------------------
// Generator.

enum class DayType {
  kClear,         // clear sky with slight haze variations
  kBrokenClouds,  // cumulus: the sun is hidden and revealed every few minutes
  kOvercast,      // closed cloud deck, mostly diffuse light
};

std::string_view DayTypeName(DayType type);

enum class FlowMode {
  kConstant,  // on/off pump at the nominal flow
  kVariable,  // flow follows in-plane irradiance: nominal · clamp(G/800, 0.3, 1)
};

// How the simulated plant runs its solar loop (pump and inlet).
enum class PumpControl {
  // The pump switches on in-plane irradiance (pump_on/off_w_m2, dwell); a
  // crude tank warmed by a fraction of the irradiance sets the inlet. The
  // default: every data set recorded before the other modes came with it.
  kIrradiance,
  // A differential thermostat (pump_controller.h): the pump runs while the
  // collector's absorber sensor (absorber_sensor.h) is warmer than the tank
  // by pump_dt_on_k, stops below pump_dt_off_k (dwell as above); the tank
  // gains the heat the sensor model says the fluid takes. A summer plant:
  // a 25 °C tank takes little from a winter sun.
  kDifferential,
  // Uncovered PVT as the source of a brine/water heat pump: the inlet is
  // brine from the evaporator, following the ambient brine_below_ambient_k
  // colder, within [brine_min_c, brine_max_c] (smoothed, τ 1 h); the pump
  // runs while the heat pump runs (heat_pump_from_h … heat_pump_to_h local
  // solar time) and the absorber is warmer than the brine (ΔT thermostat as
  // above): heat from the sun and from the ambient air, in every season.
  kHeatPumpSource,
};

// "irradiance", "differential", "heat_pump"; nullopt for any other text.
std::string_view PumpControlName(PumpControl control);
std::optional<PumpControl> PumpControlFromName(std::string_view name);

struct WeatherOptions {
  // First row, unix s UTC. Default 2024-06-01 00:00 UTC.
  std::int64_t start_time_s = 1717200000;
  // Length of the series in days (86400 s each); > 0.
  int num_days = 7;
  // Row spacing in whole seconds, 1 … 3600.
  double step_s = 60.0;
  // Seed of every random process; record it with the data set.
  std::uint64_t seed = 1;

  // Sky. If day_types is not empty, local solar day d has day_types[d %
  // size()] (see DayTypesFor); otherwise day types are drawn: with
  // probability day_type_persistence the previous day's type is kept, else a
  // new one is drawn with probabilities p_clear, p_broken and
  // 1 − p_clear − p_broken (overcast).
  std::vector<DayType> day_types;
  double p_clear = 0.35;              // [0, 1]
  double p_broken = 0.40;             // [0, 1], p_clear + p_broken ≤ 1
  double day_type_persistence = 0.5;  // [0, 1)
  double linke_turbidity = 3.5;       // clear-sky T_L, [1.5, 8]

  // Ambient air. The climatological level comes from latitude and day of
  // year; this offset shifts it (e.g. to emulate a warm spell).
  double t_amb_offset_c = 0.0;  // [−30, 30]

  // Plant operation.
  double flow_kg_s_per_m2 = 0.02;  // nominal specific mass flow, (0, 0.2]
  FlowMode flow_mode = FlowMode::kConstant;
  double pump_on_w_m2 = 200.0;      // pump starts above this in-plane irradiance
  double pump_off_w_m2 = 100.0;     // … and stops below this one; < pump_on_w_m2
  double pump_min_dwell_s = 300.0;  // minimum time between two switchings, ≥ 0
  double t_in_base_c = 25.0;        // inlet (tank) temperature at dawn, [0, 90]
  // Crude tank: heat capacity per m² of collector and the fraction of the
  // in-plane irradiance that reaches it while the pump runs; the load pulls
  // the tank back to t_in_base_c with the given time constant.
  double tank_heat_capacity_j_m2k = 4.2e5;          // ≈ 100 l of water per m², > 0
  double tank_gain_fraction = 0.4;                  // [0, 1]
  double tank_load_time_constant_s = 6.0 * 3600.0;  // > 0

  // Control of the solar loop (PumpControl); the fields below serve the
  // kDifferential and kHeatPumpSource modes only.
  PumpControl pump_control = PumpControl::kIrradiance;
  double pump_dt_on_k = 5.0;   // absorber − inlet to start the pump, > pump_dt_off_k
  double pump_dt_off_k = 2.0;  // … and to stop it, ≥ 0
  // The collector's absorber sensor: the truth plant's parameters
  // (MakeSyntheticPlantData sets them from its truth with
  // SensorParamsFromTruth, synthetic_plant.h).
  AbsorberSensorParams absorber;
  // Heat-pump source: brine = clamp(t_amb − brine_below_ambient_k,
  // brine_min_c, brine_max_c), the heat pump runs between these local solar
  // hours (from < to).
  double brine_below_ambient_k = 5.0;  // [0, 30]
  double brine_min_c = 0.0;            // [-20, brine_max_c]
  double brine_max_c = 10.0;           // [brine_min_c, 30]
  double heat_pump_from_h = 6.0;       // [0, heat_pump_to_h)
  double heat_pump_to_h = 20.0;        // (heat_pump_from_h, 24]

  // True if the options can be used; otherwise *why names the field, its
  // value and the rule it breaks.
  bool IsValid(std::string* why) const;
};

// Day type of each local solar day touched by the series. Local solar day d
// (d = 0 for the day containing start_time_s) spans the times t with
// floor((t + λ/2π · 86400 s) / 86400 s) − floor((start + λ/2π · 86400 s) / 86400 s) = d,
// λ = plant longitude east positive, so types switch near local midnight.
// Returns num_days + 1 entries (the last day may be partial).
std::vector<DayType> DayTypesFor(const WeatherOptions& options);

// A synthetic Series of num_days · 86400 / step_s rows. Channels filled:
//
//   ghi_w_m2, dhi_w_m2   clear-sky GHI (Ineichen & Perez) × a clear-sky index
//                        k_c from the day type's cloud process (clear:
//                        0.93 … 1.03 slow haze; broken: two-state Markov
//                        sun/cloud with dwell times of minutes, 0.1 … 0.6
//                        under cloud, up to 1.1 at edges; overcast: 0.05 …
//                        0.55 slow), so GHI ≤ 1.1 × clear sky; DHI from the
//                        Erbs diffuse fraction of k_t (all diffuse for
//                        cos θ_z < 0.05); 0 with the sun below the horizon.
//   g_poa_w_m2,          isotropic-sky transposition (TransposeIsotropicSky)
//   g_poa_diffuse_w_m2   onto the plant's plane; diffuse = sky + ground.
//   aoi_deg (kAoiRad)    beam angle of incidence from the SPA (radians).
//   t_amb_c              climatological level (annual mean 28 − 0.38·|φ|°C,
//                        seasonal amplitude 0.22·|φ| K peaking on day 201 in
//                        the north) + offset + a mean-reverting day-to-day
//                        anomaly (σ 3 K, τ 3 d) + a diurnal wave cos(H − 45°)
//                        (peak at 15 h solar time) whose half-range depends on
//                        the day type (6 / 4 / 1.5 K), + 0.2 K noise.
//   wind_m_s             day-type median (2 / 3.5 / 4.5 m/s) × afternoon
//                        factor × log-normal slow variation (σ_ln 0.35, τ 1 h)
//                        × gusts (σ_ln 0.25, τ 2 min); ≥ 0.
//   lw_down_w_m2         long-wave on the collector plane: sky part
//                        (1 + cos β)/2 · ε_sky σ T_a⁴ with Brunt's clear-sky
//                        ε_clr = 0.52 + 0.065 √e_a[hPa] and the cloud
//                        increase ε_sky = c + (1 − c) ε_clr (c = cloud fraction),
//                        plus ground part (1 − cos β)/2 · σ T_a⁴; e_a from a
//                        day-type relative humidity (60 / 70 / 90 %).
//   flow_kg_s            pump as pump_control says (kIrradiance: hysteresis
//                        on pump_on/off_w_m2; else the ΔT thermostat on the
//                        absorber sensor; min dwell in every mode):
//                        flow_kg_s_per_m2 · area (× irradiance factor in
//                        variable mode) × (1 + 1 % noise) when on, 0 when off.
//   t_in_c               kIrradiance: tank temperature, rises with
//                        tank_gain_fraction of the in-plane irradiance while
//                        pumping; kDifferential: tank, rises with the heat
//                        the absorber sensor model delivers; both relax to
//                        t_in_base_c through the load. kHeatPumpSource: the
//                        brine. + mixing noise in every mode.
//
// One call is one continuous run: every state (tank, pump, absorber, the
// weather's slow processes) carries across midnight; a longer num_days with
// the same options reproduces the shorter run's rows bit for bit.
//   valid                1.
//
// Aborts with a message if !options.IsValid() (a caller bug).
Series GenerateWeather(const Plant& plant, const WeatherOptions& options);

}  // namespace pvtwin
