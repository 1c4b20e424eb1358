// A throw-away PostgreSQL server for the upload's tests and benchmark:
// Debian's initdb and pg_ctl (from /usr/lib/postgresql/<version>/bin, which
// is not on PATH, or from PATH) start a cluster in a fresh temporary
// directory, listening only on a unix socket there (listen_addresses = '',
// no network), with password (SCRAM) authentication and a superuser
// password made up at run time. initdb and postgres refuse to run as root:
// under root they run as `nobody` (setpriv), which then owns the directory.
// Durability is off (fsync, synchronous_commit): a scratch server need not
// survive a power cut. The destructor stops the server and removes the
// directory.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace pvtwin {

class PgScratchServer {
 public:
  // The directory holding initdb and pg_ctl, or "" when PostgreSQL is not
  // installed.
  static std::string FindBinDir();

  PgScratchServer();
  ~PgScratchServer();
  PgScratchServer(const PgScratchServer&) = delete;
  PgScratchServer& operator=(const PgScratchServer&) = delete;

  // initdb, then start. False with *error (the log's text) on failure.
  bool Start(std::string* error);
  // pg_ctl start on the existing cluster (after Stop).
  bool Resume(std::string* error);
  // pg_ctl stop -m fast (connections are cut, as when a server goes away).
  void Stop();

  // libpq key=value string for database and user, without the password.
  std::string Conninfo(const std::string& dbname = "postgres",
                       const std::string& user = "postgres") const;
  const std::string& password() const { return password_; }
  const std::filesystem::path& dir() const { return dir_; }

  // Runs sql as the superuser: the rows as text (NULL as "NULL"), or one
  // row with one cell "ERROR <message>".
  std::vector<std::vector<std::string>> Query(const std::string& sql,
                                              const std::string& dbname = "postgres") const;
  // The first cell of the first row ("" when there is none).
  std::string Text(const std::string& sql, const std::string& dbname = "postgres") const;

 private:
  std::string Data() const;

  std::filesystem::path dir_;
  std::string bin_;
  std::string password_;
  int port_ = 0;
  bool running_ = false;
};

}  // namespace pvtwin
