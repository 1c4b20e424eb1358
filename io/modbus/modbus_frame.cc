// The Modbus TCP read codec: request ADU and reply checks. The frame layout,
// the limits and why libmodbus is not trusted with this are in modbus_frame.h.
#include "io/modbus/modbus_frame.h"

#include <cassert>
#include <cstdarg>
#include <cstdio>

namespace pvtwin {

namespace {

// Byte offsets in the ADU.
constexpr std::size_t kTransactionAt = 0;
constexpr std::size_t kProtocolAt = 2;
constexpr std::size_t kLengthAt = 4;
constexpr std::size_t kUnitAt = 6;
constexpr std::size_t kFunctionAt = 7;
constexpr std::size_t kByteCountAt = 8;  // also the exception code
constexpr std::size_t kDataAt = 9;
constexpr std::uint8_t kExceptionBit = 0x80;
constexpr int kExceptionLength = 3;  // unit id, function | 0x80, code

int Word(std::span<const std::uint8_t> bytes, std::size_t at) {
  return (bytes[at] << 8) | bytes[at + 1];
}

void PutWord(std::uint8_t* out, int value) {
  out[0] = static_cast<std::uint8_t>((value >> 8) & 0xFF);
  out[1] = static_cast<std::uint8_t>(value & 0xFF);
}

// A rejection whose message says what came and what was expected.
__attribute__((format(printf, 2, 3))) ReplyCheck Reject(ReplyStatus status, const char* format,
                                                        ...) {
  ReplyCheck check;
  check.status = status;
  va_list args;
  va_start(args, format);
  std::vsnprintf(check.message_text.data(), check.message_text.size(), format, args);
  va_end(args);
  return check;
}

// The protocol's names of the exception codes (Application Protocol §7).
const char* ExceptionName(int code) {
  switch (code) {
    case 1:
      return "illegal function";
    case 2:
      return "illegal data address";
    case 3:
      return "illegal data value";
    case 4:
      return "server device failure";
    case 5:
      return "acknowledge";
    case 6:
      return "server device busy";
    case 8:
      return "memory parity error";
    case 10:
      return "gateway path unavailable";
    case 11:
      return "gateway target device failed to respond";
    default:
      return "not a defined code";
  }
}

// The PDU of a reply whose header and MBAP length already passed.
ReplyCheck CheckPdu(const ReadRequest& request, std::span<const std::uint8_t> reply, int length) {
  const int function = reply[kFunctionAt];
  if (function == (request.function | kExceptionBit)) {
    if (length != kExceptionLength) {
      return Reject(ReplyStatus::kLength, "exception reply MBAP length %d, expected %d", length,
                    kExceptionLength);
    }
    const int code = reply[kByteCountAt];
    ReplyCheck check = Reject(ReplyStatus::kException, "exception %d (%s) to function %d", code,
                              ExceptionName(code), request.function);
    check.exception_code = static_cast<std::uint8_t>(code);
    return check;
  }
  if (function != request.function) {
    return Reject(ReplyStatus::kFunction, "reply function %d, expected %d", function,
                  request.function);
  }
  if (length < 3) {
    return Reject(ReplyStatus::kTruncated, "reply MBAP length %d, no byte count", length);
  }
  const int byte_count = reply[kByteCountAt];
  const int expected_byte_count = 2 * request.count;
  if (byte_count != expected_byte_count) {
    return Reject(ReplyStatus::kByteCount, "reply byte count %d, expected %d for %d registers",
                  byte_count, expected_byte_count, request.count);
  }
  if (length != 3 + byte_count) {
    return Reject(ReplyStatus::kLength, "reply MBAP length %d, expected %d for byte count %d",
                  length, 3 + byte_count, byte_count);
  }
  ReplyCheck check;
  check.status = ReplyStatus::kOk;
  check.register_bytes = reply.subspan(kDataAt, static_cast<std::size_t>(byte_count));
  std::snprintf(check.message_text.data(), check.message_text.size(), "%d registers",
                request.count);
  return check;
}

}  // namespace

std::array<std::uint8_t, kReadRequestAduBytes> EncodeReadRequest(const ReadRequest& request) {
  assert((request.function == 3 || request.function == 4) && "only read functions 3 and 4");
  assert(request.count >= 1 && request.count <= kMaxReadRegisterCount && "count 1..125");
  std::array<std::uint8_t, kReadRequestAduBytes> adu{};
  PutWord(&adu[kTransactionAt], request.transaction_id);
  PutWord(&adu[kProtocolAt], 0);
  PutWord(&adu[kLengthAt], static_cast<int>(kReadRequestAduBytes - 6));
  adu[kUnitAt] = request.unit_id;
  adu[kFunctionAt] = request.function;
  PutWord(&adu[8], request.address);
  PutWord(&adu[10], request.count);
  return adu;
}

std::string_view ReplyStatusName(ReplyStatus status) {
  switch (status) {
    case ReplyStatus::kOk:
      return "ok";
    case ReplyStatus::kException:
      return "exception";
    case ReplyStatus::kTruncated:
      return "truncated";
    case ReplyStatus::kTransactionId:
      return "transaction id";
    case ReplyStatus::kProtocolId:
      return "protocol id";
    case ReplyStatus::kLength:
      return "length";
    case ReplyStatus::kUnitId:
      return "unit id";
    case ReplyStatus::kFunction:
      return "function";
    case ReplyStatus::kByteCount:
      return "byte count";
  }
  return "?";
}

ReplyCheck CheckReplyHeader(const ReadRequest& request, std::span<const std::uint8_t> header) {
  if (header.size() < kMbapHeaderBytes) {
    return Reject(ReplyStatus::kTruncated, "reply of %zu bytes, shorter than the %zu-byte header",
                  header.size(), kMbapHeaderBytes);
  }
  const int transaction_id = Word(header, kTransactionAt);
  if (transaction_id != request.transaction_id) {
    return Reject(ReplyStatus::kTransactionId, "reply transaction id %d, expected %d",
                  transaction_id, request.transaction_id);
  }
  const int protocol_id = Word(header, kProtocolAt);
  if (protocol_id != 0) {
    return Reject(ReplyStatus::kProtocolId, "reply protocol id %d, expected 0", protocol_id);
  }
  const int length = Word(header, kLengthAt);
  if (length < kMbapMinLength || length > kMbapMaxLength) {
    return Reject(ReplyStatus::kLength, "reply MBAP length %d, expected %d..%d", length,
                  kMbapMinLength, kMbapMaxLength);
  }
  const int unit_id = header[kUnitAt];
  if (unit_id != request.unit_id) {
    return Reject(ReplyStatus::kUnitId, "reply unit id %d, expected %d", unit_id, request.unit_id);
  }
  ReplyCheck check;
  check.status = ReplyStatus::kOk;
  std::snprintf(check.message_text.data(), check.message_text.size(), "header of %d bytes", length);
  return check;
}

std::size_t ReplyBodyBytes(std::span<const std::uint8_t> header) {
  assert(header.size() >= kMbapHeaderBytes);
  const int length = Word(header, kLengthAt);
  assert(length >= kMbapMinLength && "call CheckReplyHeader first");
  return static_cast<std::size_t>(length - 1);
}

ReplyCheck CheckReadReply(const ReadRequest& request, std::span<const std::uint8_t> reply) {
  ReplyCheck header = CheckReplyHeader(request, reply);
  if (!header.ok()) return header;
  const int length = Word(reply, kLengthAt);
  const std::size_t following = reply.size() - 6;
  if (following != static_cast<std::size_t>(length)) {
    return Reject(ReplyStatus::kLength, "reply MBAP length %d, but %zu bytes follow it", length,
                  following);
  }
  return CheckPdu(request, reply, length);
}

void DecodeRegisterWords(const ReplyCheck& check, std::span<std::uint16_t> words) {
  assert(check.ok() && words.size() * 2 == check.register_bytes.size());
  for (std::size_t i = 0; i < words.size(); ++i) {
    words[i] = static_cast<std::uint16_t>(Word(check.register_bytes, 2 * i));
  }
}

}  // namespace pvtwin
