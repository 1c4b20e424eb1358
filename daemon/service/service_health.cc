// The health job of the Service (service_internal.h): every [log]
// status_min minutes of the daemon's clock one line saying how the daemon
// fares —
//
//   status: 2/2 devices up; samples stored/rejected in 15 min: collector
//   180/0, weather 178/2; calibration 3 accepted 2.1 h ago; forecast issued
//   2024-06-01T10:00:00Z, 4 min ago
//
// (one line in the log), and the same, shorter, as systemd's STATUS=. A
// device's sample is "rejected" when it was stored without all of the
// device's channels: read but failing its checks, or not read at all.
#include <cmath>
#include <cstdio>

#include "daemon/service/notify.h"
#include "daemon/service/service_internal.h"
#include "io/platform/log.h"
#include "io/platform/time_format.h"

namespace pvtwin::service_detail {

namespace {

// "40 s", "12 min", "2.1 h", "3.0 d".
std::string FormatAge(double age_s) {
  if (age_s < 0) age_s = 0;
  if (age_s < 90) return Format("%.0f s", age_s);
  if (age_s < 90 * 60) return Format("%.0f min", age_s / 60);
  if (age_s < 48 * 3600) return Format("%.1f h", age_s / 3600);
  return Format("%.1f d", age_s / 86400);
}

}  // namespace

void Service::StartDeviceCounts() {
  device_counts_.clear();
  for (const ModbusDevice& d : config_.modbus.devices) {
    DeviceCounts counts;
    counts.name = d.name;
    device_counts_.push_back(counts);
  }
  for (const ModbusPoint& p : config_.modbus.points) {
    if (p.device < device_counts_.size()) {
      device_counts_[p.device].channels |= 1u << static_cast<unsigned>(p.channel);
    }
  }
}

void Service::CountStoredSamples(const std::vector<Sample>& samples) {
  samples_since_status_ += samples.size();
  for (DeviceCounts& d : device_counts_) {
    for (const Sample& s : samples) {
      bool complete = (s.rejected_mask & d.channels) == 0;
      for (unsigned c = 0; complete && c < kNumChannels; ++c) {
        if (((d.channels >> c) & 1u) != 0 && !s.Has(static_cast<Channel>(c))) complete = false;
      }
      ++(complete ? d.stored : d.rejected);
    }
  }
}

void Service::ArmHealthReport() {
  const int minutes = config_.log.status_min;
  next_status_s_ = minutes > 0 ? last_status_s_ + minutes * 60.0 : INFINITY;
}

std::string Service::CalibrationHealth() const {
  // A new plant's wait: "waiting for history: 3.2 h of 48 h".
  if (!have_params_ && status_.state.rfind("waiting for history", 0) == 0) return status_.state;
  if (last_calibration_.status.empty()) return "no calibration yet";
  std::string text = "calibration " + std::to_string(last_calibration_.id) + " " +
                     last_calibration_.status + " " +
                     FormatAge(Now() - last_calibration_.run_at_s) + " ago";
  if (last_calibration_.id != params_id_) {
    text += have_params_ ? " (in use: " + std::to_string(params_id_) + ")" : " (none in use)";
  }
  return text;
}

std::string Service::ForecastHealth(bool brief) const {
  if (last_forecast_issued_at_ < 0) return "no forecast yet";
  const std::string age = FormatAge(Now() - static_cast<double>(last_forecast_issued_at_));
  if (brief) return "forecast " + age + " old";
  return "forecast issued " + FormatIsoUtc(last_forecast_issued_at_) + ", " + age + " ago";
}

void Service::MaybeReportHealth() {
  if (Now() < next_status_s_) return;
  const std::string span = FormatAge(Now() - last_status_s_);
  std::string devices, brief;
  if (!poller_) {
    devices = "polling off";
    brief = devices;
  } else {
    devices = std::to_string(status_.devices_up) + "/" + std::to_string(status_.devices) +
              " devices up";
    brief = devices + ", " + std::to_string(samples_since_status_) + " samples in " + span;
    devices += "; samples stored/rejected in " + span + ":";
    for (std::size_t i = 0; i < device_counts_.size(); ++i) {
      const DeviceCounts& d = device_counts_[i];
      devices += (i ? ", " : " ") + d.name + " " + std::to_string(d.stored) + "/" +
                 std::to_string(d.rejected);
    }
  }
  LogToStderr(kInfo, "status: " + devices + "; " + CalibrationHealth() + "; " +
                         ForecastHealth(false));
  NotifyStatus(brief + "; " + CalibrationHealth() + "; " + ForecastHealth(true));
  for (DeviceCounts& d : device_counts_) d.stored = d.rejected = 0;
  samples_since_status_ = 0;
  last_status_s_ = Now();
  ArmHealthReport();
}

}  // namespace pvtwin::service_detail
