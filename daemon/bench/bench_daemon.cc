// pvtwin-bench daemon: the daemon's steady cost at 5 s polling, measured on
// the real processes: `pvtwin sim` serving the example plant (two devices)
// on loopback and `pvtwin run` polling it in real time. CPU time and memory
// come from /proc/<pid> of the daemon.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "config/config_edit.h"
#include "core/common/clock.h"
#include "daemon/bench/bench.h"
#include "daemon/demo_config.h"
#include "io/platform/child_process.h"

namespace pvtwin::cli {

namespace {

namespace fs = std::filesystem;

// utime + stime of a process in seconds.
double CpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t paren = text.rfind(')');
  if (paren == std::string::npos) return 0.0;
  std::istringstream fields(text.substr(paren + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int i = 3; fields >> field; ++i) {  // field 3 is the state
    if (i == 14) utime = std::stod(field);
    if (i == 15) {
      stime = std::stod(field);
      break;
    }
  }
  return (utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

// A "VmRSS:"-style line of /proc/<pid>/status, in MB.
double StatusMb(pid_t pid, const std::string& key) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(key.size())) / 1024.0;
  }
  return 0.0;
}

}  // namespace

void BenchDaemon(double seconds) {
  std::string tmpl = (fs::temp_directory_path() / "pvtwin-bench-XXXXXX").string();
  if (::mkdtemp(tmpl.data()) == nullptr) return;
  const fs::path dir = tmpl;
  const std::string exe = PvtwinExecutable();
  std::ofstream(dir / "sim.toml") << kDemoPlantConfig;
  ChildProcess sim, daemon;
  std::string error;
  std::vector<std::string> lines;
  if (!sim.StartPiped({exe, "sim", "--config", (dir / "sim.toml").string(), "--ephemeral-ports"},
                      (dir / "sim.log").string(), &error) ||
      !sim.ReadUntil("ready", 20.0, &lines)) {
    std::printf("daemon: the simulator did not start (%s)\n", error.c_str());
    return;
  }
  DaemonSettings settings;
  settings.db_path = (dir / "pvtwin.db").string();
  std::string text;
  if (!EditConfig(kDemoPlantConfig, ParseListeningLines(lines), settings, &text, &error)) {
    std::printf("daemon: %s\n", error.c_str());
    return;
  }
  std::ofstream(dir / "pvtwin.toml") << text;
  if (!daemon.Start({exe, "run", "--config", (dir / "pvtwin.toml").string()},
                    (dir / "daemon.log").string(), &error)) {
    std::printf("daemon: %s\n", error.c_str());
    return;
  }
  const pid_t pid = daemon.pid();
  std::printf(
      "daemon: `pvtwin run` polling `pvtwin sim` (2 devices, loopback) every 5 s, real "
      "time, %.0f s after a 10 s settling period\n",
      seconds);
  std::fflush(stdout);
  std::this_thread::sleep_for(std::chrono::seconds(10));
  const double cpu0 = CpuSeconds(pid);
  const double wall0 = WallNowS();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const double cpu_s = CpuSeconds(pid) - cpu0;
  const double wall_s = WallNowS() - wall0;
  const double rss_mb = StatusMb(pid, "VmRSS:");
  const double peak_mb = StatusMb(pid, "VmHWM:");
  const int code = daemon.Stop(SIGTERM, 10.0);
  sim.SendLine("quit");
  sim.Stop(0, 5.0);
  std::printf("  CPU            %.3f %% of one core (%.3f s CPU in %.1f s; target <= 1 %%)\n",
              100.0 * cpu_s / wall_s, cpu_s, wall_s);
  std::printf("  RSS            %.1f MB now, %.1f MB peak (target <= 30 MB)\n", rss_mb, peak_mb);
  std::printf("  stop           exit code %d after SIGTERM\n", code);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace pvtwin::cli
