// One read of every device of the register map, for `pvtwin poll --once`:
// the poller's read plan, connection and reads (io/modbus/modbus_link.h) and
// decoding, without its threads, clock, backoff or frozen check. Each point
// comes back with its raw registers, its value and, when the poller would
// reject it, the reason; each device that cannot be read with the read and
// libmodbus's (or the reply check's) message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "config/modbus_config.h"
#include "io/modbus/read_plan.h"

namespace pvtwin {

struct PointReading {
  std::size_t point = 0;             // index into ModbusConfig::points
  bool read = false;                 // its registers came back
  std::vector<std::uint16_t> words;  // the raw registers as received
  double value = 0.0;                // in the channel's unit (core's: aoi in rad); NaN rejected
  double wire_value = 0.0;           // raw · scale + offset, before any unit conversion
  std::string rejection;             // why the poller would reject it; "" when it would not
  std::string note;                  // what becomes of a kept value ("" when nothing)
};

struct DeviceReading {
  std::size_t device = 0;  // index into ModbusConfig::devices
  std::string error;       // "" when every read was answered
  std::vector<PointReading> points;
};

// area_m2 scales the physical limits of flow and power (0: unknown), as
// PollerOptions::area_m2 does.
std::vector<DeviceReading> ReadEveryDeviceOnce(const ModbusConfig& map, double area_m2,
                                               const ReadPlanOptions& plan = {});

}  // namespace pvtwin
