#include "core/common/params.h"

#include <cmath>

namespace pvtwin {

namespace {
constexpr auto kLin = ParamScale::kLinear;
constexpr auto kLog = ParamScale::kLog;
}  // namespace

// Table 3 of the paper; see params.h for the normalisation of each entry
// and param_list.inc for the rows.
const std::array<ParamInfo, kNumParams> kParamTable = {{
#define PVTWIN_PARAM(id, owner, name, unit, symbol, start, lower, upper, scale, relative) \
  {Param::id, name, unit, symbol, start, lower, upper, scale, relative},
#include "core/common/param_list.inc"
}};

namespace {
constexpr std::array<std::string_view, kNumParams> kParamNames = {
#define PVTWIN_PARAM(id, owner, name, ...) name,
#include "core/common/param_list.inc"
};

constexpr bool ParamNamesAreDistinct() {
  for (std::size_t i = 0; i < kNumParams; ++i) {
    for (std::size_t j = i + 1; j < kNumParams; ++j) {
      if (kParamNames[i] == kParamNames[j]) return false;
    }
  }
  return true;
}
static_assert(ParamNamesAreDistinct(), "two rows of param_list.inc share a params.json name");
}  // namespace

ParamInfo ResolvedInfo(Param p, const Plant& plant) {
  ParamInfo info = Info(p);
  if (!info.relative_to_plant) return info;
  double reference = 0.0;
  switch (p) {
    case Param::kAreaM2:
      reference = plant.area_m2;
      break;
    case Param::kPvTempCoeffPerK:
      reference = plant.pv_temp_coeff_per_k;
      break;
    case Param::kPvIrrCoeffM2W:
      reference = plant.pv_irr_coeff_m2_w;
      break;
    default:
      break;
  }
  info.start *= reference;
  const double a = info.lower * reference;
  const double b = info.upper * reference;
  info.lower = std::fmin(a, b);  // a negative reference flips the interval
  info.upper = std::fmax(a, b);
  return info;
}

ParamVector StartParams(const Plant& plant) {
  ParamVector v{};
  for (std::size_t i = 0; i < kNumParams; ++i) {
    v[i] = ResolvedInfo(static_cast<Param>(i), plant).start;
  }
  return v;
}

std::optional<Param> ParamFromName(std::string_view name) {
  for (const ParamInfo& info : kParamTable) {
    if (info.name == name) return info.param;
  }
  return std::nullopt;
}

std::vector<Param> EffectParams(Effect e) {
  std::vector<Param> params;
  for (std::size_t i = 0; i < kNumParams; ++i) {
    if (kParamEffect[i] == e) params.push_back(static_cast<Param>(i));
  }
  return params;
}

}  // namespace pvtwin
