// One Modbus TCP read transaction (function 3 or 4) on a socket that
// libmodbus connected: send the request ADU of io/modbus/modbus_frame.h, read the
// 7-byte MBAP header, refuse it (before any body is read) unless its ids and
// length belong to the request, read exactly the announced rest, check the
// whole reply. The poller uses it instead of modbus_read_registers() because
// libmodbus 3.1.6 does not check the unit id, the protocol id or the MBAP
// length of a TCP reply (issue 17); libmodbus still opens, flushes and closes
// the connection. Depends on POSIX sockets and io/modbus/modbus_frame.h only.
//
// The socket is non-blocking (libmodbus opens it so): every wait is a poll()
// against one deadline, timeout_ms of wall-clock time for the whole
// transaction. Sends use MSG_NOSIGNAL: a peer that closed is an error, not a
// SIGPIPE.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "io/modbus/modbus_frame.h"

namespace pvtwin {

// The outcome of one read, TCP here or RTU through libmodbus (the poller maps
// libmodbus's errno onto it).
enum class ReadStatus {
  kOk,         // words hold the registers
  kException,  // the device answered with a Modbus exception: the link is fine
  kTimeout,    // no complete reply within timeout_ms
  kBadReply,   // a reply that does not belong to the request (ReplyCheck's reason)
  kBroken,     // send/recv failed or the peer closed the connection
};

struct ReadOutcome {
  ReadStatus status = ReadStatus::kBroken;
  std::uint8_t exception_code = 0;  // kException
  std::string message;              // empty for kOk; else what went wrong, for the log
};

// Reads request.count registers into words (size >= request.count) on fd.
ReadOutcome ReadRegistersTcp(int fd, const ReadRequest& request, int timeout_ms,
                             std::span<std::uint16_t> words);

}  // namespace pvtwin
