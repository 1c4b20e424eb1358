#include "daemon/service/notify.h"

#include <systemd/sd-daemon.h>

#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <stdexcept>

#include "config/shared_library.h"

namespace pvtwin {

namespace {

// libsystemd's functions, loaded by the first notification that has
// somewhere to go (config/shared_library.h): only `pvtwin run` under
// systemd sends any, so every other process skips the library and the
// compression and crypto libraries it maps.
struct SystemdApi {
  decltype(&::sd_notify) notify = nullptr;
  decltype(&::sd_watchdog_enabled) watchdog_enabled = nullptr;
};

// Null when libsystemd cannot be loaded, said once on standard error (the
// journal): systemd then waits for READY=1 in vain, and its own log names
// the unit.
const SystemdApi* Systemd() {
  static const SystemdApi* const api = []() -> const SystemdApi* {
    try {
      static const SharedLibrary library("libsystemd.so.0", "libsystemd0");
      static SystemdApi bound;
      library.Bind(&bound.notify, "sd_notify");
      library.Bind(&bound.watchdog_enabled, "sd_watchdog_enabled");
      return &bound;
    } catch (const std::runtime_error& e) {
      std::cerr << "cannot notify systemd: " << e.what() << "\n";
      return nullptr;
    }
  }();
  return api;
}

// sd_notify(0, state); without $NOTIFY_SOCKET nothing, as sd_notify itself
// does, and the library stays unloaded.
void Notify(const std::string& state) {
  if (std::getenv("NOTIFY_SOCKET") == nullptr) return;
  if (const SystemdApi* api = Systemd()) api->notify(0, state.c_str());
}

}  // namespace

void NotifyReady(const std::string& status) { Notify("READY=1\nSTATUS=" + status); }

void NotifyStatus(const std::string& status) { Notify("STATUS=" + status); }

void NotifyStopping() { Notify("STOPPING=1"); }

void NotifyReloading() { Notify("RELOADING=1"); }

void NotifyWatchdog() { Notify("WATCHDOG=1"); }

double WatchdogIntervalS() {
  // sd_watchdog_enabled reads $WATCHDOG_USEC (and $WATCHDOG_PID): without
  // it, no watchdog.
  if (std::getenv("WATCHDOG_USEC") == nullptr) return 0.0;
  const SystemdApi* api = Systemd();
  std::uint64_t usec = 0;
  if (api == nullptr || api->watchdog_enabled(0, &usec) <= 0) return 0.0;
  return static_cast<double>(usec) / 2e6;
}

}  // namespace pvtwin
