// The Modbus register map of the daemon's config (doc/contracts.md, "Modbus register
// map"): devices, and points that say which registers of which device feed
// which canonical channel, and how to decode them.
//
//   [[modbus.device]]  name (required, unique); either host (+ port, default
//                      502) for Modbus TCP, or serial (+ baud 19200, parity
//                      "N" | "E" | "O", data_bits 7 | 8, stop_bits 1 | 2) for
//                      RTU; unit_id 0..247 (default 1); timeout_ms 10..60000
//                      (default 500, wall-clock time of one request).
//   [[modbus.point]]   device, channel (canonical, core/channels.h), table
//                      "input" | "holding", address 0..65535 (0-based wire
//                      address), type u16 i16 u32 i32 f32 f64, word_order
//                      ABCD | CDAB | BADC | DCBA (default ABCD), scale (≠ 0,
//                      default 1), offset (default 0): value = raw·scale +
//                      offset; valid_min / valid_max (decoded values outside
//                      are rejected), nan_value (a raw value, before scale,
//                      that the device sends for "no reading").
//
// Units on the wire are the canonical CSV units: aoi_deg in degrees (the
// poller converts to radians, as the CSV reader does), flow in kg/s. A
// volume-flow meter is mapped as channel flow_l_h or flow_m3_h: the point
// feeds flow_kg_s, its value (valid range and nan_value in L/h or m³/h) times
// [plant] fluid_density_kg_m3 (ParseConfig copies it into every point).
//
// Validation (modbus_config.cc) reports, all at once with file:line: unknown
// keys, bad values, a point on an unknown device, a channel outside the
// canonical list, the same channel twice, registers of two points overlapping
// on one device and table, and a device with both or neither of host and
// serial.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/channels.h"

namespace pvtwin {

enum class RegisterTable { kInput, kHolding };  // function code 4 | 3
enum class RegisterType { kU16, kI16, kU32, kI32, kF32, kF64 };
// Byte order of a value on the wire, written for 32 bits with A the most
// significant byte (see io/modbus/register_codec.h for 16 and 64 bits).
enum class WordOrder { kABCD, kCDAB, kBADC, kDCBA };
// The unit of a point's decoded value: the channel's own, or a volume flow
// that feeds flow_kg_s through the fluid density.
enum class WireUnit { kChannel, kLitrePerHour, kCubicMetrePerHour };

std::string_view TableName(RegisterTable table);
std::string_view TypeName(RegisterType type);
std::string_view WordOrderName(WordOrder order);
// Registers (16-bit words) a value of the type occupies: 1, 2 or 4.
int RegisterCount(RegisterType type);

struct ModbusDevice {
  std::string name;
  // TCP: host and port. RTU: serial device and line settings.
  std::string host;
  int port = 502;
  std::string serial;
  int baud = 19200;
  char parity = 'N';  // 'N', 'E' or 'O'
  int data_bits = 8;
  int stop_bits = 1;
  int unit_id = 1;
  int timeout_ms = 500;
  int line = 0;  // config line of the [[modbus.device]] table

  bool IsRtu() const { return !serial.empty(); }
  // "127.0.0.1:502" or "/dev/ttyUSB0@19200,8N1", for log lines.
  std::string Endpoint() const;
};

struct ModbusPoint {
  std::size_t device = 0;  // index into ModbusConfig::devices
  Channel channel = Channel::kTInC;
  RegisterTable table = RegisterTable::kInput;
  int address = 0;
  RegisterType type = RegisterType::kU16;
  WordOrder word_order = WordOrder::kABCD;
  double scale = 1.0;
  double offset = 0.0;
  double valid_min = -std::numeric_limits<double>::infinity();
  double valid_max = std::numeric_limits<double>::infinity();
  std::optional<double> nan_value;  // raw sentinel
  WireUnit wire_unit = WireUnit::kChannel;
  double fluid_density_kg_m3 = 1040.0;  // volume flow to kg/s: [plant] fluid_density_kg_m3
  int line = 0;                         // config line of the [[modbus.point]] table

  int Count() const { return RegisterCount(type); }
  // The name the register map gives the channel: flow_l_h, flow_m3_h or the
  // canonical one.
  std::string_view ChannelNameInMap() const;
};

struct ModbusConfig {
  std::vector<ModbusDevice> devices;
  std::vector<ModbusPoint> points;  // in file order

  bool empty() const { return devices.empty() && points.empty(); }
};

}  // namespace pvtwin
