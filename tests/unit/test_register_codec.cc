// Register encoding against byte patterns computed by hand from IEEE 754 and
// two's complement (not by the codec): 1.0f = 0x3F800000, -2.5f = 0xC0200000,
// 1.0 = 0x3FF0000000000000, 0x12345678 = 305419896.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/common/units.h"
#include "io/modbus/register_codec.h"

namespace pvtwin {
namespace {

using Words = std::vector<std::uint16_t>;

double Decode(RegisterType type, WordOrder order, const Words& words) {
  return DecodeRaw(type, order, words);
}

Words Encode(RegisterType type, WordOrder order, double raw) {
  Words words(static_cast<std::size_t>(RegisterCount(type)));
  EncodeRaw(type, order, raw, words);
  return words;
}

struct Pattern {
  RegisterType type;
  WordOrder order;
  double value;
  Words words;
};

const Pattern kPatterns[] = {
    // f32 1.0 = 0x3F800000
    {RegisterType::kF32, WordOrder::kABCD, 1.0, {0x3F80, 0x0000}},
    {RegisterType::kF32, WordOrder::kCDAB, 1.0, {0x0000, 0x3F80}},
    {RegisterType::kF32, WordOrder::kBADC, 1.0, {0x803F, 0x0000}},
    {RegisterType::kF32, WordOrder::kDCBA, 1.0, {0x0000, 0x803F}},
    // f32 -2.5 = 0xC0200000
    {RegisterType::kF32, WordOrder::kABCD, -2.5, {0xC020, 0x0000}},
    {RegisterType::kF32, WordOrder::kDCBA, -2.5, {0x0000, 0x20C0}},
    // u32 0x12345678
    {RegisterType::kU32, WordOrder::kABCD, 305419896.0, {0x1234, 0x5678}},
    {RegisterType::kU32, WordOrder::kCDAB, 305419896.0, {0x5678, 0x1234}},
    {RegisterType::kU32, WordOrder::kBADC, 305419896.0, {0x3412, 0x7856}},
    {RegisterType::kU32, WordOrder::kDCBA, 305419896.0, {0x7856, 0x3412}},
    // i32 -2 = 0xFFFFFFFE
    {RegisterType::kI32, WordOrder::kABCD, -2.0, {0xFFFF, 0xFFFE}},
    {RegisterType::kI32, WordOrder::kCDAB, -2.0, {0xFFFE, 0xFFFF}},
    // i32 -123456789 = 0xF8A432EB
    {RegisterType::kI32, WordOrder::kBADC, -123456789.0, {0xA4F8, 0xEB32}},
    // f64 1.0 = 0x3FF0000000000000
    {RegisterType::kF64, WordOrder::kABCD, 1.0, {0x3FF0, 0x0000, 0x0000, 0x0000}},
    {RegisterType::kF64, WordOrder::kCDAB, 1.0, {0x0000, 0x0000, 0x0000, 0x3FF0}},
    {RegisterType::kF64, WordOrder::kBADC, 1.0, {0xF03F, 0x0000, 0x0000, 0x0000}},
    {RegisterType::kF64, WordOrder::kDCBA, 1.0, {0x0000, 0x0000, 0x0000, 0xF03F}},
    // 16-bit: word orders only swap bytes (BADC = DCBA) or not (ABCD = CDAB)
    {RegisterType::kU16, WordOrder::kABCD, 4660.0, {0x1234}},
    {RegisterType::kU16, WordOrder::kCDAB, 4660.0, {0x1234}},
    {RegisterType::kU16, WordOrder::kBADC, 4660.0, {0x3412}},
    {RegisterType::kU16, WordOrder::kDCBA, 4660.0, {0x3412}},
    {RegisterType::kI16, WordOrder::kABCD, -1.0, {0xFFFF}},
    {RegisterType::kI16, WordOrder::kABCD, -32768.0, {0x8000}},
    {RegisterType::kI16, WordOrder::kBADC, -32767.0, {0x0180}},
};

TEST(RegisterCodec, DecodesHandComputedPatterns) {
  for (const Pattern& p : kPatterns) {
    EXPECT_EQ(Decode(p.type, p.order, p.words), p.value)
        << TypeName(p.type) << " " << WordOrderName(p.order);
  }
}

TEST(RegisterCodec, EncodesHandComputedPatterns) {
  for (const Pattern& p : kPatterns) {
    EXPECT_EQ(Encode(p.type, p.order, p.value), p.words)
        << TypeName(p.type) << " " << WordOrderName(p.order) << " " << p.value;
  }
}

TEST(RegisterCodec, F64WordOrdersMoveEveryByte) {
  // Distinct bytes 01 23 45 67 89 AB CD EF show where each one goes.
  const double x = std::bit_cast<double>(std::uint64_t{0x0123456789ABCDEF});
  EXPECT_EQ(Encode(RegisterType::kF64, WordOrder::kABCD, x),
            (Words{0x0123, 0x4567, 0x89AB, 0xCDEF}));
  EXPECT_EQ(Encode(RegisterType::kF64, WordOrder::kCDAB, x),
            (Words{0xCDEF, 0x89AB, 0x4567, 0x0123}));
  EXPECT_EQ(Encode(RegisterType::kF64, WordOrder::kBADC, x),
            (Words{0x2301, 0x6745, 0xAB89, 0xEFCD}));
  EXPECT_EQ(Encode(RegisterType::kF64, WordOrder::kDCBA, x),
            (Words{0xEFCD, 0xAB89, 0x6745, 0x2301}));
  const double back =
      Decode(RegisterType::kF64, WordOrder::kBADC, {0x2301, 0x6745, 0xAB89, 0xEFCD});
  EXPECT_EQ(std::bit_cast<std::uint64_t>(back), std::uint64_t{0x0123456789ABCDEF});
}

TEST(RegisterCodec, IntegersAreRoundedAndClamped) {
  EXPECT_EQ(Encode(RegisterType::kU16, WordOrder::kABCD, 70000), (Words{0xFFFF}));
  EXPECT_EQ(Encode(RegisterType::kU16, WordOrder::kABCD, -5), (Words{0x0000}));
  EXPECT_EQ(Encode(RegisterType::kI16, WordOrder::kABCD, -40000), (Words{0x8000}));
  EXPECT_EQ(Encode(RegisterType::kI16, WordOrder::kABCD, 1.6), (Words{0x0002}));
  EXPECT_EQ(Encode(RegisterType::kU32, WordOrder::kABCD, 5e9), (Words{0xFFFF, 0xFFFF}));
  EXPECT_EQ(Encode(RegisterType::kI32, WordOrder::kABCD, std::nan("")), (Words{0, 0}));
}

ModbusPoint Point(RegisterType type, double scale, double offset) {
  ModbusPoint p;
  p.type = type;
  p.scale = scale;
  p.offset = offset;
  return p;
}

TEST(RegisterCodec, ScaleAndOffset) {
  // raw 2345 (0x0929) · 0.01 = 23.45 °C
  const ModbusPoint t = Point(RegisterType::kI16, 0.01, 0.0);
  EXPECT_DOUBLE_EQ(DecodePoint(t, Words{0x0929}).value, 23.45);
  // raw 1000 · 0.1 − 40 = 60
  const ModbusPoint u = Point(RegisterType::kU16, 0.1, -40.0);
  EXPECT_DOUBLE_EQ(DecodePoint(u, Words{1000}).value, 60.0);
  // The inverse: 23.456 °C at 0.01 °C steps is raw 2346.
  Words words(1);
  EncodePoint(t, 23.456, words);
  EXPECT_EQ(words, Words{2346});
  EncodePoint(u, 60.0, words);
  EXPECT_EQ(words, Words{1000});
}

TEST(RegisterCodec, QcRejectsSentinelNanInfAndRange) {
  ModbusPoint p = Point(RegisterType::kI16, 0.01, 0.0);
  p.nan_value = -32768;
  p.valid_min = -30;
  p.valid_max = 120;
  EXPECT_TRUE(DecodePoint(p, Words{0x8000}).rejected);  // sentinel
  EXPECT_TRUE(std::isnan(DecodePoint(p, Words{0x8000}).value));
  EXPECT_TRUE(DecodePoint(p, Words{12001}).rejected);    // 120.01 > valid_max
  EXPECT_FALSE(DecodePoint(p, Words{12000}).rejected);   // 120 is inside
  EXPECT_FALSE(DecodePoint(p, Words{0xF448}).rejected);  // raw −3000: −30.00, inside
  EXPECT_TRUE(DecodePoint(p, Words{0xF447}).rejected);   // raw −3001: −30.01 < valid_min
  ModbusPoint f = Point(RegisterType::kF32, 1.0, 0.0);
  EXPECT_TRUE(DecodePoint(f, Words{0x7FC0, 0x0000}).rejected);  // quiet NaN
  EXPECT_TRUE(DecodePoint(f, Words{0x7F80, 0x0000}).rejected);  // +Inf
  EXPECT_TRUE(DecodePoint(f, Words{0xFF80, 0x0000}).rejected);  // −Inf
  EXPECT_FALSE(DecodePoint(f, Words{0x3F80, 0x0000}).rejected);
  // A NaN value goes out as the sentinel.
  Words words(1);
  EncodePoint(p, std::nan(""), words);
  EXPECT_EQ(words, Words{0x8000});
}

TEST(RegisterCodec, AngleOfIncidenceIsDegreesOnTheWire) {
  EXPECT_DOUBLE_EQ(WireToChannelUnit(Channel::kAoiRad, 90.0), kPi / 2);
  EXPECT_DOUBLE_EQ(ChannelToWireUnit(Channel::kAoiRad, kPi), 180.0);
  EXPECT_EQ(WireToChannelUnit(Channel::kTInC, 90.0), 90.0);
}

}  // namespace
}  // namespace pvtwin
