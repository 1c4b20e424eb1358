// What the poller and the one-shot read (modbus_read_once.h) share of a
// device's connection: opening the libmodbus context (TCP or RTU, response
// timeout, unit id, connect) and one read on it, TCP through
// io/modbus/modbus_tcp_read.h, RTU through libmodbus's read calls. Both
// send function codes 3 and 4 only. Included by io/modbus's sources only
// (libmodbus is private to pvtwin_io).
#pragma once

#include <modbus/modbus.h>

#include <cstdint>
#include <span>
#include <string>

#include "config/modbus_config.h"
#include "io/modbus/modbus_tcp_read.h"
#include "io/modbus/read_plan.h"

namespace pvtwin {

// A connected context for the device, or nullptr with *error ("cannot create
// the libmodbus context: …" or "connect failed: …", libmodbus's message).
modbus_t* OpenModbus(const ModbusDevice& device, std::string* error);

// Flushes, closes and frees ctx (nullptr: nothing).
void CloseModbus(modbus_t* ctx);

// One read of `read` on the open connection into words (size >= read.count).
// TCP takes *transaction_id and advances it (wrapping at 65535).
ReadOutcome ReadModbus(modbus_t* ctx, const ModbusDevice& device, const RegisterRead& read,
                       std::uint16_t* transaction_id, std::span<std::uint16_t> words);

}  // namespace pvtwin
