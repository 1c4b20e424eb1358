#include "core/common/series.h"

namespace pvtwin {

Series Series::Slice(std::size_t begin, std::size_t end) const {
  Series out;
  out.step_s = step_s;
  out.time_s.assign(time_s.begin() + begin, time_s.begin() + end);
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    if (!columns[c].empty()) {
      out.columns[c].assign(columns[c].begin() + begin, columns[c].begin() + end);
    }
  }
  for (std::size_t c = 0; c < kNumAirChannels; ++c) {
    if (!air[c].empty()) out.air[c].assign(air[c].begin() + begin, air[c].begin() + end);
  }
  return out;
}

std::size_t Series::RowAtOrAfter(std::int64_t t) const {
  return static_cast<std::size_t>(std::lower_bound(time_s.begin(), time_s.end(), t) -
                                  time_s.begin());
}

}  // namespace pvtwin
