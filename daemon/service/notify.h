// systemd service notifications (sd_notify(3)): READY=1 once the daemon
// serves, WATCHDOG=1 while its loop runs, STOPPING=1 on the way out, and a
// STATUS= line. Without $NOTIFY_SOCKET (not run by systemd) every call is a
// no-op. libsystemd is loaded by the first call that notifies (dlopen), so
// the other commands do not map it.
#pragma once

#include <string>

namespace pvtwin {

void NotifyReady(const std::string& status);
void NotifyStatus(const std::string& status);
void NotifyStopping();
void NotifyReloading();
void NotifyWatchdog();
// Interval at which WATCHDOG=1 must be sent (half of WatchdogSec), or 0 when
// the unit has no watchdog.
double WatchdogIntervalS();

}  // namespace pvtwin
