// Model variants: which nodes, capacitances and effects a model has.
//
// Grammar (paper Table 6, extended):
//   variant   := base ("+" effect)*
//   base      := ("1N" ["1C"] | "2N" ["1Cpv" | "1Ccol" | "2C"]) ["w"] ["r"] ["I"]
//   effect    := any name of DESIGN.md's effect vocabulary (core/effects/effects.h)
// Letters: w = wind dependence of the front loss in the paper's printed form,
// r = long-wave exchange with the sky, I = beam/diffuse split with the
// incidence-angle modifier. "1C" on a one-node model is a capacitance on the
// PV node. Effects beyond the paper use the names of DESIGN.md's effect
// vocabulary; "sky_radiation" and "iam" are the same as the letters r and I,
// "capacitance" adds the next missing capacitance (1N → 1N1C, 2N → 2N1Ccol,
// 2N1Cpv/2N1Ccol → 2N2C) and "second_node" turns 1N into 2N (a capacitance on
// the PV node stays there). "+wind" is the physical wind form and cannot be
// combined with "w". Name() prints the base letters, then the extensions in
// the order of the Extension enum, so a parsed name prints canonically.
#pragma once

#include <bitset>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/channels.h"
#include "core/common/params.h"

namespace pvtwin {

enum class Extension : std::size_t {
  kWind,            // front loss U_front + c_wind·v^n (physical form)
  kTransportDelay,  // dead time and pipe loss between the collector node and the outlet sensor
  kFlowDependentU,  // fluid-side resistance r0 scales with flow^-n_flow
  kPvClipping,      // P_el = min(P_dc, P_limit); the clipped power stays as heat
  kShading,         // obstacle removing beam irradiance in an azimuth/elevation window
  kSoiling,         // transmittance loss growing with days since the last cleaning
  kClockOffset,     // weather channels shifted in time against the collector channels
  kIrradianceBias,  // plane-of-array pyranometer scale error, calibrated against GHI/DHI
  kCount
};

inline constexpr std::size_t kNumExtensions = static_cast<std::size_t>(Extension::kCount);

struct ModelSpec {
  int nodes = 1;            // 1: T_PV only; 2: T_PV and T_coll
  bool c_pv = false;        // capacitance on the PV node
  bool c_coll = false;      // capacitance on the collector node (2 nodes only)
  bool wind_paper = false;  // 'w'
  bool sky = false;         // 'r'
  bool iam = false;         // 'I'
  std::bitset<kNumExtensions> extensions;

  bool Has(Extension e) const { return extensions.test(static_cast<std::size_t>(e)); }
  // Canonical name, e.g. "2N1Ccolwr" or "1N1Cr+wind+transport_delay".
  std::string Name() const;
};

// Parses a variant name. On failure returns false and says why in *error.
bool ParseVariant(std::string_view name, ModelSpec* spec, std::string* error);

// The nine variants of the paper's Table 6, in the table's order.
const std::vector<std::string>& PaperVariants();

// Parameters the variant's equations use. Parameters outside this set have no
// effect on its outputs.
std::bitset<kNumParams> UsedParams(const ModelSpec& spec);

// Parameters identification frees by default: UsedParams minus A_PVT and the
// PV correction coefficients, which the paper keeps fixed (Table 3, left).
std::bitset<kNumParams> DefaultFreeParams(const ModelSpec& spec);

// A requirement on the input data, satisfied by any one of the channel sets.
struct InputRequirement {
  std::string what;                                // e.g. "irradiance in the collector plane"
  std::vector<std::vector<Channel>> alternatives;  // any one set suffices
};

// What a variant needs from the data to be simulated.
std::vector<InputRequirement> RequiredInputs(const ModelSpec& spec);

}  // namespace pvtwin
