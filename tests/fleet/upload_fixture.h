// The fixture of the upload tests (tests/fleet/test_*.cc): a scratch
// PostgreSQL (tests/support/pg_scratch_server.h) with a database `fleet`,
// plant configs and stores in a scratch directory, the real `pvtwin upload`
// and `pvtwin run`, and the comparison of central rows with the store's.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/common/clock.h"
#include "io/fleet/pg_client.h"
#include "io/platform/child_process.h"
#include "tests/support/files.h"
#include "tests/support/pg_scratch_server.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/wait.h"

namespace pvtwin {
namespace upload_test {

namespace fs = std::filesystem;
using testing::RawDb;
using testing::ReadFile;
using testing::RunCommand;
using testing::RunPvtwin;
using testing::ScratchDir;
using testing::WaitFor;

inline const fs::path kSimPlant =
    fs::path(PVTWIN_SOURCE_DIR) / "config" / "examples" / "sim-plant.toml";
// 2024-06-01 08:00 UTC: a June morning at the example plant.
inline constexpr std::int64_t kMorning = 1717228800;

// A local cell as SQLite holds it.
struct Cell {
  int type = SQLITE_NULL;
  std::int64_t i = 0;
  double x = 0.0;
  std::string text;
};

// Rows of `sql` from the store, typed.
inline std::vector<std::vector<Cell>> LocalRows(const fs::path& db_path, const std::string& sql) {
  sqlite3* db = nullptr;
  sqlite3_open_v2(db_path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
  sqlite3_busy_timeout(db, 5000);
  sqlite3_stmt* stmt = nullptr;
  std::vector<std::vector<Cell>> rows;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK)
      << sql << ": " << sqlite3_errmsg(db);
  while (stmt != nullptr && sqlite3_step(stmt) == SQLITE_ROW) {
    std::vector<Cell>& row = rows.emplace_back();
    for (int c = 0; c < sqlite3_column_count(stmt); ++c) {
      Cell cell;
      cell.type = sqlite3_column_type(stmt, c);
      cell.i = sqlite3_column_int64(stmt, c);
      cell.x = sqlite3_column_double(stmt, c);
      const unsigned char* t = sqlite3_column_text(stmt, c);
      cell.text = t ? reinterpret_cast<const char*>(t) : "";
      row.push_back(cell);
    }
  }
  sqlite3_finalize(stmt);
  sqlite3_close_v2(db);
  return rows;
}

// The columns of a local table, comma separated.
inline std::string LocalColumns(const fs::path& db_path, const std::string& table) {
  std::string cols;
  for (const auto& row :
       LocalRows(db_path, "SELECT name FROM pragma_table_info('" + table + "') ORDER BY cid")) {
    cols += (cols.empty() ? "" : ", ") + row[0].text;
  }
  return cols;
}

// A central cell equals a local one: NULL for NULL, the same integer, the
// same double (PostgreSQL prints the shortest text that reads back exactly),
// the same text.
inline bool SameCell(const Cell& local, const std::string& central) {
  switch (local.type) {
    case SQLITE_NULL:
      return central == "NULL";
    case SQLITE_INTEGER:
      return central == std::to_string(local.i) ||
             std::strtod(central.c_str(), nullptr) == static_cast<double>(local.i);
    case SQLITE_FLOAT:
      return std::strtod(central.c_str(), nullptr) == local.x;
    default:
      return central == local.text;
  }
}

// Every row of the local query equals the central one of the same position
// (both ordered by key); returns the number of rows compared. The central
// rows are central_table's when given (of the local table's columns).
inline std::size_t ExpectSameRows(const PgScratchServer& pg, const fs::path& db,
                                  const std::string& plant_id, const std::string& table,
                                  const std::string& local_where, const std::string& order,
                                  const std::string& central_table = "") {
  const std::string cols = LocalColumns(db, table);
  const auto local =
      LocalRows(db, "SELECT " + cols + " FROM " + table + " " + local_where + " ORDER BY " + order);
  const auto central =
      pg.Query("SELECT " + cols + " FROM " + (central_table.empty() ? table : central_table) +
                   " WHERE plant_id = '" + plant_id + "' ORDER BY " + order,
               "fleet");
  EXPECT_EQ(local.size(), central.size()) << table << " of " << plant_id;
  if (local.size() != central.size()) return 0;
  std::size_t differing = 0;
  for (std::size_t r = 0; r < local.size(); ++r) {
    for (std::size_t c = 0; c < local[r].size(); ++c) {
      if (!SameCell(local[r][c], central[r][c]) && differing++ < 5) {
        ADD_FAILURE() << table << " of " << plant_id << " row " << r << " column " << c
                      << ": local " << local[r][c].text << ", central " << central[r][c];
      }
    }
  }
  EXPECT_EQ(differing, 0u) << table << " of " << plant_id;
  return local.size();
}

class Upload : public ::testing::Test {
 protected:
  void SetUp() override {
    if (PgScratchServer::FindBinDir().empty()) {
      GTEST_SKIP() << "PostgreSQL is not installed (no initdb/pg_ctl in /usr/lib/postgresql/*/bin "
                      "or on PATH): apt-get install postgresql";
    }
    std::string error;
    ASSERT_TRUE(pg_.Start(&error)) << error;
    ASSERT_EQ(pg_.Text("CREATE DATABASE fleet"), "");
    std::ofstream(dir_ / "pgpassword") << pg_.password() << "\n";
  }

  // A plant config: the example plant, no Modbus devices unless
  // modbus_text is given (then it is the whole config with devices), the
  // store in the scratch directory, [upload] to the test server.
  fs::path WritePlant(const std::string& name, const std::string& upload_extra,
                      const std::string& modbus_text = "") {
    std::string text = modbus_text;
    if (text.empty()) {
      std::istringstream in(ReadFile(kSimPlant));
      std::string line;
      while (std::getline(in, line) && !line.starts_with("[[modbus")) text += line + "\n";
      text += "[storage]\npath = \"" + (dir_ / (name + ".db")).string() +
              "\"\n[calibration]\ntimezone = \"UTC\"\n";
    }
    text += "\n[upload]\nurl = \"" + pg_.Conninfo("fleet") + "\"\npassword_file = \"" +
            (dir_ / "pgpassword").string() + "\"\nplant_id = \"" + name + "\"\ninterval_s = 1\n" +
            upload_extra;
    const fs::path config = dir_ / (name + ".toml");
    std::ofstream(config) << text;
    return config;
  }
  fs::path Db(const std::string& name) const { return dir_ / (name + ".db"); }

  // History of the simulated plant as 1-min rows (or samples) in the store:
  // whole days, or their first keep_rows rows.
  void Import(const std::string& name, std::int64_t start, int days, int step_s, int seed,
              int keep_rows = -1) {
    const std::string csv = name + "-" + std::to_string(seed) + ".csv";
    const auto exported = RunPvtwin(
        dir_.path(), "sim --config '" + kSimPlant.string() + "' --export " + csv + " --days " +
                         std::to_string(days) + " --step " + std::to_string(step_s) + " --start " +
                         std::to_string(start) + " --seed " + std::to_string(seed));
    ASSERT_EQ(exported.exit_code, 0) << exported.err;
    if (keep_rows >= 0) {
      std::istringstream in(ReadFile(dir_ / csv));
      std::ofstream out(dir_ / csv, std::ios::trunc);
      std::string line;
      for (int i = 0; i <= keep_rows && std::getline(in, line); ++i) out << line << "\n";
    }
    ImportCsv(name, csv);
  }
  void ImportCsv(const std::string& name, const std::string& csv) {
    const auto imported = RunPvtwin(dir_.path(), "import --config " + name + ".toml --csv " + csv);
    ASSERT_EQ(imported.exit_code, 0) << imported.err;
  }

  testing::ProcessResult UploadOnce(const std::string& name, const std::string& env = "") {
    return RunCommand(dir_.path(), env + " '" + std::string(PVTWIN_BINARY) +
                                       "' upload --once --config " + name + ".toml");
  }

  bool StartDaemon(ChildProcess* daemon, const std::string& name,
                   const std::vector<std::string>& extra = {}) {
    std::vector<std::string> argv = {PVTWIN_BINARY, "run", "--config",
                                     (dir_ / (name + ".toml")).string()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    std::string error;
    const bool ok = daemon->Start(argv, (dir_ / (name + ".log")).string(), &error);
    EXPECT_TRUE(ok) << error;
    return ok;
  }
  std::string Log(const std::string& name) const { return ReadFile(dir_ / (name + ".log")); }

  double Pending(const std::string& name) {
    RawDb db(Db(name));
    return db.Number("SELECT coalesce(sum(rows_pending), 0) FROM upload_status");
  }
  long long Central(const std::string& sql) {
    const std::string t = pg_.Text(sql, "fleet");
    return t.empty() || t.starts_with("ERROR") ? -1 : std::stoll(t);
  }

  // Holds an exclusive lock on a central table while it lives, so that an
  // upload into it waits at a known point.
  std::unique_ptr<PgConnection> LockTable(const std::string& table) {
    PgError error;
    auto conn =
        PgConnection::Connect(pg_.Conninfo("fleet"), pg_.password(), "test lock", {}, &error);
    EXPECT_NE(conn, nullptr) << error.message;
    if (conn) {
      EXPECT_TRUE(conn->Exec("BEGIN; LOCK TABLE " + table + " IN ACCESS EXCLUSIVE MODE", &error))
          << error.message;
    }
    return conn;
  }
  // The backend of pvtwin's upload once it waits for that lock, stopped
  // with SIGSTOP: a server that vanished without closing the connection.
  // The lock is released after, so nothing but the stopped backend holds
  // the upload up. 0 when none was found.
  int StallUploadBackend(std::unique_ptr<PgConnection>* lock) {
    std::string pid;
    const bool waiting = WaitFor(20, [&] {
      pid = pg_.Text(
          "SELECT pid FROM pg_stat_activity WHERE application_name = 'pvtwin upload' "
          "AND wait_event_type = 'Lock'");
      return !pid.empty() && !pid.starts_with("ERROR");
    });
    EXPECT_TRUE(waiting) << pid;
    if (!waiting) return 0;
    stalled_ = std::stoi(pid);
    ::kill(stalled_, SIGSTOP);
    lock->reset();
    return stalled_;
  }
  void TearDown() override {
    if (stalled_ > 0) ::kill(stalled_, SIGCONT);  // so that the server can stop
  }

  // measurement_1min, calibration and forecast (the newest issue per ts
  // within forecast_days of the newest issue) equal centrally and locally.
  void ExpectPlantEqual(const std::string& name, int forecast_days = 7) {
    const fs::path db = Db(name);
    EXPECT_GT(ExpectSameRows(pg_, db, name, "measurement_1min", "", "ts"), 0u);
    ExpectSameRows(pg_, db, name, "calibration", "", "id");
    ExpectSameRows(pg_, db, name, "forecast",
                   "f WHERE issued_at = (SELECT max(issued_at) FROM forecast g WHERE g.ts = f.ts)"
                   " AND ts >= (SELECT max(issued_at) FROM forecast) - " +
                       std::to_string(forecast_days * 86400),
                   "ts");
  }

  ScratchDir dir_{"upload"};
  PgScratchServer pg_;
  int stalled_ = 0;  // a backend stopped with SIGSTOP
};

}  // namespace upload_test
}  // namespace pvtwin
