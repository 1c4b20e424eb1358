// The data a model run reads and writes: the per-row drivers prepared from a
// measured series (Drivers), the outputs (SimOutputs), and the per-row inputs
// of one run after the effects' hooks (RunInputs). Shared by the model
// (core/model/) and the effect modules (core/effects/) that transform them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/common/model_spec.h"
#include "core/common/params.h"
#include "core/common/plant.h"

namespace pvtwin {

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

  // Raw drivers of the effect modules (core/effects/), filled for every
  // spec so that a base model's drivers also carry the effects' signatures;
  // NaN where the data lack the channel.
  std::vector<double> wind_m_s;           // measured wind speed
  std::vector<double> t_sky_c;            // sky temperature (SkyTemperaturesC)
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
  // soiling: the recoveries of the performance at the cleanings the data
  // show (DetectCleanings, core/model/thermal_model.h), summed up to the row;
  // the loss r·d drops by it. 0 where there is none.
  std::vector<double> soiling_recovered;
  // shading: the measured P_el per I_gt relative to its solar day's upper
  // quartile (ShadingRelativeYield), NaN where undefined or without +shading.
  std::vector<double> relative_yield;
  // shading: the measured P_el per I_gt on its solar day's diffuse-lit rows
  // (ShadingDiffuseYield), NaN where undefined or without +shading.
  std::vector<double> diffuse_yield;
  // irradiance_bias: the pyranometer scale error k estimated from the two
  // sources (EstimateIrradianceBias); g_poa_w_m2, g_abs_w_m2 and a beam from
  // the plane-of-array sensors are already multiplied by (1 + k). 0 without
  // the effect.
  double irradiance_bias = 0.0;
  // 'I' variants: the in-plane irradiance's parts before the IAM (paper
  // 2.5's split, W/m²), the beam's 1/cos θ − 1 (+inf at θ ≥ 90°) and the
  // paper's τα(θ) of the beam at [plant] iam_b0: what a fitted IAM form
  // (iam's "+iam") re-weights g_abs_w_m2 and g_beam_w_m2 from. Empty without
  // 'I'.
  struct IamParts {
    std::vector<double> beam_w_m2, sky_w_m2, ground_w_m2, beam_excess, paper_k_beam;
  } iam_parts;
  // Non-empty when the sky temperature is not the measured channel's: why
  // (an implausible long-wave channel, or [plant] sky = "estimated").
  std::string sky_note;
  SkyUsed sky_used = SkyUsed::kMeasured;  // which sky t_sky_c holds

  std::size_t size() const { return time_s.size(); }
};

inline constexpr std::size_t kRunWorkVectors = 16;

struct SimOutputs {
  std::vector<double> p_el_w;    // electrical power
  std::vector<double> q_th_w;    // useful heat to the fluid, Q_u
  std::vector<double> t_pv_c;    // PV node temperature (interval mean)
  std::vector<double> t_coll_c;  // collector node (2N) or = t_pv_c (1N)
  std::vector<double> t_out_c;   // predicted outlet temperature
  // Energy terms (interval means, W), filled when SimOptions::energy_terms:
  // q_abs = q_th + q_front + q_back + q_rad + q_store.
  std::vector<double> q_abs_w, q_front_w, q_back_w, q_rad_w, q_store_w;
  // Work space of the effects' hooks (RunInputs::Scratch), kept here so that
  // repeated runs do not allocate.
  std::array<std::vector<double>, kRunWorkVectors> work;
};

struct SimOptions {
  bool energy_terms = false;
  // Called after the spec's extensions have set the run's inputs (and before
  // the integration), for per-row inputs that no variant expresses: the
  // synthetic truth's other forms (core/synth/synthetic_plant.h). Empty: none.
  std::function<void(const Drivers& drivers, RunInputs* run)> after_extensions = nullptr;
};

// The per-row inputs of one Simulate call: the Drivers' arrays, or arrays
// that the effects' transform_drivers hooks replaced (ModelExtension). The
// integration reads only these.
struct RunInputs {
  std::size_t n = 0;
  const double* g_poa_w_m2 = nullptr;  // I_gt
  const double* g_abs_w_m2 = nullptr;  // I_at
  const double* g_beam_w_m2 = nullptr;
  const double* t_amb_c = nullptr;
  const double* t_back_c = nullptr;
  const double* ln_wind = nullptr;
  const double* t_sky_k4 = nullptr;
  // Per-row coefficients that replace the paper's forms when set:
  const double* u_front_w_m2k = nullptr;  // front loss conductance, W/(m²K)
  const double* g_fluid_w_k = nullptr;    // fluid coupling conductance, W/K
  // P_el = min(η(T_PV)·A·I_at·pv_factor, p_limit_w) when electric_effects;
  // the power not converted stays in the laminate as heat.
  const double* pv_factor = nullptr;  // null = 1
  double p_limit_w = std::numeric_limits<double>::infinity();
  bool electric_effects = false;

  std::array<std::vector<double>, kRunWorkVectors>* work = nullptr;
  std::size_t work_used = 0;

  // The next vector of the work space (kept between runs: no allocation once
  // sized). A bug (abort) when more than kRunWorkVectors are taken.
  std::vector<double>& Scratch();
  // A writable copy of the array *field points to, which *field then points
  // to; an array already in the work space is returned as it is.
  double* Own(const double** field);
};

}  // namespace pvtwin
