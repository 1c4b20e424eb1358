// pvtwin upload: the store's rows into the central PostgreSQL of [upload]
// (io/fleet/upload.h). --init creates or migrates the central schema; --once
// sends everything queued and exits (cron, and the backfill of a year of
// history: resumable, since the high-water mark moves after every batch);
// without either it keeps uploading every interval_s until SIGTERM/SIGINT,
// as the daemon's upload thread does.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "core/common/clock.h"
#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/store_cli.h"
#include "daemon/service/upload_worker.h"
#include "io/platform/log.h"
#include "io/fleet/upload.h"

namespace pvtwin::cli {

namespace {

std::atomic<bool> g_upload_stop(false);
extern "C" void OnUploadStop(int) { g_upload_stop.store(true); }

struct UploadArgs {
  std::string config;
  std::string db;
  bool once = false;
  bool init = false;
  bool takeover = false;
  bool resend = false;
  double progress_every_s = 10.0;
};

UploadSettings SettingsFor(const Config& config) {
  UploadSettings s = UploadSettingsFor(config);
  s.stop = &g_upload_stop;
  return s;
}

std::string Duration(double s) {
  char buf[32];
  if (s < 120) {
    std::snprintf(buf, sizeof buf, "%.0f s", s);
  } else if (s < 7200) {
    std::snprintf(buf, sizeof buf, "%.0f min", s / 60);
  } else {
    std::snprintf(buf, sizeof buf, "%.1f h", s / 3600);
  }
  return buf;
}

// Progress of --once: on a terminal one line rewritten in place, otherwise
// one line every progress_every_s.
class Progress {
 public:
  Progress(std::int64_t total, double every_s)
      : total_(total), tty_(::isatty(STDERR_FILENO) == 1), every_s_(tty_ ? 0.25 : every_s) {}
  void Update(std::int64_t done, bool last) {
    const double elapsed = SecondsSince(start_);
    if (!last && elapsed < next_s_) return;
    next_s_ = elapsed + every_s_;
    const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
    const std::int64_t left = std::max<std::int64_t>(0, total_ - done);
    char line[160];
    std::snprintf(
        line, sizeof line, "upload: %lld/%lld rows (%.0f %%), %.0f rows/s, ETA %s",
        static_cast<long long>(done), static_cast<long long>(total_),
        total_ > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total_) : 100.0, rate,
        rate > 0 ? Duration(static_cast<double>(left) / rate).c_str() : "-");
    if (tty_) {
      std::fprintf(stderr, "\r%s\033[K%s", line, last ? "\n" : "");
    } else {
      std::fprintf(stderr, "%s\n", line);
    }
  }
  double elapsed() const { return SecondsSince(start_); }

 private:
  std::int64_t total_;
  bool tty_;
  double every_s_;
  double next_s_ = 0.0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

void LogLine(int priority, const std::string& line) { LogToStderr(priority, line); }

int RunOnce(Uploader& uploader, double progress_every_s) {
  std::vector<TablePending> pending;
  std::string error;
  if (!uploader.Pending(&pending, &error)) {
    std::cerr << error << "\n";
    return kExitRuntime;
  }
  std::int64_t total = 0;
  for (const TablePending& p : pending) total += p.rows;
  Progress progress(total, progress_every_s);
  std::int64_t done = 0;
  bool more = true;
  while (more && !g_upload_stop.load()) {
    std::int64_t rows = 0;
    PgError pg_error;
    if (!uploader.UploadBatches(&rows, &more, &pg_error)) {
      if (pg_error.fault != PgFault::kInterrupted) {
        uploader.RecordState(StateForFault(pg_error.fault), pg_error.message, false);
      }
      std::cerr << "upload: " << pg_error.message << " (" << done
                << " rows uploaded before; the rest stays queued, a later run resumes)\n";
      return kExitRuntime;
    }
    done += rows;
    progress.Update(done, false);
  }
  progress.Update(done, true);
  uploader.RecordState(UploadState::kConnected, "", !g_upload_stop.load());
  std::cerr << "upload: " << done << " rows to " << uploader.server() << " in "
            << Duration(progress.elapsed()) << (g_upload_stop.load() ? " (interrupted)" : "")
            << "\n";
  return g_upload_stop.load() ? kExitRuntime : kExitOk;
}

int RunUpload(const UploadArgs& a) {
  Config config;
  if (!LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  if (!config.upload.enabled) {
    std::cerr << a.config << ": no [upload] section (url, plant_id): nothing to upload to\n";
    return kExitBadInput;
  }
  if (!a.db.empty()) config.storage.path = a.db;
  // The store is opened (created, migrated) the way the daemon opens it.
  std::unique_ptr<Store> store;
  if (!OpenStoreOrReport(config.storage.path, StoreOptionsFor(config), &store)) {
    return kExitRuntime;
  }
  struct sigaction sa {};
  sigemptyset(&sa.sa_mask);
  sa.sa_handler = OnUploadStop;
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  UploadSettings settings = SettingsFor(config);
  settings.takeover = a.takeover;
  settings.resend = a.resend;
  if (!a.once && !a.init) {
    UploadWorker worker(settings, config.upload.interval_s, LogLine);
    worker.Start();
    while (!g_upload_stop.load()) ::usleep(100000);
    worker.Stop();
    return kExitOk;
  }
  std::string error;
  std::unique_ptr<Uploader> uploader = Uploader::Open(settings, &error);
  if (!uploader) {
    std::cerr << error << "\n";
    return kExitRuntime;
  }
  PgError pg_error;
  if (!uploader->Connect(&pg_error)) {
    if (pg_error.fault != PgFault::kInterrupted) {
      uploader->RecordState(StateForFault(pg_error.fault), pg_error.message, false);
    }
    std::cerr << "upload: " << pg_error.message << "\n";
    return kExitRuntime;
  }
  if (a.init) {
    std::cerr << "upload: central schema version " << kCentralSchemaVersion << " ready on "
              << uploader->server() << " (plant_id " << settings.plant_id << ")\n";
    if (!a.once) return kExitOk;
  }
  return RunOnce(*uploader, a.progress_every_s);
}

}  // namespace

void RegisterUpload(CLI::App& app) {
  auto args = std::make_shared<UploadArgs>();
  CLI::App* cmd = app.add_subcommand(
      "upload",
      "Replicate the store into the central PostgreSQL of [upload] (url, plant_id; the password\n"
      "from password_file, the systemd credential pgpassword or ~/.pgpass). Every uploaded\n"
      "table has a leading plant_id column there; a row is sent again when it changes\n"
      "locally. --init creates or migrates the central schema; --once sends what is queued\n"
      "(resumable: a later run continues where this one stopped) and exits; without them it\n"
      "uploads every [upload] interval_s until SIGTERM, like the daemon's upload thread.\n"
      "[upload] defaults: interval_s = 60, batch_rows = 5000, forecast_days = 7.\n"
      "A stop (SIGTERM, SIGINT) ends any wait on the server at once; what was not sent stays\n"
      "queued. A server that does not answer for 130 s counts as down.\n"
      "Exit 0 success, 1 server unreachable or refusing, 2 bad config.\n"
      "Example: pvtwin upload --once --config /etc/pvtwin/pvtwin.toml");
  cmd->add_option("--config", args->config, "the daemon's TOML config with [upload]")->required();
  cmd->add_option("--db", args->db, "SQLite file (overrides [storage] path)");
  cmd->add_flag("--once", args->once, "upload what is queued, then exit");
  cmd->add_flag("--init", args->init, "create or migrate the central schema, then exit");
  cmd->add_flag("--takeover", args->takeover,
                "bind [upload] plant_id centrally to this store although another store holds it "
                "(the plant moved to new hardware)");
  cmd->add_flag("--resend", args->resend,
                "queue every row of the store again (after the central tables were lost)");
  cmd->add_option("--progress-every", args->progress_every_s,
                  "seconds between progress lines of --once when stderr is not a terminal")
      ->check(CLI::PositiveNumber);
  cmd->callback([args] { SetExitCode(RunUpload(*args)); });
}

}  // namespace pvtwin::cli
