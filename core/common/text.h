// Numbers in sentences: the verdicts, evidence and advice the diagnosis and
// the effect modules write for a plant engineer.
#pragma once

#include <string>

namespace pvtwin {

// x with `digits` decimals ("12.35").
std::string FixedDecimals(double x, int digits);

}  // namespace pvtwin
