#include "daemon/service/upload_worker.h"

#include <algorithm>

#include "core/common/clock.h"
#include "core/common/text.h"

namespace pvtwin {

UploadSettings UploadSettingsFor(const Config& config) {
  UploadSettings s;
  s.store_path = config.storage.path;
  s.url = config.upload.url;
  s.password_file = config.upload.password_file;
  s.plant_id = config.upload.plant_id;
  s.batch_rows = config.upload.batch_rows;
  s.forecast_days = config.upload.forecast_days;
  return s;
}

UploadWorker::UploadWorker(const UploadSettings& settings, double interval_s, LogFn log)
    : settings_(settings), interval_s_(interval_s), log_(std::move(log)) {
  // A stop ends any wait on the server at once (io/fleet/pg_client.h PgWait).
  settings_.stop = stop_.Flag();
}

UploadWorker::~UploadWorker() { Stop(); }

void UploadWorker::Start() {
  thread_ = std::thread([this] { Loop(); });
}

void UploadWorker::Stop() {
  stop_.Set();
  if (thread_.joinable()) thread_.join();
}

bool UploadWorker::Round(PgError* error) {
  bool more = true;
  while (more) {
    if (stop_.IsSet()) return true;
    std::int64_t rows = 0;
    if (!uploader_->UploadBatches(&rows, &more, error)) return false;
    rows_ += rows;
    if (state_.load() != UploadState::kConnected) Enter(UploadState::kConnected, {});
  }
  uploader_->RecordState(UploadState::kConnected, "", true);
  return true;
}

void UploadWorker::Enter(UploadState next, const PgError& error) {
  const UploadState before = state_.exchange(next);
  if (uploader_) uploader_->RecordState(next, error.message, next == UploadState::kConnected);
  if (before == next) return;
  const std::string server = uploader_ ? uploader_->server() : settings_.url;
  switch (next) {
    case UploadState::kConnected:
      if (before == UploadState::kStarting) {
        log_(kNotice, "upload: connected to " + server + " as plant_id " + settings_.plant_id);
      } else {
        log_(kNotice, "upload: recovered (" + std::string(UploadStateName(before)) + " for " +
                          FixedDecimals(WallNowS() - down_since_s_, 0) + " s), connected to " + server +
                          "; the queued rows follow");
      }
      break;
    case UploadState::kAuthFailed:
      log_(kErr, "upload: authentication failed: " + error.message +
                     " (password from [upload] password_file, the credential pgpassword or "
                     "~/.pgpass); rows stay queued in the store, retried with backoff");
      break;
    case UploadState::kRefused:
      log_(kErr, "upload: refused: " + error.message +
                     "; rows stay queued in the store, retried with backoff");
      break;
    case UploadState::kDown:
      log_(kWarning, "upload: server down: " + error.message +
                         "; rows stay queued in the store, retried with backoff");
      break;
    case UploadState::kStarting:
      break;
  }
  if (next != UploadState::kConnected && before == UploadState::kConnected) {
    down_since_s_ = WallNowS();
  } else if (next != UploadState::kConnected && before == UploadState::kStarting) {
    down_since_s_ = WallNowS();
  }
}

void UploadWorker::Loop() {
  Backoff backoff(1.0, std::clamp(5.0 * interval_s_, 5.0, 300.0));
  while (!stop_.IsSet()) {
    PgError error;
    if (!uploader_) {
      std::string why;
      uploader_ = Uploader::Open(settings_, &why);
      if (!uploader_) error = {PgFault::kLocal, why, ""};
    }
    if (uploader_ && Round(&error)) {
      backoff.Reset();
      stop_.WaitFor(interval_s_);
      continue;
    }
    if (error.fault == PgFault::kInterrupted) break;  // the stop: no fault of the server
    Enter(StateForFault(error.fault), error);
    stop_.WaitFor(backoff.Next());
  }
}

}  // namespace pvtwin
