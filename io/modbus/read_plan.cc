#include "io/modbus/read_plan.h"

#include <algorithm>
#include <cassert>
#include <numeric>
#include <tuple>

namespace pvtwin {

std::vector<RegisterRead> PlanReads(const ModbusConfig& map, const ReadPlanOptions& options) {
  assert(options.max_registers >= 1 && options.max_registers <= kMaxReadRegisters);
  assert(options.max_gap >= 0);
  std::vector<std::size_t> order(map.points.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto key = [&](std::size_t i) {
    const ModbusPoint& p = map.points[i];
    return std::make_tuple(p.device, p.table, p.address);
  };
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return key(a) < key(b); });

  std::vector<RegisterRead> reads;
  for (const std::size_t i : order) {
    const ModbusPoint& p = map.points[i];
    const int end = p.address + p.Count();
    if (!reads.empty()) {
      RegisterRead& last = reads.back();
      const int last_end = last.address + last.count;
      if (last.device == p.device && last.table == p.table &&
          p.address - last_end <= options.max_gap && end - last.address <= options.max_registers) {
        last.count = std::max(last_end, end) - last.address;
        last.points.push_back(i);
        continue;
      }
    }
    reads.push_back({p.device, p.table, p.address, p.Count(), {i}});
  }
  return reads;
}

}  // namespace pvtwin
