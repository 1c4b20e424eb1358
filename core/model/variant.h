// Model variants: which nodes, capacitances and effects a model has.
//
// Grammar (paper Table 6, extended):
//   variant   := base ("+" effect)*
//   base      := ("1N" ["1C"] | "2N" ["1Cpv" | "1Ccol" | "2C"]) ["w"] ["r"] ["I"]
//   effect    := any name of doc/contracts.md's effect vocabulary (core/effects/registry.h)
// Letters: w = wind dependence of the front loss in the paper's printed form,
// r = long-wave exchange with the sky, I = beam/diffuse split with the
// incidence-angle modifier. "1C" on a one-node model is a capacitance on the
// PV node. Effects beyond the paper use the names of doc/contracts.md's effect
// vocabulary; "sky_radiation" and "iam" are the same as the letters r and I,
// "capacitance" adds the next missing capacitance (1N → 1N1C, 2N → 2N1Ccol,
// 2N1Cpv/2N1Ccol → 2N2C) and "second_node" turns 1N into 2N (a capacitance on
// the PV node stays there). "+wind" is the physical wind form and cannot be
// combined with "w". ModelSpec::Name() prints the base letters, then the
// extensions in their variant_order, so a parsed name prints canonically.
// The model asks the effect registry for the names; it knows none itself.
#pragma once

#include <bitset>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/channels.h"
#include "core/common/model_spec.h"
#include "core/common/params.h"

namespace pvtwin {

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

// What a variant needs from the data to be simulated.
std::vector<InputRequirement> RequiredInputs(const ModelSpec& spec);

}  // namespace pvtwin
