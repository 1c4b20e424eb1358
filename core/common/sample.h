// One 5 s sample of every canonical channel, as the Modbus poller delivers it
// and the SQLite store keeps it (table sample_5s).
//
// Timestamp convention: ts_s is the start of the poll period the values were
// read in (unix seconds UTC, whole seconds). A channel that was not read in
// that period (device down, timeout, not in the register map) is NaN with its
// qc bit clear; a channel that was read but rejected (outside valid_min /
// valid_max, NaN or Inf after decoding, equal to the point's nan_value
// sentinel) is NaN with its qc bit set. A value is never carried over from an
// earlier period.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/common/channels.h"

namespace pvtwin {

struct Sample {
  std::int64_t ts_s = 0;
  std::array<double, kNumChannels> value;
  std::uint32_t rejected_mask = 0;  // bit c: channel c was read but failed QC

  Sample() { value.fill(std::numeric_limits<double>::quiet_NaN()); }

  double Get(Channel c) const { return value[static_cast<std::size_t>(c)]; }
  void Set(Channel c, double v) { value[static_cast<std::size_t>(c)] = v; }
  bool Has(Channel c) const { return std::isfinite(Get(c)); }
  bool Rejected(Channel c) const { return (rejected_mask >> static_cast<unsigned>(c)) & 1u; }
  void Reject(Channel c) {
    Set(c, std::numeric_limits<double>::quiet_NaN());
    rejected_mask |= 1u << static_cast<unsigned>(c);
  }
};

static_assert(kNumChannels <= 32, "Sample::rejected_mask holds one bit per channel");

}  // namespace pvtwin
