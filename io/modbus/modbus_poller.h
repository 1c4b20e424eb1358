// The Modbus poller: reads every device of the register map once per poll
// period and delivers one Sample per period.
//
// Threads: one per device, plus one that assembles and delivers the samples.
// The device thread starts its reads at the period start t_k (simulated time
// of the Clock, so an accelerated clock works); the delivering thread waits
// until the period's deadline t_k + period and builds the Sample of period k
// from whatever the devices have published for k by then. A device that is
// slow, dead or still inside a timeout never delays another device or the
// delivery: its channels are simply missing (NaN, QC bit clear) in that
// period. A value read for period k is never reported in another period.
// Decoded values that fail the point's QC (io/modbus/register_codec.h) are NaN with
// the Sample's QC bit set.
//
// Failures: a response timeout, a reply that does not match the request
// (TCP: transaction id, protocol id, MBAP length, unit id, function or byte
// count, checked by io/modbus/modbus_frame.h; RTU: slave id, CRC, function or byte
// count, checked by libmodbus) or a broken connection: nothing of that read's
// reply is used, and the connection is flushed and closed; it is re-opened on
// a later period with capped exponential backoff (1, 2, 4 …
// backoff_max_periods periods after consecutive failures). A Modbus
// exception reply leaves the connection open (the device answered) and the
// read's channels missing. A device whose raw registers all stay
// bit-identical for frozen_after_polls polls is "frozen": its channels are
// rejected until a register changes. Each change of a device's state
// (connected, down, answering with exceptions, frozen) is logged once, with
// host, unit id, the read and the reason (the reply check's message or the
// libmodbus error); failed polls in the same state are counted, not logged.
//
// Read-only by construction: requests are function codes 3 (holding) and 4
// (input registers) only, sent by io/modbus/modbus_tcp_read.h on the socket that
// libmodbus connected (TCP: libmodbus 3.1.6 would accept a reply from another
// unit, with a non-zero protocol id or a wrong MBAP length) or by libmodbus's
// read calls (RTU). libmodbus opens, flushes and closes every connection.
//
// Timeouts (ModbusDevice::timeout_ms) are wall-clock times of one request;
// periods and backoff are in clock (possibly simulated) seconds. Stop()
// returns within the longest device timeout plus the clock's 50 ms tick.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "config/modbus_config.h"
#include "core/common/clock.h"
#include "core/common/sample.h"
#include "io/platform/log.h"
#include "io/modbus/read_plan.h"

namespace pvtwin {

struct DeviceStats {
  std::string name;
  bool connected = false;
  std::uint64_t polls = 0;        // periods polled (results handed to the delivery)
  std::uint64_t requests = 0;     // read requests sent
  std::uint64_t errors = 0;       // failed requests and connection attempts (timeouts included)
  std::uint64_t timeouts = 0;     // requests without an answer in time
  std::uint64_t bad_replies = 0;  // replies not belonging to their request (transaction or unit
                                  // id, protocol id, MBAP length, function, byte count, CRC)
  std::uint64_t reconnects = 0;   // connections opened after the first
  double last_success_s = 0;      // clock time of the last poll with every read answered; 0 = never
  std::string last_error;         // the read and the reason of the last failure
  double last_poll_wall_s = 0;    // wall-clock duration of the last poll (connect and reads)
};

struct PollerOptions {
  double period_s = 5;          // poll period in clock seconds, > 0
  int backoff_max_periods = 2;  // cap of the reconnect backoff, in periods (>= 1); it bounds
                                // the recovery after a device comes back
  int frozen_after_polls = 12;  // polls with bit-identical registers before a device counts as
                                // frozen (its channels rejected); 0 disables the check
  ReadPlanOptions plan;         // coalescing of points into reads
  // Collector area for the area-scaled physical limits of flow and power
  // (core/physical_limits.h): a decoded value outside its channel's limits
  // is rejected like one outside the point's valid range. 0: unknown.
  double area_m2 = 0.0;
};

class ModbusPoller {
 public:
  ModbusPoller(const ModbusConfig& map, PollerOptions options, const Clock& clock, LogFn log);
  ~ModbusPoller();
  ModbusPoller(const ModbusPoller&) = delete;
  ModbusPoller& operator=(const ModbusPoller&) = delete;

  // Starts polling; on_sample is called once per period (from a poller
  // thread), with Sample::ts_s = period start, every mapped channel's value
  // or NaN (rejected_mask for QC rejects). The first sample is of the first
  // period that starts after Start(). on_sample should return quickly (hand
  // the sample to a queue): a slow callback delays later deliveries, though
  // never the devices' reads.
  void Start(std::function<void(const Sample&)> on_sample);
  // Stops the threads; bounded by the longest device timeout. Idempotent.
  void Stop();
  std::vector<DeviceStats> Stats() const;

  // The reads the poller issues each period (for tests and diagnostics).
  const std::vector<RegisterRead>& Plan() const { return plan_; }

 private:
  struct Device;
  struct Result;
  void RunDevice(Device* device);
  void RunDelivery();
  void PollDevice(Device* device, std::int64_t period, Result* result);

  ModbusConfig map_;
  PollerOptions options_;
  const Clock& clock_;
  LogFn log_;
  std::vector<RegisterRead> plan_;
  std::vector<std::unique_ptr<Device>> devices_;
  std::function<void(const Sample&)> on_sample_;
  std::int64_t first_period_ = 0;  // index of the first period polled
  std::vector<std::thread> threads_;
  std::atomic<bool> stop_{false};
};

}  // namespace pvtwin
