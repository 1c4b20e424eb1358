// pvtwin poll --once: read every device of the register map once and show
// what the daemon would store, to commission a register map.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "io/modbus/modbus_read_once.h"

namespace pvtwin::cli {

namespace {

struct PollArgs {
  std::string config;
  bool once = false;
};

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// The unit of the point's value as the register map gives it.
std::string WireUnitName(const ModbusPoint& p) {
  switch (p.wire_unit) {
    case WireUnit::kLitrePerHour:
      return "L/h";
    case WireUnit::kCubicMetrePerHour:
      return "m³/h";
    case WireUnit::kChannel:
      break;
  }
  return std::string(kChannels[static_cast<std::size_t>(p.channel)].unit);
}

std::string Registers(const std::vector<std::uint16_t>& words) {
  std::string text;
  for (const std::uint16_t w : words) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%04x", w);
    text += (text.empty() ? "" : " ") + std::string(buf);
  }
  return text;
}

// One line per point: device, channel, value with unit, raw registers, and
// the reason the daemon would reject the value.
std::string PointLine(const ModbusConfig& map, const DeviceReading& device, const PointReading& r) {
  const ModbusPoint& p = map.points[r.point];
  std::string line = map.devices[device.device].name + " " + std::string(p.ChannelNameInMap()) +
                     " (" + std::string(TableName(p.table)) + " " + std::to_string(p.address) +
                     " " + std::string(TypeName(p.type)) + "): ";
  if (!r.rejection.empty()) {
    line += "rejected: " + r.rejection;
  } else {
    line += Number(r.wire_value) + " " + WireUnitName(p);
    if (p.wire_unit != WireUnit::kChannel) line += " = " + Number(r.value) + " kg/s";
    if (!r.note.empty()) line += " (" + r.note + ")";
  }
  return line + "; raw " + Registers(r.words);
}

int Poll(const PollArgs& a) {
  Config config;
  if (!LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  if (config.modbus.devices.empty()) {
    std::cerr << a.config << ": no [[modbus.device]]: nothing to poll\n";
    return kExitBadInput;
  }
  const std::vector<DeviceReading> readings =
      ReadEveryDeviceOnce(config.modbus, config.plant.area_m2);
  int failed = 0;
  for (const DeviceReading& device : readings) {
    for (const PointReading& r : device.points) {
      std::cout << PointLine(config.modbus, device, r) << "\n";
    }
    if (!device.error.empty()) {
      ++failed;
      std::cerr << "device " << config.modbus.devices[device.device].name << " (" << device.error
                << ")\n";
    }
  }
  std::cout << readings.size() - static_cast<std::size_t>(failed) << " of " << readings.size()
            << " device(s) read\n";
  return failed == 0 ? kExitOk : kExitRuntime;
}

}  // namespace

void RegisterPoll(CLI::App& app) {
  auto args = std::make_shared<PollArgs>();
  CLI::App* cmd = app.add_subcommand(
      "poll",
      "Read every Modbus device of the config's register map once, as the daemon's poller\n"
      "does (same read plan, decoding and checks), and print per point: device, channel,\n"
      "value with its unit, the raw registers (hex) and, for a value the daemon would\n"
      "reject, the reason (nan_value sentinel, not a number, valid range, physical limits).\n"
      "Writes nothing. Exit 0 every device answered, 1 a device failed (named on stderr\n"
      "with host:port or serial port, unit id, the read and libmodbus's error), 2 bad config.");
  cmd->add_option("--config", args->config, "TOML config with the register map")->required();
  cmd->add_flag("--once", args->once, "read once and exit (the only mode)")->required();
  cmd->callback([args] { SetExitCode(Poll(*args)); });
}

}  // namespace pvtwin::cli
