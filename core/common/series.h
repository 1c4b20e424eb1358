// A time series of measured (or simulated) channels, stored column-wise.
//
// time_s[i] is unix seconds UTC and marks the start of row i's interval
// (doc/contracts.md); a row covers [time_s[i], time_s[i] + step_s). A channel that
// the source did not provide has an empty column; a missing cell in a present
// column is NaN.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/common/channels.h"

namespace pvtwin {

struct Series {
  std::vector<std::int64_t> time_s;
  double step_s = 0.0;  // nominal spacing of the rows
  std::array<std::vector<double>, kNumChannels> columns;
  // The air channels (channels.h AirChannel), empty when absent, as columns.
  std::array<std::vector<double>, kNumAirChannels> air;

  std::size_t size() const { return time_s.size(); }
  bool Has(Channel c) const { return !columns[static_cast<std::size_t>(c)].empty(); }
  std::vector<double>& operator[](Channel c) { return columns[static_cast<std::size_t>(c)]; }
  const std::vector<double>& operator[](Channel c) const {
    return columns[static_cast<std::size_t>(c)];
  }
  // Value of channel c in row i, NaN if the channel is absent.
  double At(Channel c, std::size_t i) const {
    const auto& col = (*this)[c];
    return col.empty() ? std::nan("") : col[i];
  }
  bool Has(AirChannel c) const { return !air[static_cast<std::size_t>(c)].empty(); }
  std::vector<double>& operator[](AirChannel c) { return air[static_cast<std::size_t>(c)]; }
  const std::vector<double>& operator[](AirChannel c) const {
    return air[static_cast<std::size_t>(c)];
  }
  double At(AirChannel c, std::size_t i) const {
    const auto& col = (*this)[c];
    return col.empty() ? std::nan("") : col[i];
  }
  // Adds channel c filled with NaN (no-op if present).
  std::vector<double>& Ensure(Channel c) {
    auto& col = (*this)[c];
    if (col.empty()) col.assign(size(), std::nan(""));
    return col;
  }
  // Rows [begin, end) as a new series.
  Series Slice(std::size_t begin, std::size_t end) const;
  // Index of the first row with time_s ≥ t (size() if none); rows are in
  // time order.
  std::size_t RowAtOrAfter(std::int64_t t) const;
  // Rows with from ≤ time_s < to.
  Series Between(std::int64_t from, std::int64_t to) const {
    return Slice(RowAtOrAfter(from), std::max(RowAtOrAfter(from), RowAtOrAfter(to)));
  }
};

}  // namespace pvtwin
