// The SQLite store: opening it (read-write with its migrations, or
// read-only), its backup and its checkpoint. The design (schema, units, time,
// WAL and crash behaviour, retention) is described at the head of
// io/store/store.h; the parts of the store are listed in io/store/store_impl.h.
#include <sqlite3.h>

#include <memory>
#include <string>
#include <vector>

#include "io/platform/local_time.h"
#include "io/store/store_impl.h"

namespace pvtwin {

using namespace store_detail;

Store::Store(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Store::~Store() = default;

const std::string& Store::path() const { return impl_->path; }

const Store::SchemaUpgrade& Store::upgrade() const { return impl_->upgrade; }

bool Store::BackupTo(const std::string& target_path, std::string* error) {
  std::lock_guard lock(impl_->mutex);
  return impl_->BackupTo(target_path, error);
}

bool Store::Impl::BackupTo(const std::string& target_path, std::string* error) {
  sqlite3* target = nullptr;
  int rc = sqlite3_open_v2(target_path.c_str(), &target, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE,
                           nullptr);
  if (rc == SQLITE_OK) {
    sqlite3_backup* backup = sqlite3_backup_init(target, "main", db, "main");
    if (backup == nullptr) {
      rc = sqlite3_errcode(target);
    } else {
      sqlite3_backup_step(backup, -1);
      rc = sqlite3_backup_finish(backup);
    }
  }
  if (rc != SQLITE_OK) {
    *error =
        target_path + ": backup failed: " + (target ? sqlite3_errmsg(target) : "out of memory");
  }
  sqlite3_close(target);
  return rc == SQLITE_OK;
}

std::unique_ptr<Store> Store::Open(const std::string& path, std::string* error) {
  return Open(path, StoreOptions{}, error);
}

std::unique_ptr<Store> Store::Open(const std::string& path, const StoreOptions& options,
                                   std::string* error) {
  assert(error != nullptr);
  std::vector<LocalDay> no_days;
  std::string why;
  if (!options.time_zone.empty() &&
      !LocalDaysOverlapping(options.time_zone, 0, 0, &no_days, &why)) {
    *error = path + ": local days: " + why;
    return nullptr;
  }
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->options = options;
  const int rc =
      sqlite3_open_v2(path.c_str(), &impl->db,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    *error = impl->Describe(impl->Fail(rc, "cannot open database"));
    return nullptr;
  }
  sqlite3_extended_result_codes(impl->db, 0);
  sqlite3_busy_timeout(impl->db, options.busy_timeout_ms);
  // Everything the store refuses is refused before it writes anything (the
  // switch to WAL below is a write).
  if (!impl->CheckWritable(error) || !impl->CheckIntegrityAndOwner(error)) return nullptr;

  // WAL is persistent in the file; switching needs a moment without other
  // writers, so it is retried like a transaction.
  std::string mode;
  const bool wal_ok = impl->Run(
      false, "set journal_mode = WAL",
      [&impl, &mode]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        const int prc =
            sqlite3_prepare_v2(impl->db, "PRAGMA journal_mode = WAL", -1, &stmt, nullptr);
        if (prc != SQLITE_OK) return impl->Fail(prc, "PRAGMA journal_mode");
        const int src = sqlite3_step(stmt);
        if (src == SQLITE_ROW) mode = ColumnText(stmt, 0);
        sqlite3_finalize(stmt);
        return src == SQLITE_ROW ? DbStatus{} : impl->Fail(src, "PRAGMA journal_mode");
      },
      error);
  if (!wal_ok) return nullptr;
  if (mode != "wal") {
    *error = path + ": journal_mode = " + mode +
             ": the store needs WAL (is it on a network "
             "file system?)";
    return nullptr;
  }
  if (!impl->Run(
          false, "set synchronous = NORMAL",
          [&impl] { return impl->Exec("PRAGMA synchronous = NORMAL"); }, error)) {
    return nullptr;
  }

  if (!impl->Migrate(error) || !impl->SyncLocalDays(error)) return nullptr;
  return std::unique_ptr<Store>(new Store(std::move(impl)));
}

bool Store::Checkpoint(std::int64_t* db_bytes, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::int64_t bytes = 0;
  const bool ok = db.Run(
      false, "checkpoint",
      [&]() -> DbStatus {
        int log_frames = 0, checkpointed = 0;
        const int rc = sqlite3_wal_checkpoint_v2(db.db, nullptr, SQLITE_CHECKPOINT_TRUNCATE,
                                                 &log_frames, &checkpointed);
        // BUSY here means a reader holds an old snapshot: the checkpoint did
        // what it could, which is all a best-effort checkpoint promises.
        if (rc != SQLITE_OK && rc != SQLITE_BUSY) return db.Fail(rc, "wal_checkpoint");
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(
            "SELECT (page_count - freelist_count) * page_size "
            "FROM pragma_page_count(), pragma_freelist_count(), pragma_page_size()",
            &stmt);
        if (!s.ok()) return s;
        const int src = sqlite3_step(stmt);
        if (src != SQLITE_ROW) return db.Fail(src, "page_count");
        bytes = sqlite3_column_int64(stmt, 0);
        sqlite3_reset(stmt);
        return {};
      },
      error);
  if (ok && db_bytes != nullptr) *db_bytes = bytes;
  return ok;
}

// --- Read-only open (the verbs that only read) ---

namespace {

// path as the path of an SQLite URI ("file:PATH?…"): '%', '?' and '#' escaped.
std::string UriPath(const std::string& path) {
  std::string out;
  for (const char c : path) {
    if (c == '%') {
      out += "%25";
    } else if (c == '?') {
      out += "%3f";
    } else if (c == '#') {
      out += "%23";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

std::unique_ptr<Store> Store::OpenReadOnly(const std::string& path, const StoreOptions& options,
                                           std::string* error) {
  assert(error != nullptr);
  if (::access(path.c_str(), F_OK) != 0) {
    *error = path + ": no such store (" + std::strerror(errno) + ")";
    return nullptr;
  }
  const auto open = [&](const char* query) -> std::unique_ptr<Impl> {
    auto impl = std::make_unique<Impl>();
    impl->path = path;
    impl->options = options;
    const std::string uri = "file:" + UriPath(path) + "?" + query;
    const int rc =
        sqlite3_open_v2(uri.c_str(), &impl->db,
                        SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_NOMUTEX, nullptr);
    if (rc != SQLITE_OK) {
      *error = impl->Describe(impl->Fail(rc, "cannot open the store read-only"));
      return nullptr;
    }
    sqlite3_extended_result_codes(impl->db, 0);
    sqlite3_busy_timeout(impl->db, options.busy_timeout_ms);
    return impl;
  };
  std::unique_ptr<Impl> impl = open("mode=ro");
  if (impl == nullptr) return nullptr;
  // A WAL store is read through its -shm: without it, and without the right
  // to create it, the first read fails. No -wal and no -shm means no
  // connection has the store open, so its file alone is the whole store.
  int rc = sqlite3_exec(impl->db, "SELECT count(*) FROM sqlite_schema", nullptr, nullptr, nullptr);
  if ((rc == SQLITE_CANTOPEN || rc == SQLITE_READONLY) &&
      ::access((path + "-wal").c_str(), F_OK) != 0 &&
      ::access((path + "-shm").c_str(), F_OK) != 0) {
    impl = open("immutable=1");
    if (impl == nullptr) return nullptr;
    rc = sqlite3_exec(impl->db, "SELECT count(*) FROM sqlite_schema", nullptr, nullptr, nullptr);
  }
  if (rc != SQLITE_OK && rc != SQLITE_NOTADB) {
    *error = impl->Describe(impl->Fail(rc, "cannot read the store")) +
             "; a reader needs read access to the file and to its -wal and -shm files";
    return nullptr;
  }
  if (!impl->CheckIntegrityAndOwner(error)) return nullptr;
  int version = 0;
  sqlite3_exec(
      impl->db, "PRAGMA user_version",
      [](void* out, int, char** values, char**) {
        *static_cast<int*>(out) = values[0] ? std::atoi(values[0]) : 0;
        return 0;
      },
      &version, nullptr);
  if (version == 0) {
    *error = path + ": an empty database, not a pvtwin store yet; nothing to read";
    return nullptr;
  }
  if (version < kStoreSchemaVersion) {
    *error = path + ": store schema " + std::to_string(version) + " is older than this pvtwin's " +
             std::to_string(kStoreSchemaVersion) +
             "; run the daemon or `pvtwin migrate` to upgrade it (this command only reads)";
    return nullptr;
  }
  return std::unique_ptr<Store>(new Store(std::move(impl)));
}

}  // namespace pvtwin
