// The PostgreSQL connection of the upload; see io/fleet/pg_client.h.
#include "io/fleet/pg_client.h"

#include <poll.h>

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
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
  using Clock = std::chrono::steady_clock;

  PGconn* conn = nullptr;
  PgWait wait;
  std::string description;  // "host:port/db", kept after the connection is dropped

  ~Impl() { Drop(); }

  void Drop() {
    if (conn != nullptr) Libpq().PQfinish(conn);
    conn = nullptr;
  }

  Clock::time_point Deadline(double seconds) const {
    return Clock::now() + std::chrono::milliseconds(static_cast<std::int64_t>(seconds * 1000.0));
  }

  // Waits until the socket is ready for one of `events` (POLLIN, POLLOUT).
  // False with *error when the stop flag is set, the deadline passes or
  // poll fails; then the connection is dropped.
  bool WaitSocket(short events, Clock::time_point deadline, const std::string& what,
                  PgError* error) {
    const int fd = conn != nullptr ? Libpq().PQsocket(conn) : -1;
    for (;;) {
      if (wait.stop != nullptr && wait.stop->load()) {
        *error = {PgFault::kInterrupted, what + ": interrupted by a stop request", ""};
        Drop();
        return false;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      if (fd < 0 || left.count() <= 0) {
        *error = {PgFault::kUnreachable,
                  what + (fd < 0 ? ": the connection is closed"
                                 : ": no answer from the server within " + Seconds() + " s"),
                  ""};
        Drop();
        return false;
      }
      pollfd p{fd, events, 0};
      const int ready = ::poll(&p, 1, static_cast<int>(std::min<std::int64_t>(left.count(), 200)));
      if (ready > 0) return true;
      if (ready < 0 && errno != EINTR) {
        *error = {PgFault::kUnreachable, what + ": poll: " + std::strerror(errno), ""};
        Drop();
        return false;
      }
    }
  }

  std::string Seconds() const {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.0f", wait.timeout_s);
    return buf;
  }

  // The failure of a libpq call on this connection.
  bool Failed(const std::string& what, PgError* error) {
    *error = {PgFault::kUnreachable, what + ": " + Trimmed(Libpq().PQerrorMessage(conn)), ""};
    return false;
  }

  // Sends what libpq has queued.
  bool Flush(Clock::time_point deadline, const std::string& what, PgError* error) {
    for (;;) {
      const int left = Libpq().PQflush(conn);
      if (left == 0) return true;
      if (left < 0) return Failed(what, error);
      // libpq's rule: wait for either; consume what the server sent, flush again.
      if (!WaitSocket(POLLIN | POLLOUT, deadline, what, error)) return false;
      if (Libpq().PQconsumeInput(conn) != 1) return Failed(what, error);
    }
  }

  // The next result of the command in flight (null when it has no more).
  bool NextResult(Clock::time_point deadline, const std::string& what, PGresult** result,
                  PgError* error) {
    while (Libpq().PQisBusy(conn) == 1) {
      if (!WaitSocket(POLLIN, deadline, what, error)) return false;
      if (Libpq().PQconsumeInput(conn) != 1) return Failed(what, error);
    }
    *result = Libpq().PQgetResult(conn);
    return true;
  }

  // Reads every result of the command in flight; rows of the last one go
  // to *rows when not null. False with the first error.
  bool Finish(Clock::time_point deadline, const std::string& what,
              std::vector<std::vector<std::string>>* rows, PgError* error) {
    bool ok = true;
    for (;;) {
      PGresult* result = nullptr;
      if (!NextResult(deadline, what, &result, error)) return false;
      if (result == nullptr) return ok;
      if (ok) ok = Check(result, what, error);
      if (ok && rows != nullptr && Libpq().PQresultStatus(result) == PGRES_TUPLES_OK) {
        rows->clear();
        for (int r = 0; r < Libpq().PQntuples(result); ++r) {
          std::vector<std::string>& row = rows->emplace_back();
          for (int c = 0; c < Libpq().PQnfields(result); ++c)
            row.emplace_back(Libpq().PQgetvalue(result, r, c));
        }
      }
      Libpq().PQclear(result);
    }
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

  bool Usable(const std::string& what, PgError* error) const {
    if (conn != nullptr) return true;
    *error = {PgFault::kUnreachable, what + ": the connection was dropped", ""};
    return false;
  }
};

namespace {

// connect_timeout of the conninfo, in seconds, or `otherwise`.
double ConnectTimeoutOf(const std::string& conninfo, double otherwise) {
  char* message = nullptr;
  PQconninfoOption* options = Libpq().PQconninfoParse(conninfo.c_str(), &message);
  if (message != nullptr) Libpq().PQfreemem(message);
  double seconds = otherwise;
  for (PQconninfoOption* o = options; o != nullptr && o->keyword != nullptr; ++o) {
    if (std::strcmp(o->keyword, "connect_timeout") == 0 && o->val != nullptr) {
      const double s = std::atof(o->val);
      if (s > 0) seconds = std::max(s, 2.0);  // libpq's own minimum
    }
  }
  if (options != nullptr) Libpq().PQconninfoFree(options);
  return seconds;
}

}  // namespace

PgConnection::PgConnection(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PgConnection::~PgConnection() = default;

std::unique_ptr<PgConnection> PgConnection::Connect(const std::string& conninfo,
                                                    const std::string& password,
                                                    const std::string& application_name,
                                                    const PgWait& wait, PgError* error) {
  assert(error != nullptr);
  // Later entries override earlier ones: defaults, then the config's
  // string (expanded), then the password. TCP keepalives and
  // tcp_user_timeout let the kernel notice a server that vanished without
  // closing the connection; the deadlines of PgWait bound every wait anyway.
  std::vector<const char*> keys = {"application_name", "keepalives_idle", "keepalives_interval",
                                   "keepalives_count", "tcp_user_timeout", "dbname"};
  std::vector<const char*> values = {application_name.c_str(), "30", "10", "3", "30000",
                                     conninfo.c_str()};
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
  impl->wait = wait;
  impl->conn = Libpq().PQconnectStartParams(keys.data(), values.data(), 1);
  if (impl->conn == nullptr) {
    *error = {PgFault::kLocal, "connect: libpq out of memory", ""};
    return nullptr;
  }
  // libpq's connect_timeout does not apply to PQconnectPoll: the deadline is ours.
  const auto deadline = impl->Deadline(ConnectTimeoutOf(conninfo, wait.connect_timeout_s));
  PostgresPollingStatusType polling = PGRES_POLLING_WRITING;
  while (Libpq().PQstatus(impl->conn) != CONNECTION_BAD && polling != PGRES_POLLING_OK &&
         polling != PGRES_POLLING_FAILED) {
    if (Libpq().PQsocket(impl->conn) < 0) break;
    const short events = polling == PGRES_POLLING_WRITING ? POLLOUT : POLLIN;
    if (!impl->WaitSocket(events, deadline, "connect", error)) {
      if (error->fault == PgFault::kUnreachable) error->message = "connect: timeout expired";
      return nullptr;
    }
    polling = Libpq().PQconnectPoll(impl->conn);
  }
  if (Libpq().PQstatus(impl->conn) != CONNECTION_OK) {
    const std::string message = Trimmed(Libpq().PQerrorMessage(impl->conn));
    *error = {ConnectFault(message), "connect: " + message, ""};
    return nullptr;
  }
  if (Libpq().PQsetnonblocking(impl->conn, 1) != 0) {
    *error = {PgFault::kLocal, "connect: " + Trimmed(Libpq().PQerrorMessage(impl->conn)), ""};
    return nullptr;
  }
  // The server's notices ("already exists, skipping") are no news here.
  Libpq().PQsetNoticeProcessor(
      impl->conn, [](void*, const char*) {}, nullptr);
  const char* host = Libpq().PQhost(impl->conn);
  const char* port = Libpq().PQport(impl->conn);
  const char* db = Libpq().PQdb(impl->conn);
  impl->description =
      std::string(host ? host : "") + ":" + (port ? port : "") + "/" + (db ? db : "");
  return std::unique_ptr<PgConnection>(new PgConnection(std::move(impl)));
}

bool PgConnection::Exec(const std::string& sql, PgError* error) {
  return Query(sql, {}, nullptr, error);
}

bool PgConnection::Query(const std::string& sql, const std::vector<std::string>& params,
                         std::vector<std::vector<std::string>>* rows, PgError* error) {
  Impl& c = *impl_;
  const std::string what = sql.substr(0, 60);
  if (!c.Usable(what, error)) return false;
  const auto deadline = c.Deadline(c.wait.timeout_s);
  int sent = 0;
  if (params.empty()) {
    sent = Libpq().PQsendQuery(c.conn, sql.c_str());  // may hold several statements
  } else {
    std::vector<const char*> values;
    for (const std::string& p : params) values.push_back(p.c_str());
    sent = Libpq().PQsendQueryParams(c.conn, sql.c_str(), static_cast<int>(values.size()),
                                     nullptr, values.data(), nullptr, nullptr, 0);
  }
  if (sent != 1) return c.Failed(what, error);
  return c.Flush(deadline, what, error) && c.Finish(deadline, what, rows, error);
}

bool PgConnection::CopyIn(const std::string& copy_sql, const std::string& data, PgError* error) {
  Impl& c = *impl_;
  if (!c.Usable("COPY", error)) return false;
  auto deadline = c.Deadline(c.wait.timeout_s);
  if (Libpq().PQsendQuery(c.conn, copy_sql.c_str()) != 1) return c.Failed("COPY", error);
  PGresult* start = nullptr;
  if (!c.Flush(deadline, "COPY", error) || !c.NextResult(deadline, "COPY", &start, error)) {
    return false;
  }
  const bool copying = start != nullptr && Libpq().PQresultStatus(start) == PGRES_COPY_IN;
  const bool started = c.Check(start, "COPY", error);
  Libpq().PQclear(start);
  if (!started || !copying) {
    // Drain what is left of the command (an error's trailing results).
    PgError ignored;
    c.Finish(deadline, "COPY", nullptr, &ignored);
    if (started) *error = {PgFault::kRefused, "COPY: the server did not start the copy", ""};
    return false;
  }
  // In chunks: each wait for the socket renews the deadline only while the
  // server keeps taking data.
  constexpr std::size_t kChunk = 1 << 16;
  for (std::size_t at = 0; at < data.size();) {
    const std::size_t n = std::min(kChunk, data.size() - at);
    const int queued = Libpq().PQputCopyData(c.conn, data.data() + at, static_cast<int>(n));
    if (queued < 0) return c.Failed("COPY", error);
    if (queued == 1) {
      at += n;
      deadline = c.Deadline(c.wait.timeout_s);
      continue;
    }
    if (!c.WaitSocket(POLLIN | POLLOUT, deadline, "COPY", error)) return false;
    if (Libpq().PQconsumeInput(c.conn) != 1 || Libpq().PQflush(c.conn) < 0) {
      return c.Failed("COPY", error);
    }
  }
  for (;;) {
    const int ended = Libpq().PQputCopyEnd(c.conn, nullptr);
    if (ended < 0) return c.Failed("COPY", error);
    if (ended == 1) break;
    if (!c.WaitSocket(POLLOUT, deadline, "COPY", error)) return false;
  }
  return c.Flush(deadline, "COPY", error) && c.Finish(deadline, "COPY", nullptr, error);
}

std::string PgConnection::Describe() const { return impl_->description; }

bool PgConnection::Ok() const {
  return impl_->conn != nullptr && Libpq().PQstatus(impl_->conn) == CONNECTION_OK;
}

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
