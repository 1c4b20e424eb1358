// The estimates of the fine stage; see core/fit/fine_stage.h.
#include "core/fit/fine_stage.h"

#include <algorithm>
#include <vector>

namespace pvtwin::fit_internal {

std::vector<ParamEstimate> Estimates(const Drivers& drivers, const FreeSet& fs, const FineFit& fine,
                                     const IdentOptions& options) {
  std::vector<ParamEstimate> out;
  const auto used = UsedParams(drivers.spec);
  const ParamVector& best = fine.best();
  for (std::size_t i = 0; i < kNumParams; ++i) {
    if (!used.test(i)) continue;
    const ParamInfo info = SearchInfo(static_cast<Param>(i), drivers.plant, options);
    ParamEstimate e;
    e.param = info.param;
    e.value = best[i];
    e.start = fs.base[i];
    e.lower = info.lower;
    e.upper = info.upper;
    const auto it = std::find(fs.free.begin(), fs.free.end(), info.param);
    e.free = it != fs.free.end();
    if (e.free) {
      const auto j = static_cast<std::size_t>(it - fs.free.begin());
      e.undetermined = !fine.active()[j];
      e.se_unit = fine.se()[j];
      e.weak = fine.active()[j] && fine.se()[j] > options.undetermined_se;
      const double z = ToUnit(fs.infos[j], e.value);
      e.at_bound = fine.active()[j] && (z < kAtBoundZ || z > 1.0 - kAtBoundZ);
    }
    out.push_back(e);
  }
  return out;
}

}  // namespace pvtwin::fit_internal
