// The upload of the store into PostgreSQL; the design (queue, high-water
// mark, central schema) is described at the head of io/fleet/upload.h.
#include "io/fleet/upload.h"

#include <sqlite3.h>

#include <algorithm>
#include <cassert>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>

#include "io/fleet/central_views.h"

namespace pvtwin {

const std::vector<UploadTable>& UploadTables() {
  // Tables of the store (io/store/store.h and doc/contracts.md "Operation contracts");
  // those the local store does not have are left out.
  static const std::vector<UploadTable> tables = {
      {"measurement_1min", {"ts"}, {"ts"}, {}, {}, {}},
      {"calibration", {"id"}, {"id"}, {}, {}, {}},
      {"calibration_param", {"calibration_id", "name"}, {"calibration_id", "name"}, {}, {}, {}},
      {"diagnosis", {"id"}, {"id"}, {}, {}, {}},
      {"performance_daily", {"day"}, {"day"}, {}, {}, {}},
      {"qc_event", {"id"}, {"id"}, {}, {}, {}},
      {"monitor_event", {"id"}, {"id"}, {}, {}, {}},
      {"measurement_interval", {"ts"}, {"ts"}, {}, {}, {}},
      {"forecast", {"ts", "issued_at"}, {"ts"}, "issued_at", "ts", "forecast_day_ahead"},
  };
  return tables;
}

std::string_view UploadStateName(UploadState state) {
  switch (state) {
    case UploadState::kStarting:
      return "starting";
    case UploadState::kConnected:
      return "connected";
    case UploadState::kDown:
      return "down";
    case UploadState::kAuthFailed:
      return "auth_failed";
    case UploadState::kRefused:
      return "refused";
  }
  return "starting";
}

UploadState StateForFault(PgFault fault) {
  switch (fault) {
    case PgFault::kAuth:
      return UploadState::kAuthFailed;
    case PgFault::kRefused:
    case PgFault::kLocal:
      return UploadState::kRefused;
    default:
      return UploadState::kDown;
  }
}

bool ReadUploadPassword(const std::string& password_file, std::string* password,
                        std::string* error) {
  std::string path = password_file;
  if (path.empty()) {
    const char* credentials = std::getenv("CREDENTIALS_DIRECTORY");
    if (credentials == nullptr || *credentials == '\0') {
      password->clear();
      return true;
    }
    path = std::string(credentials) + "/pgpassword";
    if (std::ifstream(path).fail()) {
      password->clear();
      return true;
    }
  }
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) {
    *error = "[upload] password_file = " + path + ": cannot read the password";
    return false;
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  *password = line;
  return true;
}

namespace {

constexpr char kAppName[] = "pvtwin upload";
// pg_advisory_xact_lock key of the schema migration (any constant).
constexpr char kSchemaLockKey[] = "748201113";

enum class PgType { kBigint, kDouble, kText };

struct Column {
  std::string name;
  PgType type = PgType::kText;
};

const char* PgTypeName(PgType t) {
  return t == PgType::kBigint ? "bigint" : t == PgType::kDouble ? "double precision" : "text";
}

// SQLite's declared type → central type (SQLite's affinity rules, short).
PgType TypeOf(std::string declared) {
  for (char& c : declared) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (declared.find("INT") != std::string::npos) return PgType::kBigint;
  if (declared.find("REAL") != std::string::npos || declared.find("FLOA") != std::string::npos ||
      declared.find("DOUB") != std::string::npos) {
    return PgType::kDouble;
  }
  return PgType::kText;
}

std::string Join(const std::vector<std::string_view>& names, const std::string& prefix = "") {
  std::string s;
  for (const std::string_view n : names) s += (s.empty() ? "" : ", ") + prefix + std::string(n);
  return s;
}

// The local SQLite connection of the uploader.
class LocalDb {
 public:
  ~LocalDb() {
    if (db_ != nullptr) sqlite3_close_v2(db_);
  }
  bool Open(const std::string& path, std::string* error) {
    path_ = path;
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) {
      *error = path + ": cannot open the store for the upload: " +
               (db_ ? sqlite3_errmsg(db_) : "out of memory");
      return false;
    }
    sqlite3_busy_timeout(db_, 5000);
    return true;
  }
  bool Exec(const std::string& sql, std::string* error) {
    char* message = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message) == SQLITE_OK) return true;
    *error = path_ + ": " + sql.substr(0, 60) + ": " + (message ? message : "");
    sqlite3_free(message);
    return false;
  }
  // Rows of a query with int64 parameters, cells as SQLite values through
  // on_row.
  bool Query(const std::string& sql, const std::vector<std::int64_t>& params,
             const std::function<void(sqlite3_stmt*)>& on_row, std::string* error,
             const std::string& text_param = "") {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
      *error = path_ + ": " + sql.substr(0, 60) + ": " + sqlite3_errmsg(db_);
      return false;
    }
    int index = 1;
    if (!text_param.empty()) {
      sqlite3_bind_text(stmt, index++, text_param.c_str(), -1, SQLITE_TRANSIENT);
    }
    for (const std::int64_t p : params) sqlite3_bind_int64(stmt, index++, p);
    int rc;
    while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) on_row(stmt);
    if (rc != SQLITE_DONE) *error = path_ + ": " + sql.substr(0, 60) + ": " + sqlite3_errmsg(db_);
    sqlite3_finalize(stmt);
    return rc == SQLITE_DONE;
  }
  // A statement with text parameters (no rows expected).
  bool ExecBound(const std::string& sql, const std::vector<std::string>& texts,
                 std::string* error) {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
      *error = path_ + ": " + sql.substr(0, 60) + ": " + sqlite3_errmsg(db_);
      return false;
    }
    for (std::size_t i = 0; i < texts.size(); ++i) {
      sqlite3_bind_text(stmt, static_cast<int>(i) + 1, texts[i].c_str(), -1, SQLITE_TRANSIENT);
    }
    const int rc = sqlite3_step(stmt);
    if (rc != SQLITE_DONE) *error = path_ + ": " + sql.substr(0, 60) + ": " + sqlite3_errmsg(db_);
    sqlite3_finalize(stmt);
    return rc == SQLITE_DONE;
  }
  bool Rollback() { return sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr) == SQLITE_OK; }
  const std::string& path() const { return path_; }

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
};

std::string ColumnText(sqlite3_stmt* stmt, int i) {
  const unsigned char* t = sqlite3_column_text(stmt, i);
  return t ? reinterpret_cast<const char*>(t) : "";
}

// One cell in COPY text format, converted to the central type: a value the
// type cannot hold (text in a REAL column, written by an outside program)
// is sent as NULL rather than failing the batch forever.
void AppendCell(sqlite3_stmt* stmt, int i, PgType type, std::string* out) {
  const int kind = sqlite3_column_type(stmt, i);
  if (kind == SQLITE_NULL) {
    *out += "\\N";
    return;
  }
  char buf[40];
  if (type == PgType::kText) {
    AppendCopyText(ColumnText(stmt, i), out);
    return;
  }
  double x = 0.0;
  if (kind == SQLITE_INTEGER) {
    if (type == PgType::kBigint) {
      const auto r = std::to_chars(buf, buf + sizeof buf, sqlite3_column_int64(stmt, i));
      out->append(buf, r.ptr);
      return;
    }
    x = static_cast<double>(sqlite3_column_int64(stmt, i));
  } else if (kind == SQLITE_FLOAT) {
    x = sqlite3_column_double(stmt, i);
  } else {
    const std::string text = ColumnText(stmt, i);
    char* end = nullptr;
    x = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0') x = std::nan("");
  }
  if (type == PgType::kBigint) {
    if (!std::isfinite(x) || x != std::floor(x) || std::fabs(x) > 9.2e18) {
      *out += "\\N";
    } else {
      std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(x));
      *out += buf;
    }
    return;
  }
  if (std::isnan(x)) {
    *out += "\\N";
  } else if (std::isinf(x)) {
    *out += x > 0 ? "Infinity" : "-Infinity";
  } else {
    const auto r = std::to_chars(buf, buf + sizeof buf, x);  // shortest exact
    out->append(buf, r.ptr);
  }
}

std::int64_t NowS() { return static_cast<std::int64_t>(std::time(nullptr)); }

// 00:00 UTC of the UTC day of a unix-seconds expression, in SQLite's and in
// PostgreSQL's SQL (the store's forecast_skill rule, negative times too).
std::string SqliteDayStart(const std::string& ts) {
  return "(" + ts + " - ((" + ts + " % 86400) + 86400) % 86400)";
}
std::string PgDayStart(const std::string& ts) {
  return "(" + ts + " - mod(mod(" + ts + ", 86400) + 86400, 86400))";
}

}  // namespace

struct Uploader::Impl {
  UploadSettings settings;
  LocalDb local;
  std::unique_ptr<PgConnection> pg;
  std::string server;
  // Uploaded tables the local store has, with their columns.
  struct Table {
    const UploadTable* spec = nullptr;
    std::vector<Column> columns;
  };
  std::vector<Table> tables;
  std::string store_id;  // the local store's store_identity

  bool PrepareLocal(std::string* error);
  bool InstallTable(const UploadTable& spec, std::string* error);
  bool ReadColumns(Table* table, std::string* error);
  bool ForgetUploads(std::string* error);
  bool ReadStoreId(std::string* error);
  bool CentralSchemaComplete(bool* complete, PgError* error);
  bool CheckLostTables(const std::map<std::string, std::vector<std::string>>& central,
                       PgError* error);
  bool BindStore(PgError* error);
  bool MigrateCentral(PgError* error);
  std::string CentralTableDdl(const Table& t) const;
  std::string DayAheadTableDdl(const UploadTable& spec, bool exists) const;
  bool UploadBatch(const Table& t, std::int64_t* settled, bool* full, PgError* error);
  bool ReadBatch(const Table& t, std::int64_t hwm, std::string* copy, std::int64_t* rows_sent,
                 std::int64_t* max_seq, std::int64_t* settled, std::int64_t* keep_from,
                 std::string* error);
  bool SendBatch(const Table& t, const std::string& copy, std::int64_t keep_from, PgError* error);
  static std::string DayAheadUpsert(const Table& t, const std::string& cols,
                                    const std::string& updates);
};

namespace {

const char* const kLocalSchema[] = {
    "CREATE TABLE IF NOT EXISTS upload_queue(seq INTEGER PRIMARY KEY AUTOINCREMENT, "
    "table_name TEXT NOT NULL, k1 NOT NULL, k2 NOT NULL DEFAULT '', "
    "UNIQUE(table_name, k1, k2))",
    "CREATE INDEX IF NOT EXISTS upload_queue_by_table ON upload_queue(table_name, seq)",
    "CREATE TABLE IF NOT EXISTS upload_state(table_name TEXT PRIMARY KEY, "
    "hwm INTEGER NOT NULL DEFAULT 0, rows_uploaded INTEGER NOT NULL DEFAULT 0, "
    "last_upload_at INTEGER)",
    "CREATE TABLE IF NOT EXISTS upload_connection(id INTEGER PRIMARY KEY CHECK(id = 1), "
    "state TEXT NOT NULL, since INTEGER, last_success INTEGER, last_error TEXT, "
    "last_error_at INTEGER, server TEXT)",
    "CREATE VIEW IF NOT EXISTS upload_status(table_name, state, since, last_success, "
    "last_error, last_error_at, rows_uploaded, rows_pending, hwm) AS "
    "SELECT s.table_name, c.state, c.since, c.last_success, c.last_error, c.last_error_at, "
    "s.rows_uploaded, (SELECT count(*) FROM upload_queue q WHERE q.table_name = s.table_name "
    "AND q.seq > s.hwm), s.hwm FROM upload_state s LEFT JOIN upload_connection c ON c.id = 1",
};

}  // namespace

bool Uploader::Impl::PrepareLocal(std::string* error) {
  if (!ReadStoreId(error)) return false;
  if (!local.Exec("BEGIN IMMEDIATE", error)) return false;
  for (const char* sql : kLocalSchema) {
    if (!local.Exec(sql, error)) {
      local.Rollback();
      return false;
    }
  }
  if (settings.resend && !ForgetUploads(error)) {
    local.Rollback();
    return false;
  }
  for (const UploadTable& spec : UploadTables()) {
    bool exists = false;
    if (!local.Query(
            "SELECT 1 FROM sqlite_schema WHERE type = 'table' AND name = ?", {},
            [&](sqlite3_stmt*) { exists = true; }, error, std::string(spec.name))) {
      local.Rollback();
      return false;
    }
    if (!exists) continue;
    if (!InstallTable(spec, error)) {
      local.Rollback();
      return false;
    }
    tables.push_back({&spec, {}});
  }
  if (!local.Exec("COMMIT", error)) {
    local.Rollback();
    return false;
  }
  for (Table& t : tables) {
    if (!ReadColumns(&t, error)) return false;
  }
  return true;
}

// The store's id (io/store/store.h store_identity), sent with every upload.
bool Uploader::Impl::ReadStoreId(std::string* error) {
  store_id.clear();
  if (!local.Query(
          "SELECT store_id FROM store_identity WHERE id = 1", {},
          [&](sqlite3_stmt* stmt) { store_id = ColumnText(stmt, 0); }, error)) {
    return false;
  }
  if (store_id.empty()) {
    *error = local.path() + ": the store has no store_identity row (open it with pvtwin first)";
    return false;
  }
  return true;
}

// --resend: every table's triggers and queue go, and its counts restart,
// so that InstallTable queues every stored row again.
bool Uploader::Impl::ForgetUploads(std::string* error) {
  for (const UploadTable& spec : UploadTables()) {
    const std::string name(spec.name);
    if (!local.Exec("DROP TRIGGER IF EXISTS upload_queue_" + name + "_insert; " +
                        "DROP TRIGGER IF EXISTS upload_queue_" + name + "_update; " +
                        "DELETE FROM upload_queue WHERE table_name = '" + name + "'; " +
                        "UPDATE upload_state SET hwm = 0, rows_uploaded = 0 WHERE table_name = '" +
                        name + "'",
                    error)) {
      return false;
    }
  }
  return true;
}

// Triggers that queue every inserted or updated row of the table, and the
// rows already there (once, when the triggers are new). Triggers of an
// older pvtwin (another text) are replaced, and the rows queued again.
bool Uploader::Impl::InstallTable(const UploadTable& spec, std::string* error) {
  const std::string name(spec.name);
  const std::string trigger = "upload_queue_" + name;
  const std::string k1 = std::string(spec.local_key[0]);
  const std::string k2 = spec.local_key.size() > 1 ? std::string(spec.local_key[1]) : "";
  assert(spec.newest_column.empty() ||
         (spec.local_key.size() == 2 && spec.central_key.size() == 1 &&
          spec.central_key[0] == spec.local_key[0] && spec.local_key[1] == spec.newest_column));
  assert(spec.day_ahead_table.empty() ||
         (!spec.newest_column.empty() && spec.keep_column == spec.local_key[0]));
  const std::string new_k2 = k2.empty() ? "''" : "NEW." + k2;
  // The key's old entry goes; with newest_column (local key = central key,
  // newest_column) so do the entries of older rows of the same central key:
  // the queue keeps one entry per central row however often it is re-issued.
  // With day_ahead_table it keeps two: an older day-ahead row's entry stays
  // when the new row is no day-ahead row.
  std::string same = spec.newest_column.empty() ? " = " + new_k2 : " <= " + new_k2;
  if (!spec.day_ahead_table.empty()) {
    const std::string day = SqliteDayStart("NEW." + k1);
    same += " AND (k2 > " + day + " OR " + new_k2 + " <= " + day + ")";
  }
  const std::string body = " ON " + name + " BEGIN DELETE FROM upload_queue WHERE table_name = '" +
                           name + "' AND k1 = NEW." + k1 + " AND k2" + same +
                           "; INSERT INTO upload_queue(table_name, k1, k2) VALUES('" + name +
                           "', NEW." + k1 + ", " + new_k2 + "); END";
  const std::string insert_sql = "CREATE TRIGGER " + trigger + "_insert AFTER INSERT" + body;
  std::string installed;
  if (!local.Query(
          "SELECT sql FROM sqlite_schema WHERE type = 'trigger' AND name = ?", {},
          [&](sqlite3_stmt* stmt) { installed = ColumnText(stmt, 0); }, error,
          trigger + "_insert")) {
    return false;
  }
  if (installed == insert_sql) return true;
  // The rows already stored; of a table with newest_column only the newest
  // row per central key (the others would be replaced centrally anyway),
  // and the newest day-ahead row, within the rows kept centrally.
  std::string backfill = "INSERT OR IGNORE INTO upload_queue(table_name, k1, k2) SELECT '" + name +
                         "', " + k1 + ", " + (k2.empty() ? "''" : k2) + " FROM " + name;
  if (!spec.newest_column.empty()) {
    const std::string newest(spec.newest_column);
    const std::string keep(spec.keep_column);
    std::string same_key;
    for (const std::string_view c : spec.central_key) {
      same_key += " AND g." + std::string(c) + " = " + name + "." + std::string(c);
    }
    const std::string newest_of_key =
        "(SELECT MAX(g." + newest + ") FROM " + name + " g WHERE " + same_key.substr(5);
    backfill += " WHERE (" + newest + " = " + newest_of_key + ")";
    if (!spec.day_ahead_table.empty()) {
      backfill += " OR " + newest + " = " + newest_of_key + " AND g." + newest +
                  " <= " + SqliteDayStart(name + "." + keep) + ")";
    }
    backfill += ") AND " + keep + " >= (SELECT MAX(" + newest + ") FROM " + name + ") - " +
                std::to_string(static_cast<std::int64_t>(settings.forecast_days) * 86400);
  }
  backfill += " ORDER BY " + Join(spec.local_key);
  return local.Exec("DROP TRIGGER IF EXISTS " + trigger + "_insert", error) &&
         local.Exec("DROP TRIGGER IF EXISTS " + trigger + "_update", error) &&
         local.Exec(insert_sql, error) &&
         local.Exec("CREATE TRIGGER " + trigger + "_update AFTER UPDATE" + body, error) &&
         local.Exec(backfill, error) &&
         local.Exec("INSERT OR IGNORE INTO upload_state(table_name) VALUES('" + name + "')", error);
}

bool Uploader::Impl::ReadColumns(Table* t, std::string* error) {
  t->columns.clear();
  return local.Query(
      "SELECT name, type FROM pragma_table_info(?) ORDER BY cid", {},
      [&](sqlite3_stmt* stmt) {
        t->columns.push_back({ColumnText(stmt, 0), TypeOf(ColumnText(stmt, 1))});
      },
      error, std::string(t->spec->name));
}

std::string Uploader::Impl::CentralTableDdl(const Table& t) const {
  const std::string name = QuoteIdent(std::string(t.spec->name));
  std::string sql = "CREATE TABLE IF NOT EXISTS " + name + "(plant_id text NOT NULL";
  for (const Column& c : t.columns) sql += ", " + QuoteIdent(c.name) + " " + PgTypeName(c.type);
  sql += ", PRIMARY KEY(plant_id, " + Join(t.spec->central_key) + "));";
  for (const Column& c : t.columns) {
    sql += "ALTER TABLE " + name + " ADD COLUMN IF NOT EXISTS " + QuoteIdent(c.name) + " " +
           PgTypeName(c.type) + ";";
  }
  return sql;
}

// The day-ahead table of spec (version 5). New: made like the table, with
// its qualifying rows (the migration from version 4); else the columns
// this plant's table has are added.
std::string Uploader::Impl::DayAheadTableDdl(const UploadTable& spec, bool exists) const {
  const std::string name = QuoteIdent(std::string(spec.name));
  const std::string day_ahead = QuoteIdent(std::string(spec.day_ahead_table));
  if (!exists) {
    return "CREATE TABLE " + day_ahead + " (LIKE " + name +
           " INCLUDING DEFAULTS INCLUDING CONSTRAINTS INCLUDING INDEXES); INSERT INTO " +
           day_ahead + " SELECT * FROM " + name + " WHERE " +
           QuoteIdent(std::string(spec.newest_column)) +
           " <= " + PgDayStart(QuoteIdent(std::string(spec.keep_column))) + ";";
  }
  std::string sql;
  for (const Table& t : tables) {
    if (t.spec != &spec) continue;
    for (const Column& c : t.columns) {
      sql += "ALTER TABLE " + day_ahead + " ADD COLUMN IF NOT EXISTS " + QuoteIdent(c.name) + " " +
             PgTypeName(c.type) + ";";
    }
  }
  return sql;
}

// True when the schema version, every table and column and the view exist
// (then a role without CREATE can upload).
bool Uploader::Impl::CentralSchemaComplete(bool* complete, PgError* error) {
  std::vector<std::vector<std::string>> rows;
  if (!pg->Query("SELECT table_name, column_name FROM information_schema.columns "
                 "WHERE table_schema = current_schema()",
                 {}, &rows, error)) {
    return false;
  }
  std::map<std::string, std::vector<std::string>> central;
  for (const auto& r : rows) central[r[0]].push_back(r[1]);
  if (!CheckLostTables(central, error)) return false;
  const auto plant = central.find("plant");
  *complete =
      central.count("pvtwin_schema") && plant != central.end() &&
      std::find(plant->second.begin(), plant->second.end(), "store_id") != plant->second.end() &&
      central.count("plant_latest") && central.count("event") && central.count("forecast_skill");
  for (const Table& t : tables) {
    for (const std::string_view name : {t.spec->name, t.spec->day_ahead_table}) {
      if (name.empty()) continue;
      const auto it = central.find(std::string(name));
      if (it == central.end()) {
        *complete = false;
        continue;
      }
      for (const Column& c : t.columns) {
        if (std::find(it->second.begin(), it->second.end(), c.name) == it->second.end()) {
          *complete = false;
        }
      }
    }
  }
  // Another plant's table without its day-ahead table (version 4).
  for (const UploadTable& spec : UploadTables()) {
    if (!spec.day_ahead_table.empty() && central.count(std::string(spec.name)) &&
        !central.count(std::string(spec.day_ahead_table))) {
      *complete = false;
    }
  }
  if (central.count("pvtwin_schema")) {
    std::vector<std::vector<std::string>> version;
    if (!pg->Query("SELECT max(version) FROM pvtwin_schema", {}, &version, error)) return false;
    const int found = version.empty() ? 0 : std::atoi(version[0][0].c_str());
    if (found > kCentralSchemaVersion) {
      *error = {PgFault::kRefused,
                "the central schema is version " + std::to_string(found) +
                    ", newer than this pvtwin knows (" + std::to_string(kCentralSchemaVersion) +
                    "); upgrade pvtwin",
                ""};
      return false;
    }
    *complete = *complete && found == kCentralSchemaVersion;
  }
  return true;
}

// Every uploaded table this plant has sent rows into must still be there
// (on this server: a new, empty central database counts as lost too), with
// its key columns.
bool Uploader::Impl::CheckLostTables(const std::map<std::string, std::vector<std::string>>& central,
                                     PgError* error) {
  for (const Table& t : tables) {
    const std::string name(t.spec->name);
    std::int64_t uploaded = 0, pending = 0;
    std::string local_error;
    if (!local.Query(
            "SELECT rows_uploaded, rows_pending FROM upload_status WHERE table_name = ?", {},
            [&](sqlite3_stmt* stmt) {
              uploaded = sqlite3_column_int64(stmt, 0);
              pending = sqlite3_column_int64(stmt, 1);
            },
            &local_error, name)) {
      *error = {PgFault::kLocal, local_error, ""};
      return false;
    }
    const auto it = central.find(name);
    const std::string counts = std::to_string(uploaded) + " rows of plant_id " + settings.plant_id +
                               " were uploaded into it and " + std::to_string(pending) +
                               " are queued";
    if (it == central.end()) {
      if (uploaded == 0) continue;  // new to this plant: MigrateCentral creates it
      *error = {PgFault::kRefused,
                "central table " + name + " is missing on " + server + ", although " + counts +
                    " (renamed or dropped?): restore it, or send every row again with "
                    "`pvtwin upload --once --resend`",
                ""};
      return false;
    }
    std::vector<std::string_view> keys = {"plant_id"};
    keys.insert(keys.end(), t.spec->central_key.begin(), t.spec->central_key.end());
    for (const std::string_view key : keys) {
      if (std::find(it->second.begin(), it->second.end(), key) == it->second.end()) {
        *error = {PgFault::kRefused,
                  "central table " + name + " on " + server + " has no key column " +
                      std::string(key) + " (" + counts + "): it is not pvtwin's table",
                  ""};
        return false;
      }
    }
  }
  return true;
}

// Binds plant_id to this store centrally: the first store to upload (or a
// plant row from before store ids) takes it; another store's plant_id is
// refused unless takeover.
bool Uploader::Impl::BindStore(PgError* error) {
  const std::vector<std::string> ids = {settings.plant_id, store_id};
  std::vector<std::vector<std::string>> rows;
  if (!pg->Query("INSERT INTO plant(plant_id, first_upload_at, store_id) VALUES($1, "
                 "extract(epoch FROM now())::bigint, $2) ON CONFLICT DO NOTHING",
                 ids, nullptr, error) ||
      !pg->Query("SELECT coalesce(store_id, ''), coalesce(last_upload_at::text, 'never') "
                 "FROM plant WHERE plant_id = $1",
                 {settings.plant_id}, &rows, error)) {
    return false;
  }
  const std::string holder = rows.empty() ? "" : rows[0][0];
  if (holder == store_id) return true;
  if (!holder.empty() && !settings.takeover) {
    *error = {PgFault::kRefused,
              "plant_id " + settings.plant_id + " belongs centrally to another store (store_id " +
                  holder + ", last upload at unix " + rows[0][1] + "), not to " + local.path() +
                  " (store_id " + store_id +
                  "): two sites with one plant_id would overwrite each other's rows. Give this "
                  "site its own [upload] plant_id; if this store replaces the other one (new "
                  "hardware), run `pvtwin upload --once --takeover` once",
              ""};
    return false;
  }
  return pg->Query("UPDATE plant SET store_id = $2 WHERE plant_id = $1", ids, nullptr, error);
}

// Under the schema's advisory lock, and only when the schema is still
// incomplete once the lock is held (another uploader may have completed it
// meanwhile). The uploaded tables are altered before `plant`, in the order
// in which a batch locks them (its table, then plant), so that a migration
// and another plant's batch never wait on each other in a cycle.
bool Uploader::Impl::MigrateCentral(PgError* error) {
  const auto fail = [&](const char* what) {
    PgError ignored;
    if (pg && pg->Ok()) pg->Exec("ROLLBACK", &ignored);
    error->message = std::string(what) + error->message;
    return false;
  };
  if (!pg->Exec("BEGIN; SELECT pg_advisory_xact_lock(" + std::string(kSchemaLockKey) + ")",
                error)) {
    return fail("creating the central schema: ");
  }
  bool complete = false;
  if (!CentralSchemaComplete(&complete, error)) return fail("");
  if (complete) return pg->Exec("COMMIT", error) || fail("creating the central schema: ");
  // The tables there will be: this plant's, and those other plants brought.
  std::vector<std::vector<std::string>> rows;
  if (!pg->Query("SELECT table_name FROM information_schema.tables WHERE table_schema = "
                 "current_schema()",
                 {}, &rows, error)) {
    return fail("creating the central schema: ");
  }
  std::set<std::string> present;
  for (const auto& r : rows) present.insert(r[0]);
  // The forecast columns there will be: those other plants brought, and this
  // plant's.
  if (!pg->Query("SELECT column_name FROM information_schema.columns WHERE table_schema = "
                 "current_schema() AND table_name = 'forecast'",
                 {}, &rows, error)) {
    return fail("creating the central schema: ");
  }
  std::set<std::string> forecast_columns;
  for (const auto& r : rows) forecast_columns.insert(r[0]);
  for (const Table& t : tables) {
    if (t.spec->name != "forecast") continue;
    for (const Column& c : t.columns) forecast_columns.insert(c.name);
  }
  std::string sql =
      "CREATE TABLE IF NOT EXISTS pvtwin_schema(version integer PRIMARY KEY, "
      "applied_at timestamptz NOT NULL DEFAULT now());";
  for (const Table& t : tables) {
    sql += CentralTableDdl(t);
    present.insert(std::string(t.spec->name));
  }
  // Version 5: the day-ahead tables, of this plant's tables and of those
  // other plants brought.
  for (const UploadTable& spec : UploadTables()) {
    const std::string day_ahead(spec.day_ahead_table);
    if (day_ahead.empty() || !present.count(std::string(spec.name))) continue;
    sql += DayAheadTableDdl(spec, present.count(day_ahead) > 0);
    present.insert(day_ahead);
  }
  sql +=
      "CREATE TABLE IF NOT EXISTS plant(plant_id text PRIMARY KEY, "
      "first_upload_at bigint, last_upload_at bigint);"
      // Version 2: the store each plant_id belongs to.
      "ALTER TABLE plant ADD COLUMN IF NOT EXISTS store_id text;";
  sql += PlantLatestDdl(present.count("qc_event") > 0);
  // Version 3: the event view, as the store's.
  sql += EventDdl(present);
  // Version 4: the forecast_skill view, as the store's.
  sql += ForecastSkillDdl(present, forecast_columns);
  sql += "INSERT INTO pvtwin_schema(version) VALUES(" + std::to_string(kCentralSchemaVersion) +
         ") ON CONFLICT DO NOTHING; COMMIT;";
  return pg->Exec(sql, error) || fail("creating the central schema: ");
}

bool Uploader::Impl::ReadBatch(const Table& t, std::int64_t hwm, std::string* copy,
                               std::int64_t* rows_sent, std::int64_t* max_seq,
                               std::int64_t* settled, std::int64_t* keep_from, std::string* error) {
  const UploadTable& spec = *t.spec;
  const std::string name(spec.name);
  std::string on = "t." + std::string(spec.local_key[0]) + " = q.k1";
  if (spec.local_key.size() > 1) on += " AND t." + std::string(spec.local_key[1]) + " = q.k2";
  std::vector<std::int64_t> params = {hwm, settings.batch_rows};
  *keep_from = std::numeric_limits<std::int64_t>::min();
  if (!spec.newest_column.empty()) {
    const std::string newest(spec.newest_column);
    if (!local.Query(
            "SELECT max(" + newest + ") FROM " + name, {},
            [&](sqlite3_stmt* stmt) {
              if (sqlite3_column_type(stmt, 0) != SQLITE_NULL) {
                *keep_from = sqlite3_column_int64(stmt, 0) -
                             static_cast<std::int64_t>(settings.forecast_days) * 86400;
              }
            },
            error)) {
      return false;
    }
    std::string same_key;
    for (const std::string_view c : spec.central_key) {
      same_key += " AND g." + std::string(c) + " = t." + std::string(c);
    }
    // The newest row of its central key, or its newest day-ahead row.
    const std::string newest_of_key =
        "(SELECT max(g." + newest + ") FROM " + name + " g WHERE " + same_key.substr(5);
    on += " AND (t." + newest + " = " + newest_of_key + ")";
    if (!spec.day_ahead_table.empty()) {
      on += " OR t." + newest + " = " + newest_of_key + " AND g." + newest +
            " <= " + SqliteDayStart("t." + std::string(spec.keep_column)) + ")";
    }
    on += ") AND t." + std::string(spec.keep_column) + " >= ?";
    params.push_back(*keep_from);
  }
  std::string columns;
  for (const Column& c : t.columns) columns += ", t." + QuoteIdent(c.name);
  const std::string sql = "SELECT q.seq, t." + std::string(spec.local_key[0]) + " IS NOT NULL" +
                          columns +
                          " FROM (SELECT seq, k1, k2 FROM upload_queue WHERE table_name = ? AND "
                          "seq > ? ORDER BY seq LIMIT ?) q LEFT JOIN " +
                          name + " t ON " + on + " ORDER BY q.seq";
  std::string plant;
  AppendCopyText(settings.plant_id, &plant);
  *rows_sent = *settled = 0;
  *max_seq = hwm;
  copy->clear();
  // The keep_from parameter is bound after table name, hwm and batch size.
  return local.Query(
      sql, params,
      [&](sqlite3_stmt* stmt) {
        *max_seq = sqlite3_column_int64(stmt, 0);
        ++*settled;
        if (sqlite3_column_int(stmt, 1) == 0) return;  // deleted or superseded locally
        ++*rows_sent;
        *copy += plant;
        for (std::size_t c = 0; c < t.columns.size(); ++c) {
          copy->push_back('\t');
          AppendCell(stmt, static_cast<int>(c) + 2, t.columns[c].type, copy);
        }
        copy->push_back('\n');
      },
      error, name);
}

// The staged rows that are day-ahead rows (newest_column at or before
// 00:00 UTC of keep_column's day), the newest per central key, into
// day_ahead_table; a row there is replaced only by one at least as new.
std::string Uploader::Impl::DayAheadUpsert(const Table& t, const std::string& cols,
                                           const std::string& updates) {
  const UploadTable& spec = *t.spec;
  const std::string table = QuoteIdent(std::string(spec.day_ahead_table));
  const std::string newest = QuoteIdent(std::string(spec.newest_column));
  const std::string central_key = Join(spec.central_key);
  return "INSERT INTO " + table + "(" + cols + ") SELECT DISTINCT ON (" + central_key + ") " +
         cols + " FROM pvtwin_stage WHERE " + newest +
         " <= " + PgDayStart(QuoteIdent(std::string(spec.keep_column))) + " ORDER BY " +
         central_key + ", " + newest + " DESC ON CONFLICT (plant_id, " + central_key +
         ") DO UPDATE SET " + updates + " WHERE " + table + "." + newest + " <= EXCLUDED." + newest;
}

bool Uploader::Impl::SendBatch(const Table& t, const std::string& copy, std::int64_t keep_from,
                               PgError* error) {
  const UploadTable& spec = *t.spec;
  const std::string name = QuoteIdent(std::string(spec.name));
  std::string cols = "plant_id", updates;
  for (const Column& c : t.columns) {
    cols += ", " + QuoteIdent(c.name);
    bool key = false;
    for (const std::string_view k : spec.central_key) key = key || k == c.name;
    if (!key) {
      updates +=
          (updates.empty() ? "" : ", ") + QuoteIdent(c.name) + " = EXCLUDED." + QuoteIdent(c.name);
    }
  }
  const std::string central_key = Join(spec.central_key);
  std::string insert = "INSERT INTO " + name + "(" + cols + ") SELECT ";
  std::string order;
  if (!spec.newest_column.empty()) {
    insert += "DISTINCT ON (" + central_key + ") ";
    order = " ORDER BY " + central_key + ", " + std::string(spec.newest_column) + " DESC";
  }
  insert += cols + " FROM pvtwin_stage" + order + " ON CONFLICT (plant_id, " + central_key +
            ") DO UPDATE SET " + updates;
  if (!spec.newest_column.empty()) {
    const std::string newest = QuoteIdent(std::string(spec.newest_column));
    insert += " WHERE " + name + "." + newest + " <= EXCLUDED." + newest;
  }
  const std::vector<std::string> plant = {settings.plant_id};
  bool ok =
      pg->Exec("BEGIN; CREATE TEMP TABLE pvtwin_stage (LIKE " + name + ") ON COMMIT DROP", error) &&
      pg->CopyIn("COPY pvtwin_stage(" + cols + ") FROM STDIN", copy, error) &&
      pg->Exec(insert, error) &&
      (spec.day_ahead_table.empty() || pg->Exec(DayAheadUpsert(t, cols, updates), error)) &&
      pg->Query(
          "UPDATE plant SET last_upload_at = extract(epoch FROM now())::bigint "
          "WHERE plant_id = $1",
          plant, nullptr, error);
  if (ok && !spec.keep_column.empty()) {
    // The day-ahead table is pruned by the same rule.
    for (const std::string_view table : {spec.name, spec.day_ahead_table}) {
      if (table.empty()) continue;
      ok = ok &&
           pg->Query("DELETE FROM " + QuoteIdent(std::string(table)) + " WHERE plant_id = $1 AND " +
                         QuoteIdent(std::string(spec.keep_column)) + " < $2",
                     {settings.plant_id, std::to_string(keep_from)}, nullptr, error);
    }
  }
  ok = ok && pg->Exec("COMMIT", error);
  if (!ok) {
    PgError ignored;
    if (pg->Ok()) pg->Exec("ROLLBACK", &ignored);
    error->message = "upload of " + std::string(spec.name) + ": " + error->message;
  }
  return ok;
}

bool Uploader::Impl::UploadBatch(const Table& t, std::int64_t* settled, bool* full,
                                 PgError* error) {
  const std::string name(t.spec->name);
  std::string local_error;
  std::int64_t hwm = 0;
  std::string copy;
  std::int64_t rows_sent = 0, max_seq = 0, keep_from = 0;
  // One read transaction: the queue entries and the rows they name are one
  // snapshot.
  bool ok =
      local.Exec("BEGIN", &local_error) &&
      local.Query(
          "SELECT hwm FROM upload_state WHERE table_name = ?", {},
          [&](sqlite3_stmt* stmt) { hwm = sqlite3_column_int64(stmt, 0); }, &local_error, name) &&
      ReadBatch(t, hwm, &copy, &rows_sent, &max_seq, settled, &keep_from, &local_error);
  local.Rollback();  // ends the read transaction
  if (!ok) {
    *error = {PgFault::kLocal, local_error, ""};
    return false;
  }
  *full = *settled >= settings.batch_rows;
  if (*settled == 0) return true;
  if (rows_sent > 0) {
    if (!SendBatch(t, copy, keep_from, error)) return false;
    if (settings.after_central_commit) settings.after_central_commit();
  }
  // After the central COMMIT only: raise the mark, forget the entries.
  const std::string update = "UPDATE upload_state SET hwm = max(hwm, " + std::to_string(max_seq) +
                             "), rows_uploaded = rows_uploaded + " + std::to_string(rows_sent) +
                             ", last_upload_at = " + std::to_string(NowS()) +
                             " WHERE table_name = '" + name + "'";
  const std::string forget = "DELETE FROM upload_queue WHERE table_name = '" + name +
                             "' AND seq <= " + std::to_string(max_seq);
  if (!local.Exec("BEGIN IMMEDIATE", &local_error) || !local.Exec(update, &local_error) ||
      !local.Exec(forget, &local_error) || !local.Exec("COMMIT", &local_error)) {
    local.Rollback();
    *error = {PgFault::kLocal, "recording the high-water mark: " + local_error, ""};
    return false;
  }
  return true;
}

Uploader::Uploader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Uploader::~Uploader() = default;

std::unique_ptr<Uploader> Uploader::Open(const UploadSettings& settings, std::string* error) {
  auto impl = std::make_unique<Impl>();
  impl->settings = settings;
  if (!impl->local.Open(settings.store_path, error) || !impl->PrepareLocal(error)) return nullptr;
  return std::unique_ptr<Uploader>(new Uploader(std::move(impl)));
}

bool Uploader::Connect(PgError* error) {
  Impl& u = *impl_;
  if (u.pg && u.pg->Ok()) return true;
  u.pg.reset();
  std::string password, why;
  if (!ReadUploadPassword(u.settings.password_file, &password, &why)) {
    *error = {PgFault::kAuth, why, ""};
    return false;
  }
  PgWait wait;
  wait.stop = u.settings.stop;
  u.pg = PgConnection::Connect(u.settings.url, password, kAppName, wait, error);
  if (!u.pg) return false;
  u.server = u.pg->Describe();
  bool complete = false;
  bool ok = u.pg->Exec("SET statement_timeout = '" + std::to_string(kPgStatementTimeoutS) + "s'",
                       error) &&
            u.CentralSchemaComplete(&complete, error) && (complete || u.MigrateCentral(error));
  // One uploader per plant_id at a time (session lock, ends with the
  // connection).
  std::vector<std::vector<std::string>> rows;
  ok = ok && u.pg->Query("SELECT pg_try_advisory_lock(hashtext('pvtwin upload ' || $1))",
                         {u.settings.plant_id}, &rows, error);
  if (ok && (rows.empty() || rows[0][0] != "t")) {
    *error = {PgFault::kRefused,
              "plant_id " + u.settings.plant_id +
                  " is being uploaded by another connection (a second pvtwin upload, or two "
                  "plants configured with the same plant_id)",
              ""};
    ok = false;
  }
  ok = ok && u.BindStore(error);
  if (!ok) u.pg.reset();
  return ok;
}

bool Uploader::connected() const { return impl_->pg && impl_->pg->Ok(); }
void Uploader::Disconnect() { impl_->pg.reset(); }
std::string Uploader::server() const { return impl_->server; }

bool Uploader::Pending(std::vector<TablePending>* out, std::string* error) {
  out->clear();
  return impl_->local.Query(
      "SELECT table_name, rows_pending FROM upload_status ORDER BY table_name", {},
      [&](sqlite3_stmt* stmt) {
        out->push_back({ColumnText(stmt, 0), sqlite3_column_int64(stmt, 1)});
      },
      error);
}

bool Uploader::UploadBatches(std::int64_t* rows, bool* more, PgError* error) {
  Impl& u = *impl_;
  *rows = 0;
  *more = false;
  if (!Connect(error)) return false;
  for (const Impl::Table& t : u.tables) {
    std::int64_t settled = 0;
    bool full = false;
    if (!u.UploadBatch(t, &settled, &full, error)) {
      if (error->fault != PgFault::kLocal) u.pg.reset();
      return false;
    }
    *rows += settled;
    *more = *more || full;
  }
  return true;
}

void Uploader::RecordState(UploadState state, const std::string& last_error, bool success) {
  Impl& u = *impl_;
  const std::string now = std::to_string(NowS());
  // ?1 state, ?2 server, ?3 last error ('' keeps the previous one).
  std::string sql =
      "INSERT INTO upload_connection(id, state, since, server, last_error, last_error_at) "
      "VALUES(1, ?1, " +
      now + ", ?2, NULLIF(?3, ''), CASE WHEN ?3 = '' THEN NULL ELSE " + now +
      " END) ON CONFLICT(id) DO UPDATE SET since = CASE WHEN state = ?1 THEN since ELSE " + now +
      " END, state = ?1, server = ?2, last_error = CASE WHEN ?3 = '' THEN last_error ELSE ?3 END, "
      "last_error_at = CASE WHEN ?3 = '' THEN last_error_at ELSE " +
      now + " END";
  if (success) sql += ", last_success = " + now;
  std::string ignored;
  // Best effort: the log carries the same news.
  u.local.ExecBound(sql, {std::string(UploadStateName(state)), u.server, last_error}, &ignored);
}

}  // namespace pvtwin
