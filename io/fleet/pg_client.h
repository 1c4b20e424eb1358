// A PostgreSQL connection for the upload (io/fleet/upload.h), behind one file:
// libpq's handles are freed by their owners, every failure is a PgError
// that says what was done, the server's message and what kind of fault it
// is (the upload's states: down, auth failure, refused).
//
// The password is never part of the connection string that the config
// holds (config/plant_config.h UploadConfig): it comes in separately and is
// handed to libpq as its own parameter.
//
// Every wait on the network is bounded and interruptible: the connection
// runs in libpq's non-blocking mode and each call polls its socket in short
// ticks, checking the caller's stop flag (SIGTERM) and a deadline of
// PgWait::timeout_s without an answer. A server that vanished without
// closing the connection (a stopped backend, a cable pulled) therefore ends
// a call with kUnreachable after the deadline, and a stop request ends it at
// once with kInterrupted; in both cases the connection is dropped, since the
// server may be in the middle of the command.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace pvtwin {

enum class PgFault {
  kNone,
  kUnreachable,  // no server answers (stopped, network, socket missing)
  kAuth,         // the server refused the login (password, pg_hba.conf)
  kRefused,      // connected (or known to the server), but refused: schema, permission, data
  kLocal,        // the plant's own SQLite store failed (the upload's side, not the server)
  kInterrupted,  // the caller's stop flag was set while waiting (no fault of the server)
};

// How long a call waits for the server, and what ends the wait early.
struct PgWait {
  // Set by a signal handler or the daemon's stop; polled every tick.
  const std::atomic<bool>* stop = nullptr;
  // Seconds a command may go without an answer before the server counts as
  // gone: above the session's statement_timeout (kPgStatementTimeoutS), so
  // that a slow statement ends with the server's error rather than ours.
  double timeout_s = 130.0;
  // Seconds to establish a connection (connect_timeout of the conninfo
  // overrides it).
  double connect_timeout_s = 10.0;
};

// The statement_timeout the upload sets on its session, in seconds.
inline constexpr int kPgStatementTimeoutS = 120;

struct PgError {
  PgFault fault = PgFault::kNone;
  std::string message;  // "<what>: <server or libpq message>"
  std::string sqlstate;
};

class PgConnection {
 public:
  // Connects with libpq to `conninfo` (URI or key=value), adding `password`
  // when not empty; every later call waits as `wait` says.
  static std::unique_ptr<PgConnection> Connect(const std::string& conninfo,
                                               const std::string& password,
                                               const std::string& application_name,
                                               const PgWait& wait, PgError* error);
  ~PgConnection();
  PgConnection(const PgConnection&) = delete;
  PgConnection& operator=(const PgConnection&) = delete;

  // Runs one or more statements without parameters.
  bool Exec(const std::string& sql, PgError* error);
  // Runs one statement with text parameters; the rows, each cell as text
  // (NULL as ""), go to *rows when not null.
  bool Query(const std::string& sql, const std::vector<std::string>& params,
             std::vector<std::vector<std::string>>* rows, PgError* error);
  // COPY ... FROM STDIN with `data` in COPY's text format.
  bool CopyIn(const std::string& copy_sql, const std::string& data, PgError* error);
  // "host:port/db" or "socket dir/db", for log lines.
  std::string Describe() const;
  // False once the server has gone away or a call was abandoned (the
  // caller reconnects).
  bool Ok() const;

 private:
  struct Impl;
  explicit PgConnection(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// s in COPY text format: backslash, tab, newline and carriage return
// escaped; NUL bytes dropped and invalid UTF-8 bytes replaced by '?'.
void AppendCopyText(const std::string& s, std::string* out);

// s as a quoted SQL identifier ("name").
std::string QuoteIdent(const std::string& s);

}  // namespace pvtwin
