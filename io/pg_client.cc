// The PostgreSQL connection of the upload; see io/pg_client.h.
#include "io/pg_client.h"

#include <cassert>
#include <cstring>
#include <stdexcept>

#include "config/libpq_api.h"

namespace pvtwin {

namespace {

std::string Trimmed(const char* text) {
  std::string s = text != nullptr ? text : "";
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  // libpq's multi-line messages read as one log line.
  for (char& c : s) {
    if (c == '\n') c = ' ';
  }
  return s;
}

// A failed login, told apart from an unreachable server by the server's
// answer (libpq gives no SQLSTATE for a failed connection).
PgFault ConnectFault(const std::string& message) {
  static const char* const kAuthSigns[] = {"password authentication failed", "no password supplied",
                                           "authentication failed", "no pg_hba.conf entry",
                                           "role \""};
  static const char* const kRefusedSigns[] = {"permission denied for database", "database \""};
  for (const char* sign : kAuthSigns) {
    if (message.find(sign) != std::string::npos) return PgFault::kAuth;
  }
  for (const char* sign : kRefusedSigns) {
    if (message.find(sign) != std::string::npos) return PgFault::kRefused;
  }
  return PgFault::kUnreachable;
}

}  // namespace

struct PgConnection::Impl {
  PGconn* conn = nullptr;
  ~Impl() {
    if (conn != nullptr) Libpq().PQfinish(conn);
  }

  // The error of a finished command; false unless it succeeded.
  bool Check(PGresult* result, const std::string& what, PgError* error) {
    const ExecStatusType status = result ? Libpq().PQresultStatus(result) : PGRES_FATAL_ERROR;
    const bool ok = status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK ||
                    status == PGRES_COPY_IN || status == PGRES_EMPTY_QUERY;
    if (!ok) {
      const char* state = result ? Libpq().PQresultErrorField(result, PG_DIAG_SQLSTATE) : nullptr;
      error->sqlstate = state != nullptr ? state : "";
      error->message =
          what + ": " +
          Trimmed(result ? Libpq().PQresultErrorMessage(result) : Libpq().PQerrorMessage(conn));
      error->fault =
          Libpq().PQstatus(conn) == CONNECTION_OK ? PgFault::kRefused : PgFault::kUnreachable;
      if (error->sqlstate.starts_with("08")) error->fault = PgFault::kUnreachable;
      if (error->sqlstate.starts_with("28")) error->fault = PgFault::kAuth;
    }
    return ok;
  }
};

PgConnection::PgConnection(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PgConnection::~PgConnection() = default;

std::unique_ptr<PgConnection> PgConnection::Connect(const std::string& conninfo,
                                                    const std::string& password,
                                                    const std::string& application_name,
                                                    PgError* error) {
  assert(error != nullptr);
  // Later entries override earlier ones: defaults, then the config's
  // string (expanded), then the password.
  // TCP keepalives notice a server that vanished without closing the
  // connection within about a minute (the upload thread would wait on it).
  std::vector<const char*> keys = {"connect_timeout",     "application_name", "keepalives_idle",
                                   "keepalives_interval", "keepalives_count", "dbname"};
  std::vector<const char*> values = {"10", application_name.c_str(), "30", "10",
                                     "3",  conninfo.c_str()};
  if (!password.empty()) {
    keys.push_back("password");
    values.push_back(password.c_str());
  }
  keys.push_back(nullptr);
  values.push_back(nullptr);
  try {
    Libpq();
  } catch (const std::runtime_error& e) {
    *error = {PgFault::kLocal, std::string("connect: ") + e.what(), ""};
    return nullptr;
  }
  auto impl = std::make_unique<Impl>();
  impl->conn = Libpq().PQconnectdbParams(keys.data(), values.data(), 1);
  if (impl->conn == nullptr || Libpq().PQstatus(impl->conn) != CONNECTION_OK) {
    const std::string message =
        impl->conn ? Trimmed(Libpq().PQerrorMessage(impl->conn)) : "libpq out of memory";
    *error = {ConnectFault(message), "connect: " + message, ""};
    return nullptr;
  }
  // The server's notices ("already exists, skipping") are no news here.
  Libpq().PQsetNoticeProcessor(
      impl->conn, [](void*, const char*) {}, nullptr);
  return std::unique_ptr<PgConnection>(new PgConnection(std::move(impl)));
}

bool PgConnection::Exec(const std::string& sql, PgError* error) {
  PGresult* result = Libpq().PQexec(impl_->conn, sql.c_str());
  const bool ok = impl_->Check(result, sql.substr(0, 60), error);
  Libpq().PQclear(result);
  return ok;
}

bool PgConnection::Query(const std::string& sql, const std::vector<std::string>& params,
                         std::vector<std::vector<std::string>>* rows, PgError* error) {
  std::vector<const char*> values;
  for (const std::string& p : params) values.push_back(p.c_str());
  PGresult* result = Libpq().PQexecParams(impl_->conn, sql.c_str(), static_cast<int>(values.size()),
                                          nullptr, values.data(), nullptr, nullptr, 0);
  const bool ok = impl_->Check(result, sql.substr(0, 60), error);
  if (ok && rows != nullptr) {
    rows->clear();
    for (int r = 0; r < Libpq().PQntuples(result); ++r) {
      std::vector<std::string>& row = rows->emplace_back();
      for (int c = 0; c < Libpq().PQnfields(result); ++c)
        row.emplace_back(Libpq().PQgetvalue(result, r, c));
    }
  }
  Libpq().PQclear(result);
  return ok;
}

bool PgConnection::CopyIn(const std::string& copy_sql, const std::string& data, PgError* error) {
  PGresult* start = Libpq().PQexec(impl_->conn, copy_sql.c_str());
  const bool started = impl_->Check(start, "COPY", error);
  Libpq().PQclear(start);
  if (!started) return false;
  if (Libpq().PQputCopyData(impl_->conn, data.data(), static_cast<int>(data.size())) != 1 ||
      Libpq().PQputCopyEnd(impl_->conn, nullptr) != 1) {
    *error = {PgFault::kUnreachable, "COPY: " + Trimmed(Libpq().PQerrorMessage(impl_->conn)), ""};
    return false;
  }
  bool ok = true;
  while (PGresult* result = Libpq().PQgetResult(impl_->conn)) {
    if (ok) ok = impl_->Check(result, "COPY", error);
    Libpq().PQclear(result);
  }
  return ok;
}

std::string PgConnection::Describe() const {
  const char* host = Libpq().PQhost(impl_->conn);
  const char* port = Libpq().PQport(impl_->conn);
  const char* db = Libpq().PQdb(impl_->conn);
  return std::string(host ? host : "") + ":" + (port ? port : "") + "/" + (db ? db : "");
}

bool PgConnection::Ok() const { return Libpq().PQstatus(impl_->conn) == CONNECTION_OK; }

void AppendCopyText(const std::string& s, std::string* out) {
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    switch (c) {
      case '\\':
        *out += "\\\\";
        continue;
      case '\t':
        *out += "\\t";
        continue;
      case '\n':
        *out += "\\n";
        continue;
      case '\r':
        *out += "\\r";
        continue;
      case 0:
        continue;
      default:
        break;
    }
    if (c < 0x80) {
      out->push_back(static_cast<char>(c));
      continue;
    }
    // A UTF-8 sequence: lead byte, then 1-3 continuation bytes.
    const std::size_t len = c >= 0xF0 && c <= 0xF4 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 0;
    bool valid = len > 0 && i + len <= n && !(c >= 0xF8);
    for (std::size_t k = 1; valid && k < len; ++k) {
      valid = (static_cast<unsigned char>(s[i + k]) & 0xC0) == 0x80;
    }
    if (!valid) {
      out->push_back('?');
      continue;
    }
    out->append(s, i, len);
    i += len - 1;
  }
}

std::string QuoteIdent(const std::string& s) {
  std::string q = "\"";
  for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace pvtwin
