// The structure of a model variant (ModelSpec) and the interface through
// which an effect beyond the paper's letters plugs into the model
// (ModelExtension). Shared by the effect modules (core/effects/), which
// define the extensions, and the model (core/model/), which parses variant
// names and runs the hooks; neither the struct nor the model knows an effect
// by name.
//
// The paper's letters (Table 6) are fields: nodes, capacitance placement,
// 'w', 'r', 'I'. Every other effect is a ModelExtension, printed as
// "+name" after the letters in the order of ModelExtension::variant_order.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/channels.h"
#include "core/common/params.h"

namespace pvtwin {

struct Series;
struct Drivers;
struct RunInputs;
struct SimOutputs;

// A requirement on the input data, satisfied by any one of the channel sets.
struct InputRequirement {
  std::string what;                                // e.g. "irradiance in the collector plane"
  std::vector<std::vector<Channel>> alternatives;  // any one set suffices
};

// How an effect enters the model. Every hook may be null. The hooks run in
// this order:
//  1. prepare_drivers, once per data set in PrepareDrivers, after the base
//     drivers are built (e.g. a sensor calibration from a second source);
//  2. transform_drivers, once per Simulate call before the RC integration:
//     replaces per-row inputs (RunInputs' arrays) or sets coefficients, in
//     increasing driver_stage, then in variant_order. The integration's row
//     loop only reads the arrays, so it stays branch-light and does not
//     allocate (the work space is reused between calls);
//  3. transform_outputs, after the integration (e.g. what a sensor behind a
//     pipe sees).
struct ModelExtension {
  std::string_view name;  // doc/contracts.md vocabulary; "+name" in a variant
  int variant_order = 0;  // position among the "+name" parts of a canonical name
  // Parameters its equations use; identification frees them by default.
  std::vector<Param> params;
  // Parameters of the base model that its hooks read as well (the "+wind"
  // front loss reads U_front). A run with sensitivities differentiates the
  // base model's arithmetic only, so the columns of these and of `params`
  // come from differences (core/model/sensitivities.h). The sensitivity
  // tests of every registered effect catch a read left out here.
  std::vector<Param> reads_base_params;
  // True when transform_outputs is affine in the outputs it reads and writes
  // (parameters and drivers fixed), as a sensor behind a pipe is: a run with
  // sensitivities then pushes its derivatives through the hook. False: no
  // sensitivities for a spec with this extension.
  bool outputs_affine = false;
  // Inputs it needs beyond the base variant's.
  std::vector<InputRequirement> inputs;
  // True when the front loss reads the wind (drivers' ln_wind is filled).
  bool reads_wind = false;
  // Stage of transform_drivers: 0 = timing of the weather rows, 1 = values.
  int driver_stage = 1;
  bool (*prepare_drivers)(const Series& series, Drivers* drivers, std::string* error) = nullptr;
  void (*transform_drivers)(const Drivers& drivers, const ParamVector& params,
                            RunInputs* run) = nullptr;
  void (*transform_outputs)(const Drivers& drivers, const ParamVector& params, RunInputs* run,
                            SimOutputs* out) = nullptr;
};

struct ModelSpec {
  int nodes = 1;            // 1: T_PV only; 2: T_PV and T_coll
  bool c_pv = false;        // capacitance on the PV node
  bool c_coll = false;      // capacitance on the collector node (2 nodes only)
  bool wind_paper = false;  // 'w'
  bool sky = false;         // 'r'
  bool iam = false;         // 'I'
  // Effects beyond the letters, sorted by variant_order, each once.
  std::vector<const ModelExtension*> extensions;

  bool Has(const ModelExtension& e) const;
  // Adds e in canonical order (nothing when present); Remove drops it.
  void Add(const ModelExtension& e);
  void Remove(const ModelExtension& e);
  // Whether the front loss depends on the wind ('w' or an extension that reads it).
  bool ReadsWind() const;
  // Canonical name, e.g. "2N1Ccolwr" or "1N1Cr+wind+transport_delay".
  std::string Name() const;
};

}  // namespace pvtwin
