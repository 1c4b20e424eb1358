// Values in Modbus registers: the typed encoding of one register-map point
// (config/modbus_config.h), written on 16-bit words so that no byte order of
// the host or of libmodbus's float helpers leaks in (libmodbus 3.1.6's plain
// modbus_get_float() is CDAB).
//
// Byte order. A value of n words (u16/i16: 1, u32/i32/f32: 2, f64: 4) is the
// big-endian byte sequence b0 b1 … b(2n−1) of its two's-complement or IEEE 754
// representation. On the wire, word i is:
//   ABCD  b(2i)   b(2i+1)          big-endian words in big-endian order
//   CDAB  word n−1−i of ABCD       words reversed ("word swap")
//   BADC  b(2i+1) b(2i)            bytes swapped within each word
//   DCBA  word n−1−i of BADC       fully little-endian
// For 32 bits this is the usual naming (A = most significant byte); for one
// word CDAB = ABCD and DCBA = BADC.
//
// Scaling and QC: value = raw · scale + offset. A decoded value is rejected
// (not a number for the store, the Sample's QC bit set) when raw equals the
// point's nan_value sentinel, when value is NaN or ±Inf, or when it lies
// outside [valid_min, valid_max].
#pragma once

#include <cstdint>
#include <span>

#include "config/modbus_config.h"
#include "core/common/channels.h"

namespace pvtwin {

// The raw value (before scale and offset) in words.size() == RegisterCount(type)
// words. Integers are exact in a double.
double DecodeRaw(RegisterType type, WordOrder order, std::span<const std::uint16_t> words);

// Inverse of DecodeRaw. Integer types take raw rounded to the nearest integer
// and clamped to the type's range (NaN → 0); f32 rounds to float.
void EncodeRaw(RegisterType type, WordOrder order, double raw, std::span<std::uint16_t> words);

struct DecodedValue {
  double value = 0.0;     // raw · scale + offset, in the wire unit; NaN when rejected
  bool rejected = false;  // sentinel, NaN/Inf or outside the valid range
};

DecodedValue DecodePoint(const ModbusPoint& point, std::span<const std::uint16_t> words);

// What a device sends for `value` (wire unit): raw = (value − offset) / scale,
// encoded as EncodeRaw does. A NaN value is sent as the nan_value sentinel when
// the point has one, as NaN for float types, and as raw 0 otherwise.
void EncodePoint(const ModbusPoint& point, double value, std::span<std::uint16_t> words);

// Channel values in core (Sample, Series) use radians for the angle of
// incidence; the register map, like the canonical CSV, uses degrees.
double WireToChannelUnit(Channel channel, double wire_value);
double ChannelToWireUnit(Channel channel, double channel_value);

// The same for a point of the register map, whose value may also be a volume
// flow (L/h, m³/h) feeding flow_kg_s through its fluid density.
double PointToChannelUnit(const ModbusPoint& point, double wire_value);
double ChannelToPointUnit(const ModbusPoint& point, double channel_value);

}  // namespace pvtwin
