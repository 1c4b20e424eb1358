// Coalescing of register-map points into reads (io/modbus/read_plan.h).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/plant_config.h"
#include "io/modbus/read_plan.h"
#include "tests/support/files.h"

namespace pvtwin {
namespace {

ModbusPoint At(std::size_t device, RegisterTable table, int address, RegisterType type) {
  ModbusPoint p;
  p.device = device;
  p.table = table;
  p.address = address;
  p.type = type;
  return p;
}

ModbusConfig TwoDevices() {
  ModbusConfig map;
  map.devices.resize(2);
  map.devices[0].name = "a";
  map.devices[1].name = "b";
  return map;
}

// Every point in exactly one read, inside it; reads within 125 registers.
void ExpectCoversEveryPointOnce(const ModbusConfig& map, const std::vector<RegisterRead>& reads) {
  std::vector<int> seen(map.points.size(), 0);
  for (const RegisterRead& r : reads) {
    EXPECT_LE(r.count, kMaxReadRegisters);
    for (const std::size_t i : r.points) {
      ++seen[i];
      const ModbusPoint& p = map.points[i];
      EXPECT_EQ(p.device, r.device);
      EXPECT_EQ(p.table, r.table);
      EXPECT_GE(p.address, r.address);
      EXPECT_LE(p.address + p.Count(), r.address + r.count);
    }
  }
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "point " << i;
}

TEST(ReadPlan, MergesContiguousPointsAndBridgesSmallGaps) {
  ModbusConfig map = TwoDevices();
  map.points = {At(0, RegisterTable::kInput, 10, RegisterType::kF32),   // 10..11
                At(0, RegisterTable::kInput, 0, RegisterType::kU16),    // 0
                At(0, RegisterTable::kInput, 1, RegisterType::kF64),    // 1..4, gap 5..9 (5)
                At(0, RegisterTable::kInput, 20, RegisterType::kI16),   // gap 12..19 (8): bridged
                At(0, RegisterTable::kInput, 30, RegisterType::kI32)};  // gap 21..29 (9): new read
  const std::vector<RegisterRead> reads = PlanReads(map);
  ASSERT_EQ(reads.size(), 2u);
  EXPECT_EQ(reads[0].address, 0);
  EXPECT_EQ(reads[0].count, 21);
  EXPECT_EQ(reads[0].points, (std::vector<std::size_t>{1, 2, 0, 3}));
  EXPECT_EQ(reads[1].address, 30);
  EXPECT_EQ(reads[1].count, 2);
  ExpectCoversEveryPointOnce(map, reads);
}

TEST(ReadPlan, GapOptionZeroNeedsContiguity) {
  ModbusConfig map = TwoDevices();
  map.points = {At(0, RegisterTable::kInput, 0, RegisterType::kU16),
                At(0, RegisterTable::kInput, 2, RegisterType::kU16)};
  EXPECT_EQ(PlanReads(map, {125, 0}).size(), 2u);
  EXPECT_EQ(PlanReads(map, {125, 1}).size(), 1u);
}

TEST(ReadPlan, SplitsAtTablesDevicesAndThe125RegisterLimit) {
  ModbusConfig map = TwoDevices();
  // 63 contiguous f32 = 126 registers: one read of 62 points (124 registers)
  // and one of the last point.
  for (int i = 0; i < 63; ++i)
    map.points.push_back(At(0, RegisterTable::kInput, 2 * i, RegisterType::kF32));
  map.points.push_back(At(0, RegisterTable::kHolding, 0, RegisterType::kU16));
  map.points.push_back(At(1, RegisterTable::kInput, 0, RegisterType::kU16));
  const std::vector<RegisterRead> reads = PlanReads(map);
  ASSERT_EQ(reads.size(), 4u);
  EXPECT_EQ(reads[0].count, 124);
  EXPECT_EQ(reads[0].points.size(), 62u);
  EXPECT_EQ(reads[1].address, 124);
  EXPECT_EQ(reads[1].count, 2);
  EXPECT_EQ(reads[2].table, RegisterTable::kHolding);
  EXPECT_EQ(reads[3].device, 1u);
  ExpectCoversEveryPointOnce(map, reads);
}

TEST(ReadPlan, ExampleMapNeedsThreeReads) {
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(LoadConfig(std::string(PVTWIN_GOLDEN_DIR) + "/../../config/examples/sim-plant.toml",
                         &config, &errors));
  const std::vector<RegisterRead> reads = PlanReads(config.modbus);
  // collector input 0..15, collector holding 100, weather input 0..11 (gap 6..7 bridged)
  ASSERT_EQ(reads.size(), 3u);
  EXPECT_EQ(reads[0].count, 16);
  EXPECT_EQ(reads[1].address, 100);
  EXPECT_EQ(reads[2].count, 12);
  ExpectCoversEveryPointOnce(config.modbus, reads);
}

}  // namespace
}  // namespace pvtwin
