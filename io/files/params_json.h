// params.json: the parameters of one model, as written by `pvtwin calibrate`
// and read by `pvtwin simulate`.
//
//   { "variant": "2N1Ccolwr",            (optional, informative)
//     "params": { "u_front_w_m2k": 12.5, "c_coll_j_m2k": 81000, ... },
//     "fit": { ... } }                    (optional, written by calibrate)
//
// A flat object mapping parameter names (core/params.h) to numbers is read
// as well. Parameters that are not given take their Table 3 start values.
#pragma once

#include <bitset>
#include <string>

#include "core/common/diagnostic.h"
#include "core/common/params.h"
#include "core/common/plant.h"

namespace pvtwin {

struct ParamsFile {
  std::string variant;  // empty when the file does not name one
  ParamVector values{};
  std::bitset<kNumParams> given;  // which values the file set
};

// Reads path; returns false with every problem in *errors (unknown parameter
// name, a value that is not a finite number, malformed JSON with its line).
bool ReadParamsJson(const std::string& path, const Plant& plant, ParamsFile* out,
                    Diagnostics* errors);
bool ParseParamsJson(const std::string& text, const std::string& path_for_messages,
                     const Plant& plant, ParamsFile* out, Diagnostics* errors);

// The JSON text of a params file: "variant", "params" with the given
// parameters (all when `only` is empty), and `fit_json` (a JSON object text,
// may be empty) under "fit".
std::string FormatParamsJson(const std::string& variant, const ParamVector& values,
                             const std::bitset<kNumParams>& only, const std::string& fit_json);

// Writes the text atomically (temporary file, then rename).
bool WriteTextFileAtomically(const std::string& path, const std::string& text, std::string* error);

}  // namespace pvtwin
