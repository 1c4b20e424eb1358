#include "io/modbus/modbus_link.h"

#include <cerrno>

namespace pvtwin {

namespace {

bool IsException(int error) { return error > MODBUS_ENOBASE && error <= EMBXGTAR; }

// libmodbus's errors for a reply that is not the answer to the request.
bool IsBadReply(int error) {
  return error == EMBBADCRC || error == EMBBADDATA || error == EMBBADEXC || error == EMBUNKEXC ||
         error == EMBBADSLAVE;
}

int FunctionOf(RegisterTable table) {
  return table == RegisterTable::kInput ? MODBUS_FC_READ_INPUT_REGISTERS
                                        : MODBUS_FC_READ_HOLDING_REGISTERS;
}

// RTU reads stay with libmodbus: for RTU it compares the slave id and checks
// the CRC (modbus-rtu.c), then the function and byte count (modbus.c
// check_confirmation).
ReadOutcome ReadRegistersRtu(modbus_t* ctx, const RegisterRead& read,
                             std::span<std::uint16_t> words) {
  const int function = FunctionOf(read.table);
  const int n = function == MODBUS_FC_READ_INPUT_REGISTERS
                    ? modbus_read_input_registers(ctx, read.address, read.count, words.data())
                    : modbus_read_registers(ctx, read.address, read.count, words.data());
  const int error = errno;
  ReadOutcome outcome;
  if (n == read.count) {
    outcome.status = ReadStatus::kOk;
    return outcome;
  }
  outcome.message = n < 0 ? modbus_strerror(error) : "short answer";
  if (n >= 0 || IsBadReply(error)) {
    outcome.status = ReadStatus::kBadReply;
  } else if (IsException(error)) {
    outcome.status = ReadStatus::kException;
    outcome.exception_code = static_cast<std::uint8_t>(error - MODBUS_ENOBASE);
  } else {
    outcome.status = error == ETIMEDOUT ? ReadStatus::kTimeout : ReadStatus::kBroken;
  }
  return outcome;
}

}  // namespace

modbus_t* OpenModbus(const ModbusDevice& c, std::string* error) {
  modbus_t* ctx = c.IsRtu()
                      ? modbus_new_rtu(c.serial.c_str(), c.baud, c.parity, c.data_bits, c.stop_bits)
                      : modbus_new_tcp_pi(c.host.c_str(), std::to_string(c.port).c_str());
  if (ctx == nullptr) {
    *error = std::string("cannot create the libmodbus context: ") + modbus_strerror(errno);
    return nullptr;
  }
  modbus_set_response_timeout(ctx, static_cast<std::uint32_t>(c.timeout_ms / 1000),
                              static_cast<std::uint32_t>(c.timeout_ms % 1000) * 1000u);
  modbus_set_slave(ctx, c.unit_id);
  if (modbus_connect(ctx) != 0) {
    *error = std::string("connect failed: ") + modbus_strerror(errno);
    modbus_free(ctx);
    return nullptr;
  }
  return ctx;
}

void CloseModbus(modbus_t* ctx) {
  if (ctx == nullptr) return;
  modbus_flush(ctx);
  modbus_close(ctx);
  modbus_free(ctx);
}

ReadOutcome ReadModbus(modbus_t* ctx, const ModbusDevice& device, const RegisterRead& read,
                       std::uint16_t* transaction_id, std::span<std::uint16_t> words) {
  if (device.IsRtu()) return ReadRegistersRtu(ctx, read, words);
  ReadRequest request;
  request.transaction_id = (*transaction_id)++;
  request.unit_id = static_cast<std::uint8_t>(device.unit_id);
  request.function = static_cast<std::uint8_t>(FunctionOf(read.table));
  request.address = static_cast<std::uint16_t>(read.address);
  request.count = static_cast<std::uint16_t>(read.count);
  return ReadRegistersTcp(modbus_get_socket(ctx), request, device.timeout_ms, words);
}

}  // namespace pvtwin
