#include "core/series.h"

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
  return out;
}

}  // namespace pvtwin
