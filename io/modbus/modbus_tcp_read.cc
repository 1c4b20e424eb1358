// One Modbus TCP read transaction on a non-blocking socket; see
// modbus_tcp_read.h for the order of reads and checks and the timeout rule.
#include "io/modbus/modbus_tcp_read.h"

#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <cassert>
#include <cerrno>
#include <chrono>
#include <cstring>

namespace pvtwin {

namespace {

using SteadyClock = std::chrono::steady_clock;

enum class Io { kDone, kTimeout, kClosed, kError };

// Waits until fd is ready for `events` (or reports an error or hang-up,
// which the following send/recv turns into an errno) or the deadline passes.
Io WaitReady(int fd, short events, SteadyClock::time_point deadline) {
  for (;;) {
    const auto left = deadline - SteadyClock::now();
    if (left <= SteadyClock::duration::zero()) return Io::kTimeout;
    // Rounded up: a 0 ms poll() would spin through the last millisecond.
    const auto left_ms = std::chrono::ceil<std::chrono::milliseconds>(left).count();
    pollfd p{fd, events, 0};
    const int rc = poll(&p, 1, static_cast<int>(left_ms));
    if (rc > 0) return Io::kDone;
    if (rc < 0 && errno != EINTR) return Io::kError;
  }
}

Io SendAll(int fd, std::span<const std::uint8_t> bytes, SteadyClock::time_point deadline) {
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return Io::kError;
    const Io ready = WaitReady(fd, POLLOUT, deadline);
    if (ready != Io::kDone) return ready;
  }
  return Io::kDone;
}

Io ReceiveExactly(int fd, std::span<std::uint8_t> out, SteadyClock::time_point deadline) {
  std::size_t got = 0;
  while (got < out.size()) {
    const ssize_t n = recv(fd, out.data() + got, out.size() - got, 0);
    if (n > 0) {
      got += static_cast<std::size_t>(n);
      continue;
    }
    if (n == 0) return Io::kClosed;
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return Io::kError;
    const Io ready = WaitReady(fd, POLLIN, deadline);
    if (ready != Io::kDone) return ready;
  }
  return Io::kDone;
}

ReadOutcome Failed(Io io, const char* doing, int timeout_ms) {
  const int error = errno;  // before anything below can touch it
  ReadOutcome outcome;
  switch (io) {
    case Io::kTimeout:
      outcome.status = ReadStatus::kTimeout;
      outcome.message = std::string("no reply within ") + std::to_string(timeout_ms) + " ms";
      break;
    case Io::kClosed:
      outcome.status = ReadStatus::kBroken;
      outcome.message = std::string("connection closed by the device while ") + doing;
      break;
    case Io::kError:
    case Io::kDone:
      outcome.status = ReadStatus::kBroken;
      outcome.message = std::string(doing) + ": " + std::strerror(error);
      break;
  }
  return outcome;
}

ReadOutcome Rejected(const ReplyCheck& check) {
  ReadOutcome outcome;
  outcome.status = ReadStatus::kBadReply;
  outcome.message = std::string(check.message());
  return outcome;
}

}  // namespace

ReadOutcome ReadRegistersTcp(int fd, const ReadRequest& request, int timeout_ms,
                             std::span<std::uint16_t> words) {
  assert(words.size() >= request.count);
  const auto deadline = SteadyClock::now() + std::chrono::milliseconds(timeout_ms);
  const auto adu = EncodeReadRequest(request);
  if (const Io io = SendAll(fd, adu, deadline); io != Io::kDone) {
    return Failed(io, "sending the request", timeout_ms);
  }

  std::array<std::uint8_t, kMaxTcpAduBytes> reply{};
  const std::span<std::uint8_t> header(reply.data(), kMbapHeaderBytes);
  if (const Io io = ReceiveExactly(fd, header, deadline); io != Io::kDone) {
    return Failed(io, "reading the reply header", timeout_ms);
  }
  // Refused here, the length never makes us wait for (or read) a body that
  // is not one: 65535 would otherwise hold the read until the timeout.
  if (const ReplyCheck check = CheckReplyHeader(request, header); !check.ok()) {
    return Rejected(check);
  }
  const std::size_t body_bytes = ReplyBodyBytes(header);
  const std::span<std::uint8_t> body(reply.data() + kMbapHeaderBytes, body_bytes);
  if (const Io io = ReceiveExactly(fd, body, deadline); io != Io::kDone) {
    return Failed(io, "reading the reply", timeout_ms);
  }

  const ReplyCheck check = CheckReadReply(
      request, std::span<const std::uint8_t>(reply.data(), kMbapHeaderBytes + body_bytes));
  ReadOutcome outcome;
  if (check.status == ReplyStatus::kException) {
    outcome.status = ReadStatus::kException;
    outcome.exception_code = check.exception_code;
    outcome.message = std::string(check.message());
    return outcome;
  }
  if (!check.ok()) return Rejected(check);
  DecodeRegisterWords(check, words.first(request.count));
  outcome.status = ReadStatus::kOk;
  return outcome;
}

}  // namespace pvtwin
