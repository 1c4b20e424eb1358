#include "io/modbus/modbus_poller.h"

#include <modbus/modbus.h>

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <chrono>
#include <cmath>

#include "core/data/physical_limits.h"
#include "io/modbus/modbus_link.h"
#include "io/modbus/register_codec.h"

namespace pvtwin {

namespace {

// Results of a few recent periods are kept, so a late delivery thread still
// finds period k although the device has already published k + 1.
constexpr std::size_t kResultSlots = 4;

enum class LinkState { kStarting, kOk, kDown, kExceptions, kFrozen };

}  // namespace

struct ModbusPoller::Result {
  std::int64_t period = -1;
  std::array<double, kNumChannels> value{};
  std::uint32_t read_mask = 0;  // channel bits with a value or a reject
  std::uint32_t rejected_mask = 0;
};

struct ModbusPoller::Device {
  std::size_t index = 0;
  ModbusDevice config;
  std::vector<const RegisterRead*> reads;
  modbus_t* ctx = nullptr;
  bool connected = false;
  bool ever_connected = false;
  int failures = 0;                       // consecutive polls that lost the connection
  std::uint16_t next_transaction_id = 1;  // TCP: our own counter, wrapping at 65535
  std::int64_t next_attempt_period = 0;
  LinkState state = LinkState::kStarting;
  std::uint64_t failed_polls_in_state = 0;
  std::vector<std::uint16_t> words;  // this poll's raw registers, reads concatenated
  std::vector<std::uint16_t> previous_words;
  int unchanged_polls = 0;

  mutable std::mutex mutex;  // guards stats and slots
  DeviceStats stats;
  std::array<Result, kResultSlots> slots;

  std::string Who() const {
    return "modbus " + config.name + " (" + config.Endpoint() + " unit " +
           std::to_string(config.unit_id) + ")";
  }

  // One read on the open connection (io/modbus/modbus_link.h: TCP through our
  // own frame checks, RTU through libmodbus; function codes 3 and 4 only).
  ReadOutcome Read(const RegisterRead& read, std::span<std::uint16_t> words) {
    return ReadModbus(ctx, config, read, &next_transaction_id, words);
  }

  void Close() {
    CloseModbus(ctx);
    ctx = nullptr;
    connected = false;
  }
};

ModbusPoller::ModbusPoller(const ModbusConfig& map, PollerOptions options, const Clock& clock,
                           LogFn log)
    : map_(map), options_(options), clock_(clock), log_(std::move(log)) {
  assert(options_.period_s > 0 && options_.backoff_max_periods >= 1);
  plan_ = PlanReads(map_, options_.plan);
  for (std::size_t d = 0; d < map_.devices.size(); ++d) {
    auto device = std::make_unique<Device>();
    device->index = d;
    device->config = map_.devices[d];
    device->stats.name = device->config.name;
    for (const RegisterRead& read : plan_) {
      if (read.device == d) device->reads.push_back(&read);
    }
    devices_.push_back(std::move(device));
  }
}

ModbusPoller::~ModbusPoller() { Stop(); }

void ModbusPoller::Start(std::function<void(const Sample&)> on_sample) {
  assert(threads_.empty());
  on_sample_ = std::move(on_sample);
  stop_.store(false);
  // Computed here, not in the threads: a thread that starts late must not
  // skip a period that began after Start().
  first_period_ = static_cast<std::int64_t>(std::floor(clock_.NowS() / options_.period_s)) + 1;
  for (auto& device : devices_) threads_.emplace_back([this, d = device.get()] { RunDevice(d); });
  threads_.emplace_back([this] { RunDelivery(); });
}

void ModbusPoller::Stop() {
  stop_.store(true);
  for (std::thread& t : threads_) t.join();
  threads_.clear();
  for (auto& device : devices_) device->Close();
}

std::vector<DeviceStats> ModbusPoller::Stats() const {
  std::vector<DeviceStats> stats;
  for (const auto& device : devices_) {
    std::lock_guard<std::mutex> lock(device->mutex);
    stats.push_back(device->stats);
  }
  return stats;
}

void ModbusPoller::RunDevice(Device* device) {
  const double period_s = options_.period_s;
  std::int64_t k = first_period_;
  while (!stop_.load()) {
    if (!clock_.SleepUntil(static_cast<double>(k) * period_s, stop_)) break;
    // After a long timeout the device may be late: poll the current period.
    k = std::max(k, static_cast<std::int64_t>(std::floor(clock_.NowS() / period_s)));
    Result result;
    result.period = k;
    const auto begin = std::chrono::steady_clock::now();
    PollDevice(device, k, &result);
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    {
      std::lock_guard<std::mutex> lock(device->mutex);
      device->slots[static_cast<std::size_t>(k) % kResultSlots] = result;
      device->stats.last_poll_wall_s = wall_s;
      ++device->stats.polls;
    }
    ++k;
  }
}

void ModbusPoller::PollDevice(Device* device, std::int64_t period, Result* result) {
  const ModbusDevice& c = device->config;
  const auto set_state = [&](LinkState state, const std::string& why, int priority) {
    if (state == device->state) {
      ++device->failed_polls_in_state;
      return;
    }
    std::string line = device->Who() + ": " + why;
    if (state == LinkState::kOk && device->state != LinkState::kStarting) {
      line += " after " + std::to_string(device->failed_polls_in_state + 1) + " failed attempts";
    }
    log_(priority, line);
    device->state = state;
    device->failed_polls_in_state = 0;
  };
  const auto record_error = [&](const std::string& message, ReadStatus status) {
    std::lock_guard<std::mutex> lock(device->mutex);
    ++device->stats.errors;
    if (status == ReadStatus::kTimeout) ++device->stats.timeouts;
    if (status == ReadStatus::kBadReply) ++device->stats.bad_replies;
    device->stats.last_error = message;
    device->stats.connected = device->connected;
  };
  const auto lose_connection = [&](const std::string& message) {
    device->Close();
    ++device->failures;
    const int wait =
        std::min(1 << std::min(device->failures - 1, 20), options_.backoff_max_periods);
    device->next_attempt_period = period + wait;
    set_state(LinkState::kDown,
              message + "; reconnecting in " + std::to_string(wait) + " period(s), backoff up to " +
                  std::to_string(options_.backoff_max_periods),
              kErr);
  };

  if (!device->connected) {
    if (period < device->next_attempt_period) return;
    std::string error;
    device->ctx = OpenModbus(c, &error);
    if (!error.empty()) {
      record_error(error, ReadStatus::kBroken);
      lose_connection(error);
      return;
    }
    device->connected = true;
    std::lock_guard<std::mutex> lock(device->mutex);
    if (device->ever_connected) ++device->stats.reconnects;
    device->ever_connected = true;
    device->stats.connected = true;
  }

  device->words.clear();
  bool all_answered = true;
  std::string exception;
  for (const RegisterRead* read : device->reads) {
    std::array<std::uint16_t, kMaxReadRegisters> buf{};
    const ReadOutcome outcome = device->Read(*read, buf);
    {
      std::lock_guard<std::mutex> lock(device->mutex);
      ++device->stats.requests;
    }
    if (outcome.status != ReadStatus::kOk) {
      all_answered = false;
      const std::string message = "read " + std::string(TableName(read->table)) + " " +
                                  std::to_string(read->address) + "+" +
                                  std::to_string(read->count) + ": " + outcome.message;
      record_error(message, outcome.status);
      if (outcome.status == ReadStatus::kException) {
        // The device answered: the connection is fine, this read's data is not.
        exception = message;
        continue;
      }
      // Timeout, a reply that is not this read's (ids, length, function, byte
      // count, CRC), broken connection: none of the reply is used, and a late
      // or stray answer may still come, so flush and re-open.
      lose_connection(message);
      return;
    }
    device->words.insert(device->words.end(), buf.begin(), buf.begin() + read->count);
    for (const std::size_t i : read->points) {
      const ModbusPoint& p = map_.points[i];
      const auto offset = static_cast<std::size_t>(p.address - read->address);
      const DecodedValue v = DecodePoint(
          p,
          std::span<const std::uint16_t>(buf.data() + offset, static_cast<std::size_t>(p.Count())));
      const auto c_index = static_cast<std::size_t>(p.channel);
      result->read_mask |= 1u << c_index;
      result->value[c_index] = PointToChannelUnit(p, v.value);
      if (v.rejected || !PassesEdge(p.channel, result->value[c_index], options_.area_m2)) {
        result->rejected_mask |= 1u << c_index;
      }
    }
  }
  device->failures = 0;

  if (all_answered) {
    device->unchanged_polls =
        device->words == device->previous_words ? device->unchanged_polls + 1 : 0;
    device->previous_words.swap(device->words);
    std::lock_guard<std::mutex> lock(device->mutex);
    device->stats.last_success_s = clock_.NowS();
  }
  const bool frozen =
      options_.frozen_after_polls > 0 && device->unchanged_polls >= options_.frozen_after_polls;
  if (frozen) {
    result->rejected_mask |= result->read_mask;
    set_state(LinkState::kFrozen,
              "every register unchanged for " + std::to_string(device->unchanged_polls) +
                  " polls: values frozen, rejected until they change",
              kWarning);
  } else if (!exception.empty()) {
    set_state(LinkState::kExceptions, "device answers with an exception: " + exception, kWarning);
  } else {
    set_state(LinkState::kOk, "polling " + std::to_string(device->reads.size()) + " read(s)",
              device->ever_connected && device->state == LinkState::kStarting ? kInfo : kNotice);
  }
}

void ModbusPoller::RunDelivery() {
  const double period_s = options_.period_s;
  std::int64_t k = first_period_;
  while (!stop_.load()) {
    if (!clock_.SleepUntil(static_cast<double>(k + 1) * period_s, stop_)) break;
    Sample sample;
    sample.ts_s = std::llround(static_cast<double>(k) * period_s);
    for (const auto& device : devices_) {
      std::lock_guard<std::mutex> lock(device->mutex);
      const Result& r = device->slots[static_cast<std::size_t>(k) % kResultSlots];
      if (r.period != k) continue;
      for (std::size_t c = 0; c < kNumChannels; ++c) {
        if (!((r.read_mask >> c) & 1u)) continue;
        if ((r.rejected_mask >> c) & 1u) {
          sample.Reject(static_cast<Channel>(c));
        } else {
          sample.value[c] = r.value[c];
        }
      }
    }
    on_sample_(sample);
    ++k;
  }
}

}  // namespace pvtwin
