// Powers and power errors as text, the same way in every command: the whole
// collector's figure in W first, then the same figure per m² of nameplate
// area ("71.70 W (39.83 W/m²)"). The paper's objective and tables are per m²
// (Table 3), an operator's meters read W: every printed MAE gives both.
#pragma once

#include <string>

namespace pvtwin {

// "71.70 W (39.83 W/m²)"; "n/a" when w is not finite. area_m2 ≤ 0 (not
// known) gives the W figure alone.
std::string WattsAndPerM2(double w, double area_m2);

}  // namespace pvtwin
