// Modbus TCP read transactions as bytes: the request ADU of a "read holding
// registers" (function 3) or "read input registers" (function 4) and the
// check of the reply ADU against it. Pure and allocation-free (no sockets, no
// heap, nothing thrown); depends on the standard library only, so the fuzz
// harness (tests/fuzz/fuzz_modbus_reply.cc) builds it on its own.
//
// Why not libmodbus: 3.1.6 accepts a TCP reply with another unit id, a
// protocol id such as 0x0007 (it tests `rsp[2] != 0 && rsp[3] != 0`) and any
// MBAP length (it reads the body by function code and byte count), so a
// gateway answering for another slave would feed that slave's values in.
//
// Frame (Modbus Messaging on TCP/IP Implementation Guide V1.0b, §3.1.3; Modbus
// Application Protocol V1.1b3, §6.3 and §6.4), every field big-endian:
//   MBAP header  transaction id (2), protocol id (2) = 0, length (2) = the
//                number of bytes that follow it (unit id + PDU), unit id (1)
//   request PDU  function (1), start address (2), quantity (2)   → length 6
//   reply PDU    function (1), byte count (1) = 2·quantity, words  → length 3 + 2·quantity
//   exception    function | 0x80 (1), exception code (1)          → length 3
// A PDU is at most 253 bytes, so a length lies in 2..254 and an ADU is at
// most 260 bytes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace pvtwin {

inline constexpr std::size_t kMbapHeaderBytes = 7;       // up to and including the unit id
inline constexpr std::size_t kReadRequestAduBytes = 12;  // header + 5-byte PDU
inline constexpr int kMbapMinLength = 2;                 // unit id + function code
inline constexpr int kMbapMaxLength = 254;               // unit id + 253-byte PDU
inline constexpr std::size_t kMaxTcpAduBytes = 6 + kMbapMaxLength;
inline constexpr int kMaxReadRegisterCount = 125;  // 2·125 + 3 bytes fill the PDU's 253

struct ReadRequest {
  std::uint16_t transaction_id = 0;
  std::uint8_t unit_id = 1;
  std::uint8_t function = 3;  // 3 read holding registers, 4 read input registers
  std::uint16_t address = 0;  // first register (PDU address, 0-based)
  std::uint16_t count = 1;    // registers, 1..kMaxReadRegisterCount
};

// The request ADU. The request must be valid (function 3 or 4, count
// 1..125): anything else is a bug of the caller and asserts.
std::array<std::uint8_t, kReadRequestAduBytes> EncodeReadRequest(const ReadRequest& request);

enum class ReplyStatus {
  kOk,             // register data of the requested count
  kException,      // a well-formed exception reply; exception_code holds its code
  kTruncated,      // fewer bytes than the header (or the minimal PDU) needs
  kTransactionId,  // not the reply to this request
  kProtocolId,     // protocol id other than 0 (not Modbus)
  kLength,         // MBAP length outside 2..254 or not the bytes that follow it
  kUnitId,         // answered for another unit (gateway mix-up)
  kFunction,       // neither the request's function nor its exception
  kByteCount,      // byte count other than 2·count
};

// "ok", "exception", "truncated", "transaction id", … for logs and tests.
std::string_view ReplyStatusName(ReplyStatus status);

struct ReplyCheck {
  ReplyStatus status = ReplyStatus::kTruncated;
  std::uint8_t exception_code = 0;  // kException: 1 illegal function, 2 illegal address, …
  std::span<const std::uint8_t> register_bytes;  // kOk: the 2·count data bytes inside the reply
  std::array<char, 96> message_text{};           // NUL-terminated; a fixed buffer: no allocation

  bool ok() const { return status == ReplyStatus::kOk; }
  // What was expected and what came, e.g. "reply unit id 7, expected 1".
  std::string_view message() const { return message_text.data(); }
};

// Checks the first kMbapHeaderBytes of a reply: transaction id, protocol id,
// length within 2..254, unit id. The caller reads no body before this passes:
// a length of 65535 must not make it wait for 65 kB. kOk or a rejection.
ReplyCheck CheckReplyHeader(const ReadRequest& request, std::span<const std::uint8_t> header);

// Bytes of the reply that follow a header that passed CheckReplyHeader (the
// MBAP length minus the unit id already read).
std::size_t ReplyBodyBytes(std::span<const std::uint8_t> header);

// Checks a whole reply ADU against its request: the header as above, the
// MBAP length equal to the bytes that follow it, the function (or its
// exception with a code), the byte count equal to 2·count. Any request and
// any bytes are allowed; nothing outside `reply` is read.
ReplyCheck CheckReadReply(const ReadRequest& request, std::span<const std::uint8_t> reply);

// The register words of an accepted reply, big-endian on the wire.
// words.size() must be register_bytes.size() / 2.
void DecodeRegisterWords(const ReplyCheck& check, std::span<std::uint16_t> words);

}  // namespace pvtwin
