// The plant simulator's Modbus side: one libmodbus server per device of a
// register map (TCP on the device's host:port, or RTU on its serial device),
// serving every point of that device with the plant's value at the current
// simulated time, encoded as the point says (the inverse of the poller's
// decoding: raw = (value − offset) / scale in the point's type and word
// order). Requests outside the mapped registers get exception 2 (illegal
// data address) from libmodbus.
//
// Fault injection (tests, demos), per device and for a window of simulated
// time:
//   drop       close every connection and refuse new ones (TCP: accepted and
//              closed at once; RTU: no answer)
//   exception  answer every read with exception 4 (server device failure)
//   delay      answer after delay_ms of wall time (beyond a poller's timeout)
//   nan        serve NaN (float types) or the nan_value sentinel / the type's
//              largest raw value (integer types)
//   range      serve valid_max plus the valid span (or 1e9 without a range)
//   freeze     keep serving the values of the fault's first request
//   stray      answer with a reply that belongs to another request (TCP: a
//              wrong transaction id; RTU: a wrong unit id)
//   wrong_unit answer as another unit (unit id + 6): a gateway that mixes up
//              its slaves (TCP: the MBAP unit id; RTU: the slave address)
//   glitch     serve kGlitchWM2 on the short-wave irradiance points (the
//              paper's night glitch, Table 2), the other points as they are
// Text form (command line, control protocol):
//   DEVICE:KIND:from=S:for=S[:ms=N]   S simulated seconds after the start
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "config/modbus_config.h"
#include "core/common/clock.h"
#include "io/platform/log.h"
#include "io/sim/plant_source.h"

namespace pvtwin {

enum class FaultKind {
  kDrop,
  kException,
  kDelay,
  kNan,
  kRange,
  kFreeze,
  kStray,
  kWrongUnit,
  kGlitch
};

// The short-wave irradiance a "glitch" fault serves, W/m².
inline constexpr double kGlitchWM2 = 6000.0;

struct Fault {
  std::string device;
  FaultKind kind = FaultKind::kDrop;
  double from_s = 0;    // simulated seconds after the simulator's start
  double for_s = 0;     // length, simulated seconds (> 0)
  int delay_ms = 2000;  // kDelay: wall-clock delay of each answer
};

// Parses "DEVICE:KIND:from=S:for=S[:ms=N]"; false with *error on bad text.
bool ParseFault(std::string_view text, Fault* fault, std::string* error);

// A clock that moves only when told: the simulator's stepped mode.
class SteppedClock final : public Clock {
 public:
  explicit SteppedClock(double start_s) : now_s_(start_s) {}
  double NowS() const override { return now_s_.load(); }
  bool SleepUntil(double t_s, const std::atomic<bool>& stop) const override;
  void Advance(double dt_s) { now_s_.store(now_s_.load() + dt_s); }

 private:
  std::atomic<double> now_s_;
};

struct SimServerOptions {
  bool ephemeral_ports = false;  // bind TCP devices to port 0 (the kernel picks a free one)
  int port_offset = 0;           // added to every configured TCP port
};

class ModbusSimServer {
 public:
  // start_s: simulated time that fault windows count from.
  ModbusSimServer(const ModbusConfig& map, PlantSource* source, const Clock& clock, double start_s,
                  SimServerOptions options, LogFn log);
  ~ModbusSimServer();
  ModbusSimServer(const ModbusSimServer&) = delete;
  ModbusSimServer& operator=(const ModbusSimServer&) = delete;

  // Binds every device and starts serving. False with *error if one fails.
  bool Start(std::string* error);
  void Stop();

  // One line per device: "DEVICE tcp HOST:PORT" or "DEVICE rtu PATH".
  std::vector<std::string> Endpoints() const;
  // The bound TCP port of device i (0 for RTU).
  int Port(std::size_t device) const;

  // Adds a fault; false if its device is not in the map.
  bool AddFault(const Fault& fault, std::string* error);

  // Requests answered so far, all devices (benchmarks, tests).
  std::uint64_t Requests() const { return requests_.load(); }

 private:
  struct Device;
  void Serve(Device* device);

  ModbusConfig map_;
  PlantSource* source_;
  const Clock& clock_;
  double start_s_;
  SimServerOptions options_;
  LogFn log_;
  std::vector<std::unique_ptr<Device>> devices_;
  std::vector<std::thread> threads_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> requests_{0};
  mutable std::mutex faults_mutex_;
  std::vector<Fault> faults_;
};

}  // namespace pvtwin
