#include "io/modbus/register_codec.h"

#include <bit>
#include <cassert>
#include <cmath>
#include <limits>

#include "core/common/units.h"

namespace pvtwin {

namespace {

// The value's bits, most significant first: 16, 32 or 64 of them in a u64.
std::uint64_t Bits(RegisterType type, double raw) {
  const auto clamped = [raw](double lo, double hi) {
    if (std::isnan(raw)) return 0.0;
    return std::fmin(std::fmax(std::nearbyint(raw), lo), hi);
  };
  switch (type) {
    case RegisterType::kU16:
      return static_cast<std::uint64_t>(clamped(0, 65535));
    case RegisterType::kI16:
      return static_cast<std::uint16_t>(static_cast<std::int16_t>(clamped(-32768, 32767)));
    case RegisterType::kU32:
      return static_cast<std::uint64_t>(clamped(0, 4294967295.0));
    case RegisterType::kI32:
      return static_cast<std::uint32_t>(
          static_cast<std::int32_t>(clamped(-2147483648.0, 2147483647.0)));
    case RegisterType::kF32:
      return std::bit_cast<std::uint32_t>(static_cast<float>(raw));
    case RegisterType::kF64:
      return std::bit_cast<std::uint64_t>(raw);
  }
  return 0;
}

double FromBits(RegisterType type, std::uint64_t bits) {
  switch (type) {
    case RegisterType::kU16:
    case RegisterType::kU32:
      return static_cast<double>(bits);
    case RegisterType::kI16:
      return static_cast<std::int16_t>(static_cast<std::uint16_t>(bits));
    case RegisterType::kI32:
      return static_cast<std::int32_t>(static_cast<std::uint32_t>(bits));
    case RegisterType::kF32:
      return std::bit_cast<float>(static_cast<std::uint32_t>(bits));
    case RegisterType::kF64:
      return std::bit_cast<double>(bits);
  }
  return 0.0;
}

std::uint16_t SwapBytes(std::uint16_t w) { return static_cast<std::uint16_t>((w << 8) | (w >> 8)); }

bool ReversesWords(WordOrder order) {
  return order == WordOrder::kCDAB || order == WordOrder::kDCBA;
}
bool SwapsBytes(WordOrder order) { return order == WordOrder::kBADC || order == WordOrder::kDCBA; }

}  // namespace

double DecodeRaw(RegisterType type, WordOrder order, std::span<const std::uint16_t> words) {
  const std::size_t n = static_cast<std::size_t>(RegisterCount(type));
  assert(words.size() == n);
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < n; ++i) {
    // Word i of the ABCD (big-endian) sequence.
    std::uint16_t w = words[ReversesWords(order) ? n - 1 - i : i];
    if (SwapsBytes(order)) w = SwapBytes(w);
    bits = (bits << 16) | w;
  }
  return FromBits(type, bits);
}

void EncodeRaw(RegisterType type, WordOrder order, double raw, std::span<std::uint16_t> words) {
  const std::size_t n = static_cast<std::size_t>(RegisterCount(type));
  assert(words.size() == n);
  const std::uint64_t bits = Bits(type, raw);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint16_t w = static_cast<std::uint16_t>(bits >> (16 * (n - 1 - i)));
    if (SwapsBytes(order)) w = SwapBytes(w);
    words[ReversesWords(order) ? n - 1 - i : i] = w;
  }
}

DecodedValue DecodePoint(const ModbusPoint& point, std::span<const std::uint16_t> words) {
  const double raw = DecodeRaw(point.type, point.word_order, words);
  const double value = raw * point.scale + point.offset;
  const bool sentinel = point.nan_value.has_value() && raw == *point.nan_value;
  if (sentinel || !std::isfinite(value) || value < point.valid_min || value > point.valid_max) {
    return {std::numeric_limits<double>::quiet_NaN(), true};
  }
  return {value, false};
}

void EncodePoint(const ModbusPoint& point, double value, std::span<std::uint16_t> words) {
  double raw = (value - point.offset) / point.scale;
  if (std::isnan(value) && point.nan_value.has_value()) raw = *point.nan_value;
  EncodeRaw(point.type, point.word_order, raw, words);
}

double WireToChannelUnit(Channel channel, double wire_value) {
  return channel == Channel::kAoiRad ? DegToRad(wire_value) : wire_value;
}

double ChannelToWireUnit(Channel channel, double channel_value) {
  return channel == Channel::kAoiRad ? RadToDeg(channel_value) : channel_value;
}

namespace {
// kg/s per wire unit of volume flow.
double KgSPerWireUnit(const ModbusPoint& point) {
  switch (point.wire_unit) {
    case WireUnit::kLitrePerHour:
      return point.fluid_density_kg_m3 / 1000.0 / 3600.0;
    case WireUnit::kCubicMetrePerHour:
      return point.fluid_density_kg_m3 / 3600.0;
    case WireUnit::kChannel:
      break;
  }
  return 1.0;
}
}  // namespace

double PointToChannelUnit(const ModbusPoint& point, double wire_value) {
  return WireToChannelUnit(point.channel, wire_value) * KgSPerWireUnit(point);
}

double ChannelToPointUnit(const ModbusPoint& point, double channel_value) {
  return ChannelToWireUnit(point.channel, channel_value) / KgSPerWireUnit(point);
}

}  // namespace pvtwin
