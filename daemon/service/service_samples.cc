// The samples job of the Service (service_internal.h): the poller's samples
// into sample_5s (held in memory while the database refuses them), the 1-min
// aggregation, and the devices' state changes as events.
#include <cmath>

#include "daemon/service/service_internal.h"
#include "io/platform/log.h"

namespace pvtwin::service_detail {

void Service::StoreSamples() {
  std::vector<Sample> fresh = queue_.Take();
  pending_.insert(pending_.end(), fresh.begin(), fresh.end());
  if (pending_.empty()) return;
  if (pending_.size() > kMaxPendingSamples) {
    const std::size_t drop = pending_.size() - kMaxPendingSamples;
    LogToStderr(kErr, "database unwritable for a day: dropping the " + std::to_string(drop) +
                          " oldest samples");
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(drop));
  }
  std::string error;
  if (!store_->InsertSamples(pending_, &error)) {
    if (!store_failing_) {
      LogToStderr(kErr, "storing samples failed (kept in memory, retried): " + error);
      store_failing_ = true;
    }
    return;
  }
  if (store_failing_) LogToStderr(kNotice, "storing samples works again");
  store_failing_ = false;
  status_.samples_stored += pending_.size();
  CountStoredSamples(pending_);
  pending_.clear();
}

void Service::Aggregate() {
  // The sample of the period starting at t arrives at t + period; a minute
  // is complete once its last period has been delivered.
  const double settled_s = Now() - config_.poll.period_s - 1.0;
  const std::int64_t up_to = static_cast<std::int64_t>(std::floor(settled_s / 60.0)) * 60;
  int written = 0;
  std::string error;
  if (!store_->AggregateMinutes(up_to, &written, &error)) {
    LogToStderr(kWarning, "aggregation to 1-min rows failed (retried): " + error);
    return;
  }
  status_.minutes_aggregated += static_cast<std::uint64_t>(written);
}

void Service::UpdateDeviceStatus() {
  if (!poller_) return;
  int up = 0;
  const std::vector<DeviceStats> stats = poller_->Stats();
  for (const DeviceStats& d : stats) up += d.connected ? 1 : 0;
  // The poller's state changes (a device down, back, answering with
  // exceptions, frozen) become events here, on the main thread: a busy
  // database must never hold up a poll thread.
  std::vector<std::pair<int, std::string>> changes;
  {
    std::lock_guard lock(device_events_mutex_);
    changes.swap(device_events_);
  }
  for (const auto& [priority, line] : changes) {
    std::string error;
    const char* severity = priority <= kErr ? "error" : priority <= kWarning ? "warning" : "info";
    if (!store_->InsertMonitorEvent(static_cast<std::int64_t>(Now()), "device", severity, line,
                                    &error)) {
      LogToStderr(kWarning, "recording the device event failed: " + error);
    }
  }
  status_.devices = static_cast<int>(stats.size());
  status_.devices_up = up;
}

}  // namespace pvtwin::service_detail
