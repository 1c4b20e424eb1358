#include "config/modbus_config.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <utility>

#include "config/toml_reader.h"

namespace pvtwin {

namespace {

constexpr std::array<std::string_view, 2> kTableNames = {"input", "holding"};
constexpr std::array<std::string_view, 6> kTypeNames = {"u16", "i16", "u32", "i32", "f32", "f64"};
constexpr std::array<std::string_view, 4> kOrderNames = {"ABCD", "CDAB", "BADC", "DCBA"};

template <typename Enum, std::size_t N>
Enum FromName(const std::array<std::string_view, N>& names, std::string_view name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return static_cast<Enum>(it - names.begin());
}

template <std::size_t N>
std::vector<std::string_view> Choices(const std::array<std::string_view, N>& names) {
  return {names.begin(), names.end()};
}

}  // namespace

std::string_view TableName(RegisterTable table) {
  return kTableNames[static_cast<std::size_t>(table)];
}
std::string_view TypeName(RegisterType type) { return kTypeNames[static_cast<std::size_t>(type)]; }
std::string_view WordOrderName(WordOrder order) {
  return kOrderNames[static_cast<std::size_t>(order)];
}

std::string_view ModbusPoint::ChannelNameInMap() const {
  switch (wire_unit) {
    case WireUnit::kLitrePerHour:
      return "flow_l_h";
    case WireUnit::kCubicMetrePerHour:
      return "flow_m3_h";
    case WireUnit::kChannel:
      break;
  }
  return ChannelName(channel);
}

int RegisterCount(RegisterType type) {
  switch (type) {
    case RegisterType::kU16:
    case RegisterType::kI16:
      return 1;
    case RegisterType::kU32:
    case RegisterType::kI32:
    case RegisterType::kF32:
      return 2;
    case RegisterType::kF64:
      return 4;
  }
  return 1;
}

std::string ModbusDevice::Endpoint() const {
  if (IsRtu()) {
    return serial + "@" + std::to_string(baud) + "," + std::to_string(data_bits) + parity +
           std::to_string(stop_bits);
  }
  return host + ":" + std::to_string(port);
}

namespace config_detail {
namespace {

using pvtwin::config_detail::Interval;

constexpr int kStandardBauds[] = {1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200};

// Host names and IP literals: letters, digits, '.', '-', ':' (IPv6).
bool IsHostName(std::string_view host) {
  return std::all_of(host.begin(), host.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
           c == '-' || c == ':';
  });
}

std::string CanonicalChannelList() {
  std::string list;
  for (const ChannelInfo& info : kChannels) {
    list += (list.empty() ? "" : ", ") + std::string(info.name);
  }
  return list + "; or flow_l_h, flow_m3_h for a volume flow";
}

// One [[modbus.*]] array: its tables, or an error when it is something else.
std::vector<const toml::table*> TablesOf(const toml::node& node, std::string_view key,
                                         const SourceText& source, const std::string& file,
                                         Diagnostics* errors) {
  std::vector<const toml::table*> tables;
  const auto* array = node.as_array();
  if (array != nullptr) {
    for (const toml::node& element : *array) {
      if (const auto* table = element.as_table()) {
        tables.push_back(table);
      } else {
        array = nullptr;
        break;
      }
    }
  }
  if (array == nullptr) {
    errors->push_back({file, static_cast<int>(node.source().begin.line),
                       "modbus." + std::string(key),
                       node.is_table() ? "" : source.Quote(node.source()),
                       "expected an array of tables [[modbus." + std::string(key) + "]]"});
    tables.clear();
  }
  return tables;
}

void ReadDevice(SectionReader& r, const std::string& file, ModbusDevice* d, Diagnostics* errors) {
  r.String("name", kRequired, &d->name);
  const bool has_host = r.String("host", kOptional, &d->host);
  const bool has_serial = r.String("serial", kOptional, &d->serial);
  if (has_host && !IsHostName(d->host)) r.Reject("host", "expected an IP address or host name");
  if (has_serial && !d->serial.starts_with("/")) {
    r.Reject("serial", "expected the absolute path of a serial device, e.g. /dev/ttyUSB0");
  }
  if (has_host && has_serial) {
    r.Reject("serial", "a device is either TCP (host) or RTU (serial), not both");
  }
  if (!has_host && !has_serial && r.Written("host").empty() && r.Written("serial").empty()) {
    errors->push_back(
        {file, d->line, "host", "", "required key missing: host (TCP) or serial (RTU)"});
  }
  // Keys of the other transport are errors rather than silently ignored.
  const auto only_for = [&](std::string_view key, bool allowed, std::string_view transport) {
    if (!allowed && !r.Written(key).empty()) {
      r.Reject(key, "only for " + std::string(transport) + " devices");
    }
  };
  r.Integer("port", kOptional, Closed(1, 65535), &d->port);
  only_for("port", !has_serial, "TCP (host)");
  if (r.Integer("baud", kOptional, Closed(1, 4000000), &d->baud) &&
      std::find(std::begin(kStandardBauds), std::end(kStandardBauds), d->baud) ==
          std::end(kStandardBauds)) {
    r.Reject("baud",
             "expected a standard rate: 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200");
  }
  std::string parity = "N";
  if (r.Choice("parity", kOptional, {"N", "E", "O"}, &parity)) d->parity = parity[0];
  r.Integer("data_bits", kOptional, Closed(7, 8), &d->data_bits);
  r.Integer("stop_bits", kOptional, Closed(1, 2), &d->stop_bits);
  for (std::string_view key : {"baud", "parity", "data_bits", "stop_bits"}) {
    only_for(key, !has_host, "serial (RTU)");
  }
  if (r.Integer("unit_id", kOptional, Closed(0, 255), &d->unit_id) && has_serial &&
      (d->unit_id < 1 || d->unit_id > 247)) {
    r.Reject("unit_id", "an RTU unit id must be within [1, 247]");
  }
  r.Integer("timeout_ms", kOptional, Closed(10, 60000), &d->timeout_ms);
}

// "" when the register type can hold the raw sentinel *raw, so that a
// decoded register can equal it; else the rule it breaks. An f32 sentinel is
// rounded to float (the decoder compares the float it read, widened to
// double: 0.1 would never match 0.1f), and the spellings of ±FLT_MAX that
// round to it (3.4028235e38) are taken.
std::string SentinelRule(RegisterType type, double* raw) {
  const auto integer_within = [raw, type](double lo, double hi) -> std::string {
    if (*raw >= lo && *raw <= hi && std::trunc(*raw) == *raw) return "";
    return "must be an integer within [" + FormatNumber(lo) + ", " + FormatNumber(hi) +
           "], the range of " + std::string(TypeName(type));
  };
  switch (type) {
    case RegisterType::kU16:
      return integer_within(0, std::numeric_limits<std::uint16_t>::max());
    case RegisterType::kI16:
      return integer_within(std::numeric_limits<std::int16_t>::min(),
                            std::numeric_limits<std::int16_t>::max());
    case RegisterType::kU32:
      return integer_within(0, std::numeric_limits<std::uint32_t>::max());
    case RegisterType::kI32:
      return integer_within(std::numeric_limits<std::int32_t>::min(),
                            std::numeric_limits<std::int32_t>::max());
    case RegisterType::kF32: {
      // Halfway between FLT_MAX and 2^128, the next binade: above it a
      // double rounds to infinity as a float.
      const double max = std::numeric_limits<float>::max();
      const double overflow = std::ldexp(1.0, 128) - std::ldexp(1.0, 103);
      if (!(std::abs(*raw) < overflow)) {
        return "must be within the range of f32, |x| <= " + FormatNumber(max);
      }
      *raw = std::abs(*raw) > max ? std::copysign(max, *raw)
                                  : static_cast<double>(static_cast<float>(*raw));
      return "";
    }
    case RegisterType::kF64:
      return "";
  }
  return "";
}

// Reads one point; returns false when a key the cross-checks need is bad.
bool ReadPoint(SectionReader& r, const std::vector<ModbusDevice>& devices, ModbusPoint* p) {
  bool ok = true;
  std::string device;
  if (r.String("device", kRequired, &device)) {
    const auto it = std::find_if(devices.begin(), devices.end(),
                                 [&](const ModbusDevice& d) { return d.name == device; });
    if (it == devices.end()) {
      r.Reject("device", "no [[modbus.device]] has this name");
      ok = false;
    } else {
      p->device = static_cast<std::size_t>(it - devices.begin());
    }
  } else {
    ok = false;
  }
  std::string channel;
  if (r.String("channel", kRequired, &channel)) {
    if (const std::optional<Channel> c = ChannelFromName(channel)) {
      p->channel = *c;
    } else if (channel == "flow_l_h" || channel == "flow_m3_h") {
      p->channel = Channel::kMdotKgS;
      p->wire_unit = channel == "flow_l_h" ? WireUnit::kLitrePerHour : WireUnit::kCubicMetrePerHour;
    } else {
      r.Reject("channel", "not a canonical channel (" + CanonicalChannelList() + ")");
      ok = false;
    }
  } else {
    ok = false;
  }
  std::string text;
  if (r.Choice("table", kRequired, Choices(kTableNames), &text)) {
    p->table = FromName<RegisterTable>(kTableNames, text);
  } else {
    ok = false;
  }
  const bool type_ok = r.Choice("type", kRequired, Choices(kTypeNames), &text);
  if (type_ok) {
    p->type = FromName<RegisterType>(kTypeNames, text);
  } else {
    ok = false;
  }
  if (!r.Integer("address", kRequired, Closed(0, 65535), &p->address)) ok = false;
  if (ok && p->address + p->Count() > 65536) {
    r.Reject("address", "a " + std::string(TypeName(p->type)) + " needs " +
                            std::to_string(p->Count()) + " registers, past the last address 65535");
    ok = false;
  }
  if (r.Choice("word_order", kOptional, Choices(kOrderNames), &text)) {
    p->word_order = FromName<WordOrder>(kOrderNames, text);
  }
  // Wide enough for any meter's scaling (a u32 counter in Wh to W needs
  // 3600), narrow enough that a typo like 1e308 cannot turn a register into
  // infinity.
  constexpr Interval kScaling = Closed(-1e9, 1e9);
  if (r.Number("scale", kOptional, kScaling, &p->scale) && p->scale == 0.0) {
    r.Reject("scale", "must not be 0");
  }
  r.Number("offset", kOptional, kScaling, &p->offset);
  r.Number("valid_min", kOptional, kScaling, &p->valid_min);
  if (r.Number("valid_max", kOptional, kScaling, &p->valid_max) && !(p->valid_max > p->valid_min)) {
    r.Reject("valid_max", "must be > valid_min");
  }
  double sentinel = 0.0;
  if (r.Number("nan_value", kOptional, Interval{}, &sentinel) && type_ok) {
    const std::string rule = SentinelRule(p->type, &sentinel);
    if (rule.empty()) {
      p->nan_value = sentinel;
    } else {
      r.Reject("nan_value", rule);
    }
  }
  return ok;
}

std::string RegisterRange(const ModbusPoint& p) {
  return std::to_string(p.address) + ".." + std::to_string(p.address + p.Count() - 1);
}

}  // namespace

void ReadModbusSection(const toml::node& node, const SourceText& source, const std::string& file,
                       ModbusConfig* out, Diagnostics* errors) {
  const toml::table* modbus = node.as_table();
  if (modbus == nullptr) {
    errors->push_back({file, static_cast<int>(node.source().begin.line), "modbus",
                       source.Quote(node.source()),
                       "expected [[modbus.device]] and [[modbus.point]] tables"});
    return;
  }
  std::vector<const toml::table*> device_tables;
  std::vector<const toml::table*> point_tables;
  for (const auto& [key, child] : *modbus) {
    if (key.str() == "device") {
      device_tables = TablesOf(child, "device", source, file, errors);
    } else if (key.str() == "point") {
      point_tables = TablesOf(child, "point", source, file, errors);
    } else {
      errors->push_back({file, static_cast<int>(child.source().begin.line),
                         "modbus." + std::string(key.str()),
                         child.is_table() ? "" : source.Quote(child.source()),
                         child.is_table() ? "unknown section" : "unknown key"});
    }
  }

  ModbusConfig config;
  for (const toml::table* table : device_tables) {
    SectionReader r(*table, source, file, errors);
    ModbusDevice device;
    device.line = static_cast<int>(table->source().begin.line);
    ReadDevice(r, file, &device, errors);
    r.ReportUnknownKeys();
    const auto same = std::find_if(config.devices.begin(), config.devices.end(),
                                   [&](const ModbusDevice& d) { return d.name == device.name; });
    if (!device.name.empty() && same != config.devices.end()) {
      r.Reject("name", "device name already used at line " + std::to_string(same->line));
    }
    config.devices.push_back(device);
  }

  std::map<Channel, int> channel_line;  // first point feeding each channel
  for (const toml::table* table : point_tables) {
    SectionReader r(*table, source, file, errors);
    ModbusPoint point;
    point.line = static_cast<int>(table->source().begin.line);
    const bool ok = ReadPoint(r, config.devices, &point);
    r.ReportUnknownKeys();
    if (!ok) continue;
    const auto [it, inserted] = channel_line.emplace(point.channel, r.Line("channel"));
    if (!inserted) {
      r.Reject("channel", "channel already fed by the point at line " + std::to_string(it->second));
      continue;
    }
    for (const ModbusPoint& other : config.points) {
      if (other.device != point.device || other.table != point.table) continue;
      if (point.address < other.address + other.Count() &&
          other.address < point.address + point.Count()) {
        r.Reject("address",
                 "registers " + RegisterRange(point) + " overlap registers " +
                     RegisterRange(other) + " of " + std::string(other.ChannelNameInMap()) +
                     " (line " + std::to_string(other.line) + ") on " +
                     config.devices[point.device].name + " " + std::string(TableName(point.table)));
        break;
      }
    }
    config.points.push_back(point);
  }
  *out = std::move(config);
}

}  // namespace config_detail
}  // namespace pvtwin
