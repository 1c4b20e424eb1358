// libFuzzer harness for the Modbus TCP reply check (io/modbus/modbus_frame.h), the
// first code that sees bytes from the network. Input: 8 bytes of request
// (transaction id hi/lo, unit id, function, address hi/lo, count hi/lo; any
// values, not only the 3/4 and 1..125 the poller sends), then the reply ADU.
// It must never crash or read outside the reply, and what it accepts must
// be consistent: checked by the invariants below (a violation traps, so the
// fuzzer keeps the input). Seeds: tests/fuzz/corpus/modbus_reply/.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "io/modbus/modbus_frame.h"

namespace {

constexpr std::size_t kRequestBytes = 8;

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

pvtwin::ReadRequest RequestFrom(const std::uint8_t* data) {
  pvtwin::ReadRequest r;
  r.transaction_id = static_cast<std::uint16_t>((data[0] << 8) | data[1]);
  r.unit_id = data[2];
  r.function = data[3];
  r.address = static_cast<std::uint16_t>((data[4] << 8) | data[5]);
  r.count = static_cast<std::uint16_t>((data[6] << 8) | data[7]);
  return r;
}

// The poller's order: the header alone first, then the announced body.
void CheckLikeThePoller(const pvtwin::ReadRequest& request, std::span<const std::uint8_t> reply,
                        const pvtwin::ReplyCheck& whole) {
  if (reply.size() < pvtwin::kMbapHeaderBytes) return;
  const auto header = reply.first(pvtwin::kMbapHeaderBytes);
  const pvtwin::ReplyCheck head = pvtwin::CheckReplyHeader(request, header);
  if (!head.ok()) {
    Require(!whole.ok() && whole.status == head.status);
    return;
  }
  const std::size_t body = pvtwin::ReplyBodyBytes(header);
  Require(body >= 1 && body <= 253);
  if (whole.ok() || whole.status == pvtwin::ReplyStatus::kException) {
    Require(reply.size() == pvtwin::kMbapHeaderBytes + body);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < kRequestBytes) return 0;
  const pvtwin::ReadRequest request = RequestFrom(data);
  const std::span<const std::uint8_t> reply(data + kRequestBytes, size - kRequestBytes);
  const pvtwin::ReplyCheck check = pvtwin::CheckReadReply(request, reply);

  // The message is a terminated string in its buffer, never empty.
  Require(std::memchr(check.message_text.data(), '\0', check.message_text.size()) != nullptr);
  Require(!check.message().empty());

  if (check.ok()) {
    const std::span<const std::uint8_t> bytes = check.register_bytes;
    Require(bytes.data() >= reply.data() &&
            bytes.data() + bytes.size() <= reply.data() + reply.size());
    Require(bytes.size() == 2u * request.count && request.count <= pvtwin::kMaxReadRegisterCount);
    Require(reply.size() == 9 + bytes.size() && reply[7] == request.function);
    std::array<std::uint16_t, pvtwin::kMaxReadRegisterCount> words{};
    pvtwin::DecodeRegisterWords(check, std::span(words).first(request.count));
  } else {
    Require(check.register_bytes.empty());
  }
  if (check.status == pvtwin::ReplyStatus::kException) {
    Require(reply.size() == 9 && reply[7] == (request.function | 0x80));
    Require(check.exception_code == reply[8]);
  }
  CheckLikeThePoller(request, reply, check);
  return 0;
}
