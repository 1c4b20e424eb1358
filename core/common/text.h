// Numbers in sentences: the verdicts, evidence and advice the diagnosis and
// the effect modules write for a plant engineer.
#pragma once

#include <string>

namespace pvtwin {

// x with `digits` decimals ("12.35").
std::string FixedDecimals(double x, int digits);

// x with `digits` significant digits, as printf's %g ("0.225", "1e+03").
std::string SignificantDigits(double x, int digits);

}  // namespace pvtwin
