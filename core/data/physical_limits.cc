#include "core/data/physical_limits.h"

#include <cmath>

#include "core/common/units.h"
#include "core/data/qc.h"

namespace pvtwin {

namespace {

// Limits per m² of collector for the area-scaled channels.
constexpr double kFlowKgSM2 = 1.0;
constexpr double kPElLoWM2 = -50.0, kPElHiWM2 = 600.0;
constexpr double kQThLoWM2 = -5000.0, kQThHiWM2 = 2500.0;
// Short-wave irradiance (physical_limits.h says why): the largest zero
// offset of a pyranometer below, the BSRN limit with cloud enhancement above.
constexpr double kIrradianceLoWM2 = -30.0, kIrradianceHiWM2 = 2500.0;

}  // namespace

PhysicalLimit PhysicalLimitOf(Channel c, double area_m2) {
  const double a_m2 = area_m2 > 0.0 ? area_m2 : kMaxAreaM2;
  switch (c) {
    case Channel::kTInC:
    case Channel::kTOutC:
    case Channel::kTBackC:
    case Channel::kTPvC:
      return {-60.0, 250.0};
    case Channel::kMdotKgS:
      return {-kFlowKgSM2 * a_m2, kFlowKgSM2 * a_m2};
    case Channel::kGPoaWM2:
    case Channel::kGhiWM2:
    case Channel::kDhiWM2:
    case Channel::kGPoaDiffuseWM2:
      return {kIrradianceLoWM2, kIrradianceHiWM2};
    case Channel::kAoiRad:
      return {0.0, kPi};
    case Channel::kTAmbC:
      return {-90.0, 60.0};
    case Channel::kWindMS:
      return {0.0, 100.0};
    case Channel::kTSkyC:
      return {-120.0, 60.0};
    case Channel::kLwDownWM2:
      return {40.0, 700.0};
    case Channel::kPElW:
      return {kPElLoWM2 * a_m2, kPElHiWM2 * a_m2};
    case Channel::kQThW:
      return {kQThLoWM2 * a_m2, kQThHiWM2 * a_m2};
    case Channel::kValid:
      return {0.0, 1.0};
    case Channel::kCount:
      break;
  }
  return {std::nan(""), std::nan("")};
}

bool PassesEdge(Channel c, double value, double area_m2) {
  return PhysicalLimitOf(c, area_m2).Contains(value) ||
         (IsShortWave(c) && IsIrradianceGlitch(value));
}

PhysicalLimit ProviderLimitOf(ProviderQuantity q) {
  switch (q) {
    case ProviderQuantity::kAirTemperatureC:
      return PhysicalLimitOf(Channel::kTAmbC, 0.0);
    case ProviderQuantity::kPercent:
      return {0.0, 100.0};
    case ProviderQuantity::kWindAt10mMS:
      return {0.0, 113.0};
    case ProviderQuantity::kIrradianceWM2:
      return {0.0, 1500.0};
  }
  return {std::nan(""), std::nan("")};
}

std::size_t LimitViolations::Total() const {
  std::size_t total = 0;
  for (const std::size_t n : count) total += n;
  return total;
}

LimitViolations ApplyPhysicalLimits(Series* series, double area_m2) {
  LimitViolations v;
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    const PhysicalLimit limit = PhysicalLimitOf(static_cast<Channel>(c), area_m2);
    std::vector<double>& column = series->columns[c];
    for (std::size_t i = 0; i < column.size(); ++i) {
      if (std::isnan(column[i]) || limit.Contains(column[i])) continue;
      if (v.count[c]++ == 0) {
        v.first_row[c] = i;
        v.first_value[c] = column[i];
      }
      column[i] = std::nan("");
    }
  }
  return v;
}

}  // namespace pvtwin
