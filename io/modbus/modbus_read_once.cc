#include "io/modbus/modbus_read_once.h"

#include <array>
#include <cmath>
#include <cstdio>

#include "core/data/physical_limits.h"
#include "core/data/qc.h"
#include "io/modbus/modbus_link.h"
#include "io/modbus/register_codec.h"

namespace pvtwin {

namespace {

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// Why DecodePoint or the physical limits reject the point's value ("" when
// neither does), the same checks in the same order as the poller.
std::string Rejection(const ModbusPoint& p, std::span<const std::uint16_t> words, double area_m2) {
  const double raw = DecodeRaw(p.type, p.word_order, words);
  if (p.nan_value.has_value() && raw == *p.nan_value) {
    return "raw " + Number(raw) + " is the nan_value sentinel";
  }
  const double value = raw * p.scale + p.offset;
  if (!std::isfinite(value)) return "not a number (" + Number(value) + ")";
  if (value < p.valid_min || value > p.valid_max) {
    return Number(value) + " outside the valid range [" + Number(p.valid_min) + ", " +
           Number(p.valid_max) + "]";
  }
  const PhysicalLimit limit = PhysicalLimitOf(p.channel, area_m2);
  const double channel_value = PointToChannelUnit(p, value);
  if (!PassesEdge(p.channel, channel_value, area_m2)) {
    return Number(channel_value) + " outside the physical limits of " +
           std::string(ChannelName(p.channel)) + " [" + Number(limit.lo) + ", " + Number(limit.hi) +
           "]";
  }
  return "";
}

DeviceReading ReadDevice(const ModbusConfig& map, std::size_t d,
                         const std::vector<RegisterRead>& plan, double area_m2) {
  const ModbusDevice& device = map.devices[d];
  DeviceReading out;
  out.device = d;
  const std::string who = device.Endpoint() + " unit " + std::to_string(device.unit_id);
  std::string error;
  modbus_t* ctx = OpenModbus(device, &error);
  if (ctx == nullptr) {
    out.error = who + ": " + error;
    return out;
  }
  std::uint16_t transaction_id = 1;
  for (const RegisterRead& read : plan) {
    if (read.device != d) continue;
    std::array<std::uint16_t, kMaxReadRegisters> buf{};
    const ReadOutcome outcome = ReadModbus(ctx, device, read, &transaction_id, buf);
    if (outcome.status != ReadStatus::kOk) {
      out.error = who + ": read " + std::string(TableName(read.table)) + " address " +
                  std::to_string(read.address) + " count " + std::to_string(read.count) + ": " +
                  outcome.message;
      // A timeout or a stray reply leaves the connection unusable; stop here.
      if (outcome.status != ReadStatus::kException) break;
      continue;
    }
    for (const std::size_t i : read.points) {
      const ModbusPoint& p = map.points[i];
      const auto offset = static_cast<std::size_t>(p.address - read.address);
      const std::span<const std::uint16_t> words(buf.data() + offset,
                                                 static_cast<std::size_t>(p.Count()));
      PointReading r;
      r.point = i;
      r.read = true;
      r.words.assign(words.begin(), words.end());
      r.wire_value = DecodeRaw(p.type, p.word_order, words) * p.scale + p.offset;
      r.rejection = Rejection(p, words, area_m2);
      r.value = r.rejection.empty() ? PointToChannelUnit(p, r.wire_value) : std::nan("");
      if (r.rejection.empty() && IsShortWave(p.channel) && IsIrradianceGlitch(r.value)) {
        r.note =
            "the paper's night glitch (above 5000 W/m²): stored as read, 0 W/m² in the "
            "1-min row";
      }
      out.points.push_back(std::move(r));
    }
  }
  CloseModbus(ctx);
  return out;
}

}  // namespace

std::vector<DeviceReading> ReadEveryDeviceOnce(const ModbusConfig& map, double area_m2,
                                               const ReadPlanOptions& plan_options) {
  const std::vector<RegisterRead> plan = PlanReads(map, plan_options);
  std::vector<DeviceReading> readings;
  for (std::size_t d = 0; d < map.devices.size(); ++d) {
    readings.push_back(ReadDevice(map, d, plan, area_m2));
  }
  return readings;
}

}  // namespace pvtwin
