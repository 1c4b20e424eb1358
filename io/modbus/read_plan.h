// Coalescing of register-map points into Modbus read requests: as few reads
// as the protocol allows. Points of one device and one table, sorted by
// address, are merged into one read while the read stays within
// max_registers (125, the limit of function codes 3 and 4) and the unused
// registers between two neighbouring points are at most max_gap (reading a
// few unmapped registers is cheaper than another round trip; devices answer
// them, usually with 0).
#pragma once

#include <cstddef>
#include <vector>

#include "config/modbus_config.h"

namespace pvtwin {

inline constexpr int kMaxReadRegisters = 125;

struct ReadPlanOptions {
  int max_registers = kMaxReadRegisters;  // registers per read, 1..125
  int max_gap = 8;                        // unused registers bridged, >= 0
};

struct RegisterRead {
  std::size_t device = 0;
  RegisterTable table = RegisterTable::kInput;
  int address = 0;                  // first register
  int count = 0;                    // registers read
  std::vector<std::size_t> points;  // indices into ModbusConfig::points, by address
};

// The reads of every point, ordered by device, table and address. Every point
// is in exactly one read and lies inside [address, address + count).
std::vector<RegisterRead> PlanReads(const ModbusConfig& map, const ReadPlanOptions& options = {});

}  // namespace pvtwin
