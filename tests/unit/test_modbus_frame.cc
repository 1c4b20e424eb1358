// The Modbus TCP read codec (io/modbus/modbus_frame.h) against the worked example of
// the Modbus Application Protocol V1.1b3, §6.3 "Read Holding Registers":
// request PDU 03 00 6B 00 03 (registers 108-110, PDU address 0x006B), reply
// PDU 03 06 02 2B 00 00 00 64 (555, 0, 100), wrapped in the MBAP header of
// the TCP Implementation Guide (length = unit id + PDU = 6 and 9). Then every
// way a reply can fail to belong to its request.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/modbus/modbus_frame.h"

namespace pvtwin {
namespace {

using Bytes = std::vector<std::uint8_t>;

// The spec's request, transaction id 0x1234, unit 1.
ReadRequest SpecRequest() {
  ReadRequest r;
  r.transaction_id = 0x1234;
  r.unit_id = 1;
  r.function = 3;
  r.address = 0x006B;
  r.count = 3;
  return r;
}

// The spec's reply PDU in an MBAP header; each test breaks one field.
Bytes SpecReply() {
  return {0x12, 0x34, 0x00, 0x00, 0x00, 0x09, 0x01,         // MBAP
          0x03, 0x06, 0x02, 0x2B, 0x00, 0x00, 0x00, 0x64};  // PDU
}

ReplyCheck Check(const Bytes& reply) { return CheckReadReply(SpecRequest(), reply); }

TEST(ModbusFrame, RequestIsTheSpecExampleByteForByte) {
  const auto adu = EncodeReadRequest(SpecRequest());
  const std::array<std::uint8_t, 12> expected = {0x12, 0x34, 0x00, 0x00, 0x00, 0x06,
                                                 0x01, 0x03, 0x00, 0x6B, 0x00, 0x03};
  EXPECT_EQ(adu, expected);
}

TEST(ModbusFrame, InputRegisterRequestCarriesFunction4AndFullRange) {
  ReadRequest r;
  r.transaction_id = 0xFFFF;
  r.unit_id = 247;
  r.function = 4;
  r.address = 0xFFFF;
  r.count = 125;
  const auto adu = EncodeReadRequest(r);
  const std::array<std::uint8_t, 12> expected = {0xFF, 0xFF, 0x00, 0x00, 0x00, 0x06,
                                                 0xF7, 0x04, 0xFF, 0xFF, 0x00, 0x7D};
  EXPECT_EQ(adu, expected);
}

TEST(ModbusFrame, SpecReplyDecodesTo555And0And100) {
  const Bytes reply = SpecReply();
  const ReplyCheck check = Check(reply);
  ASSERT_TRUE(check.ok()) << check.message();
  ASSERT_EQ(check.register_bytes.size(), 6u);
  std::array<std::uint16_t, 3> words{};
  DecodeRegisterWords(check, words);
  EXPECT_EQ(words, (std::array<std::uint16_t, 3>{555, 0, 100}));
}

TEST(ModbusFrame, HighBitWordsDecodeBigEndian) {
  ReadRequest r = SpecRequest();
  r.count = 2;
  const Bytes reply = {0x12, 0x34, 0x00, 0x00, 0x00, 0x07, 0x01,
                       0x03, 0x04, 0xFF, 0x01, 0x80, 0x00};
  const ReplyCheck check = CheckReadReply(r, reply);
  ASSERT_TRUE(check.ok()) << check.message();
  std::array<std::uint16_t, 2> words{};
  DecodeRegisterWords(check, words);
  EXPECT_EQ(words[0], 0xFF01);
  EXPECT_EQ(words[1], 0x8000);
}

struct Rejection {
  const char* what;
  Bytes reply;
  ReplyStatus status;
  const char* message;
};

// One field broken per case, starting from the spec reply.
std::vector<Rejection> Rejections() {
  std::vector<Rejection> cases;
  const auto with = [](std::size_t at, std::uint8_t value) {
    Bytes b = SpecReply();
    b[at] = value;
    return b;
  };
  cases.push_back({"wrong transaction id", with(1, 0x35), ReplyStatus::kTransactionId,
                   "reply transaction id 4661, expected 4660"});
  cases.push_back({"protocol id 7", with(3, 0x07), ReplyStatus::kProtocolId,
                   "reply protocol id 7, expected 0"});
  cases.push_back({"protocol id 0x0100", with(2, 0x01), ReplyStatus::kProtocolId,
                   "reply protocol id 256, expected 0"});
  cases.push_back(
      {"length 0", with(5, 0x00), ReplyStatus::kLength, "reply MBAP length 0, expected 2..254"});
  Bytes len_max = SpecReply();
  len_max[4] = 0xFF;
  len_max[5] = 0xFF;
  cases.push_back(
      {"length 65535", len_max, ReplyStatus::kLength, "reply MBAP length 65535, expected 2..254"});
  cases.push_back({"length one short", with(5, 0x08), ReplyStatus::kLength,
                   "reply MBAP length 8, but 9 bytes follow it"});
  cases.push_back({"length one long", with(5, 0x0A), ReplyStatus::kLength,
                   "reply MBAP length 10, but 9 bytes follow it"});
  cases.push_back(
      {"wrong unit", with(6, 0x07), ReplyStatus::kUnitId, "reply unit id 7, expected 1"});
  cases.push_back(
      {"wrong function", with(7, 0x04), ReplyStatus::kFunction, "reply function 4, expected 3"});
  cases.push_back({"exception of another function", with(7, 0x84), ReplyStatus::kFunction,
                   "reply function 132, expected 3"});
  // Byte count 4 with the MBAP length and the data shortened to match: only
  // the byte count is wrong.
  const Bytes short_count = {0x12, 0x34, 0x00, 0x00, 0x00, 0x07, 0x01,
                             0x03, 0x04, 0x02, 0x2B, 0x00, 0x00};
  cases.push_back({"short byte count", short_count, ReplyStatus::kByteCount,
                   "reply byte count 4, expected 6 for 3 registers"});
  // Byte count right, one data byte missing, length consistent with the bytes.
  const Bytes short_data = {0x12, 0x34, 0x00, 0x00, 0x00, 0x08, 0x01,
                            0x03, 0x06, 0x02, 0x2B, 0x00, 0x00, 0x00};
  cases.push_back({"data shorter than the byte count", short_data, ReplyStatus::kLength,
                   "reply MBAP length 8, expected 9 for byte count 6"});
  cases.push_back({"header cut", Bytes{0x12, 0x34, 0x00, 0x00, 0x00, 0x09}, ReplyStatus::kTruncated,
                   "reply of 6 bytes, shorter than the 7-byte header"});
  const Bytes no_byte_count = {0x12, 0x34, 0x00, 0x00, 0x00, 0x02, 0x01, 0x03};
  cases.push_back({"no byte count", no_byte_count, ReplyStatus::kTruncated,
                   "reply MBAP length 2, no byte count"});
  const Bytes long_exception = {0x12, 0x34, 0x00, 0x00, 0x00, 0x04, 0x01, 0x83, 0x02, 0x00};
  cases.push_back({"exception with a trailing byte", long_exception, ReplyStatus::kLength,
                   "exception reply MBAP length 4, expected 3"});
  return cases;
}

TEST(ModbusFrame, RejectsEveryBrokenField) {
  for (const Rejection& c : Rejections()) {
    SCOPED_TRACE(c.what);
    const ReplyCheck check = Check(c.reply);
    EXPECT_FALSE(check.ok());
    EXPECT_EQ(ReplyStatusName(check.status), ReplyStatusName(c.status));
    EXPECT_EQ(check.message(), c.message);
    EXPECT_TRUE(check.register_bytes.empty());
  }
}

TEST(ModbusFrame, ExceptionReplyCarriesItsCode) {
  const Bytes reply = {0x12, 0x34, 0x00, 0x00, 0x00, 0x03, 0x01, 0x83, 0x02};
  const ReplyCheck check = Check(reply);
  EXPECT_EQ(check.status, ReplyStatus::kException);
  EXPECT_EQ(check.exception_code, 2);
  EXPECT_EQ(check.message(), "exception 2 (illegal data address) to function 3");
  EXPECT_TRUE(check.register_bytes.empty());
}

TEST(ModbusFrame, ExceptionFromAnotherUnitIsAUnitMismatch) {
  const Bytes reply = {0x12, 0x34, 0x00, 0x00, 0x00, 0x03, 0x09, 0x83, 0x02};
  EXPECT_EQ(Check(reply).status, ReplyStatus::kUnitId);
}

// The header check alone decides before any body is read: a reader that
// trusted length 65535 would wait for 65 kB.
TEST(ModbusFrame, HeaderCheckRefusesLengthsBeforeTheBody) {
  const ReadRequest r = SpecRequest();
  for (const int length : {0, 1, 255, 65535}) {
    const Bytes header = {0x12,
                          0x34,
                          0x00,
                          0x00,
                          static_cast<std::uint8_t>(length >> 8),
                          static_cast<std::uint8_t>(length & 0xFF),
                          0x01};
    const ReplyCheck check = CheckReplyHeader(r, header);
    EXPECT_EQ(check.status, ReplyStatus::kLength) << length;
  }
  for (const int length : {2, 254}) {
    const Bytes header = {0x12, 0x34, 0x00, 0x00, 0x00, static_cast<std::uint8_t>(length), 0x01};
    ASSERT_TRUE(CheckReplyHeader(r, header).ok()) << length;
    EXPECT_EQ(ReplyBodyBytes(header), static_cast<std::size_t>(length - 1));
  }
}

// No prefix of a valid reply and no reply with a byte appended is accepted.
TEST(ModbusFrame, EveryTruncationAndExtensionIsRejected) {
  const Bytes full = SpecReply();
  for (std::size_t n = 0; n < full.size(); ++n) {
    const Bytes prefix(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_FALSE(Check(prefix).ok()) << n << " bytes";
  }
  Bytes longer = full;
  longer.push_back(0x00);
  EXPECT_EQ(Check(longer).status, ReplyStatus::kLength);
}

// A full 125-register reply: the largest the protocol allows (length 253).
TEST(ModbusFrame, LargestReadIsAccepted) {
  ReadRequest r = SpecRequest();
  r.count = kMaxReadRegisterCount;
  Bytes reply = {0x12, 0x34, 0x00, 0x00, 0x00, 253, 0x01, 0x03, 250};
  for (int i = 0; i < kMaxReadRegisterCount; ++i) {
    reply.push_back(static_cast<std::uint8_t>(i >> 8));
    reply.push_back(static_cast<std::uint8_t>(i));
  }
  const ReplyCheck check = CheckReadReply(r, reply);
  ASSERT_TRUE(check.ok()) << check.message();
  std::array<std::uint16_t, kMaxReadRegisterCount> words{};
  DecodeRegisterWords(check, words);
  EXPECT_EQ(words[124], 124);
}

}  // namespace
}  // namespace pvtwin
