#include "tests/support/pg_scratch_server.h"

#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include "config/libpq_api.h"

namespace pvtwin {

namespace fs = std::filesystem;

namespace {

std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string AsOwner() {
  return geteuid() == 0 ? "setpriv --reuid=nobody --regid=nogroup --clear-groups -- " : "";
}

std::string RandomWord() {
  std::random_device rd;
  const std::string letters = "abcdefghijkmnopqrstuvwxyzABCDEFGHJKLMNPQRSTUVWXYZ23456789";
  std::string w;
  for (int i = 0; i < 24; ++i) w += letters[rd() % letters.size()];
  return w;
}

}  // namespace

std::string PgScratchServer::FindBinDir() {
  std::string best;
  int best_version = -1;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/usr/lib/postgresql", ec)) {
    const fs::path bin = e.path() / "bin";
    const int version = std::atoi(e.path().filename().c_str());
    if (fs::exists(bin / "initdb") && fs::exists(bin / "pg_ctl") && version > best_version) {
      best = bin.string();
      best_version = version;
    }
  }
  if (!best.empty()) return best;
  for (const char* dir : {"/usr/local/bin", "/usr/bin"}) {
    if (fs::exists(fs::path(dir) / "initdb") && fs::exists(fs::path(dir) / "pg_ctl")) return dir;
  }
  return "";
}

PgScratchServer::PgScratchServer() {
  std::string pattern = (fs::temp_directory_path() / "pvtwin_pg_XXXXXX").string();
  if (::mkdtemp(pattern.data()) != nullptr) dir_ = pattern;
}

PgScratchServer::~PgScratchServer() {
  Stop();
  std::error_code ec;
  if (!dir_.empty()) fs::remove_all(dir_, ec);
}

std::string PgScratchServer::Data() const { return (dir_ / "data").string(); }

bool PgScratchServer::Start(std::string* error) {
  bin_ = FindBinDir();
  if (bin_.empty() || dir_.empty()) {
    *error =
        bin_.empty() ? "no PostgreSQL binaries (initdb, pg_ctl) found" : "no temporary directory";
    return false;
  }
  password_ = RandomWord();
  port_ = 20000 + static_cast<int>(getpid() % 20000);
  std::ofstream(dir_ / "pwfile") << password_ << "\n";
  if (geteuid() == 0) {
    // postgres must own its directory, and reach it.
    ::chmod(dir_.c_str(), 0755);
    if (std::system(("chown -R nobody:nogroup '" + dir_.string() + "'").c_str()) != 0) {
      *error = "chown of " + dir_.string() + " to nobody failed";
      return false;
    }
  }
  const std::string initdb = AsOwner() + "'" + bin_ + "/initdb' -D '" + Data() +
                             "' -U postgres --auth=scram-sha-256 --pwfile='" +
                             (dir_ / "pwfile").string() + "' -N -E UTF8 --no-instructions >'" +
                             (dir_ / "initdb.log").string() + "' 2>&1";
  if (std::system(initdb.c_str()) != 0) {
    *error = "initdb failed: " + ReadText(dir_ / "initdb.log");
    return false;
  }
  return Resume(error);
}

bool PgScratchServer::Resume(std::string* error) {
  const std::string options = "-c listen_addresses='' -c unix_socket_directories='" +
                              dir_.string() + "' -c port=" + std::to_string(port_) +
                              " -c fsync=off -c synchronous_commit=off -c full_page_writes=off"
                              " -c shared_buffers=16MB -c max_connections=30";
  const std::string start = AsOwner() + "'" + bin_ + "/pg_ctl' -D '" + Data() + "' -l '" +
                            (dir_ / "server.log").string() + "' -w -t 60 -o \"" + options +
                            "\" start >/dev/null 2>&1";
  if (std::system(start.c_str()) != 0) {
    *error = "pg_ctl start failed: " + ReadText(dir_ / "server.log");
    return false;
  }
  running_ = true;
  return true;
}

void PgScratchServer::Stop() {
  if (!running_) return;
  const std::string stop =
      AsOwner() + "'" + bin_ + "/pg_ctl' -D '" + Data() + "' -m fast -w -t 60 stop >/dev/null 2>&1";
  [[maybe_unused]] const int rc = std::system(stop.c_str());
  running_ = false;
}

std::string PgScratchServer::Conninfo(const std::string& dbname, const std::string& user) const {
  return "host=" + dir_.string() + " port=" + std::to_string(port_) + " dbname=" + dbname +
         " user=" + user;
}

std::vector<std::vector<std::string>> PgScratchServer::Query(const std::string& sql,
                                                             const std::string& dbname) const {
  const std::string conninfo = Conninfo(dbname) + " password=" + password_;
  PGconn* conn = Libpq().PQconnectdb(conninfo.c_str());
  std::vector<std::vector<std::string>> rows;
  if (Libpq().PQstatus(conn) != CONNECTION_OK) {
    rows.push_back({"ERROR " + std::string(Libpq().PQerrorMessage(conn))});
    Libpq().PQfinish(conn);
    return rows;
  }
  PGresult* result = Libpq().PQexec(conn, sql.c_str());
  const ExecStatusType status = Libpq().PQresultStatus(result);
  if (status != PGRES_TUPLES_OK && status != PGRES_COMMAND_OK) {
    rows.push_back({"ERROR " + std::string(Libpq().PQresultErrorMessage(result))});
  } else {
    for (int r = 0; r < Libpq().PQntuples(result); ++r) {
      std::vector<std::string>& row = rows.emplace_back();
      for (int c = 0; c < Libpq().PQnfields(result); ++c) {
        row.push_back(Libpq().PQgetisnull(result, r, c) ? "NULL"
                                                        : Libpq().PQgetvalue(result, r, c));
      }
    }
  }
  Libpq().PQclear(result);
  Libpq().PQfinish(conn);
  return rows;
}

std::string PgScratchServer::Text(const std::string& sql, const std::string& dbname) const {
  const auto rows = Query(sql, dbname);
  return rows.empty() || rows[0].empty() ? "" : rows[0][0];
}

}  // namespace pvtwin
