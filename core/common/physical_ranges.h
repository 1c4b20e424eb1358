// The physically possible range of each model parameter, beside Table 3's
// search range (params.h). The paper's ranges are start values ±50 % for
// several parameters (ε_PVT 0.075–0.225, η_PVref 0.075–0.225); a plant whose
// value lies outside them is a real plant, not a bad fit. The gap diagnosis
// re-fits a parameter that ends at a Table 3 bound within the hull of that
// range and this one (core/diagnosis/physical_refit.cc). Each entry names its
// source in a comment in physical_ranges.cc.
#pragma once

#include <string_view>

#include "core/common/params.h"
#include "core/common/plant.h"

namespace pvtwin {

struct PhysicalRange {
  double lower = 0.0;  // absolute, in the parameter's unit (resolved at the plant)
  double upper = 0.0;
  std::string_view source;  // one line: where the range comes from
};

// The physical range of p at this plant. Ranges of the parameters whose
// Table 3 bounds are factors of the plant's value (A_PVT, f_corr_I) are
// factors of it too and come back resolved, as ResolvedInfo's bounds do.
PhysicalRange PhysicalRangeOf(Param p, const Plant& plant);

// ResolvedInfo(p, plant) with the bounds widened to the hull of Table 3's
// range and the physical range: never narrower than Table 3's.
ParamInfo WidenedInfo(Param p, const Plant& plant);

}  // namespace pvtwin
