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
// Decoded values that fail the point's QC (io/register_codec.h) are NaN with
// the Sample's QC bit set.
//
// Failures: a response timeout, a reply that does not match the request
// (transaction id or unit id mismatch, bad CRC) or a broken connection flush
// and close the connection; it is re-opened on a later period with capped
// exponential backoff (1, 2, 4 … backoff_max_periods periods after
// consecutive failures). A Modbus exception reply leaves the connection open
// (the device answered) and the read's channels missing. A device whose raw
// registers all stay bit-identical for frozen_after_polls polls is "frozen":
// its channels are rejected until a register changes. Each change of a
// device's state (connected, down, answering with exceptions, frozen) is
// logged once, with host, unit id, the read and the libmodbus error; failed
// polls in the same state are counted, not logged.
//
// Read-only by construction: the only libmodbus calls that send a request
// are function codes 3 (holding) and 4 (input registers).
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
#include "core/clock.h"
#include "core/sample.h"
#include "io/log.h"
#include "io/read_plan.h"

namespace pvtwin {

struct DeviceStats {
  std::string name;
  bool connected = false;
  std::uint64_t polls = 0;       // periods polled (results handed to the delivery)
  std::uint64_t requests = 0;    // read requests sent
  std::uint64_t errors = 0;      // failed requests and connection attempts (timeouts included)
  std::uint64_t timeouts = 0;    // requests without an answer in time
  std::uint64_t reconnects = 0;  // connections opened after the first
  double last_success_s = 0;     // clock time of the last poll with every read answered; 0 = never
  std::string last_error;        // libmodbus message of the last failure
  double last_poll_wall_s = 0;   // wall-clock duration of the last poll (connect and reads)
};

struct PollerOptions {
  double period_s = 5;          // poll period in clock seconds, > 0
  int backoff_max_periods = 2;  // cap of the reconnect backoff, in periods (>= 1); it bounds
                                // the recovery after a device comes back
  int frozen_after_polls = 12;  // polls with bit-identical registers before a device counts as
                                // frozen (its channels rejected); 0 disables the check
  ReadPlanOptions plan;         // coalescing of points into reads
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
