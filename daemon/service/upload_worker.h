// The upload of the store into the central PostgreSQL as a thread of its
// own (io/fleet/upload.h does the work): the daemon's loop never waits for the
// server. While the server is down, unreachable or refusing, the thread
// retries with exponential backoff (1 s doubling up to
// clamp(5·interval_s, 5 s, 300 s)) and the rows wait in the store's queue;
// the log gets one line per change of state (connected, down, recovered,
// auth failure, refused), not one per retry, and upload_connection in the
// store says the same for the operator.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "config/plant_config.h"
#include "daemon/service/worker_thread.h"
#include "io/platform/log.h"
#include "io/fleet/upload.h"

namespace pvtwin {

// The upload's settings from the config's [upload] and [storage] path.
UploadSettings UploadSettingsFor(const Config& config);

class UploadWorker {
 public:
  UploadWorker(const UploadSettings& settings, double interval_s, LogFn log);
  ~UploadWorker();  // stops and joins
  UploadWorker(const UploadWorker&) = delete;
  UploadWorker& operator=(const UploadWorker&) = delete;

  void Start();
  // Asks the thread to stop, and joins it: a batch in flight is abandoned at
  // once, whatever the server does (its rows stay queued).
  void Stop();

  UploadState state() const { return state_.load(); }
  std::int64_t rows_uploaded() const { return rows_.load(); }

 private:
  void Loop();
  // One round: batches until nothing is pending. False after a fault.
  bool Round(PgError* error);
  void Enter(UploadState next, const PgError& error);

  UploadSettings settings_;
  double interval_s_;
  LogFn log_;
  std::unique_ptr<Uploader> uploader_;
  std::thread thread_;
  StopRequest stop_;
  std::atomic<UploadState> state_{UploadState::kStarting};
  std::atomic<std::int64_t> rows_{0};
  double down_since_s_ = 0.0;
};

}  // namespace pvtwin
