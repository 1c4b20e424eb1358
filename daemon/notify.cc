#include "daemon/notify.h"

#include <systemd/sd-daemon.h>

#include <cstdint>

namespace pvtwin {

void NotifyReady(const std::string& status) { sd_notify(0, ("READY=1\nSTATUS=" + status).c_str()); }

void NotifyStatus(const std::string& status) { sd_notify(0, ("STATUS=" + status).c_str()); }

void NotifyStopping() { sd_notify(0, "STOPPING=1"); }

void NotifyReloading() { sd_notify(0, "RELOADING=1"); }

void NotifyWatchdog() { sd_notify(0, "WATCHDOG=1"); }

double WatchdogIntervalS() {
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) <= 0) return 0.0;
  return static_cast<double>(usec) / 2e6;
}

}  // namespace pvtwin
