// Migrating an existing store: a backup copy beside it first (SQLite's online
// backup, never overwriting an earlier one), one log line naming both
// versions and the copy, and nothing of the kind for a new or a current
// store. Real store files; the copy is opened as a database of its own.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/store/store.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/sqlite_db.h"
#include "tests/support/store_schema_v10.h"
#include "tests/support/store_schema_v11.h"

namespace pvtwin {
namespace {

using testing::RawDb;

using testing::kJune1Noon2024UtcS;

class StoreMigrationTest : public testing::TempDirTest {
 protected:
  std::string DbPath() const { return (dir_ / "pvtwin.db").string(); }

  // Opens the store, collecting what it logs.
  std::unique_ptr<Store> OpenLogged(std::vector<std::string>* lines) {
    StoreOptions options;
    options.log = [lines](int priority, const std::string& line) {
      EXPECT_EQ(priority, kNotice);
      lines->push_back(line);
    };
    std::string error;
    std::unique_ptr<Store> store = Store::Open(DbPath(), options, &error);
    EXPECT_NE(store, nullptr) << error;
    return store;
  }

  // A store with three samples, taken back to what version 7 wrote: version
  // 9's tables and views and version 8's columns dropped, and its views as
  // version 7 had them (their columns do not matter to the migration, which
  // drops and creates them).
  void MakeVersion7Store() {
    {
      std::vector<std::string> lines;
      auto store = OpenLogged(&lines);
      ASSERT_NE(store, nullptr);
      std::vector<Sample> samples(3);
      for (int i = 0; i < 3; ++i) {
        samples[i].ts_s = kJune1Noon2024UtcS + 5 * i;
        samples[i].Set(Channel::kPElW, 100.0 + i);
      }
      std::string error;
      ASSERT_TRUE(store->InsertSamples(samples, &error)) << error;
      EXPECT_TRUE(lines.empty()) << "a new store is created, not migrated: " << lines[0];
      EXPECT_EQ(store->upgrade().from_version, 0);
    }
    RawDb db(DbPath());
    // Each later version's objects go first (a new version adds its own
    // here), then version 8's.
    static_assert(kStoreSchemaVersion == 12, "take the new version's objects back here too");
    std::vector<std::string> downgrade = testing::DropSchemaV12();
    for (const std::string& sql : testing::DropSchemaV11()) downgrade.push_back(sql);
    downgrade.insert(downgrade.end(),
                     {"DROP VIEW performance_daily_local", "DROP VIEW forecast_skill_local",
                      "DROP TABLE local_day_zone", "DROP TABLE local_day",
                      "DROP VIEW forecast_latest", "DROP VIEW forecast_skill",
                      "ALTER TABLE forecast DROP COLUMN basis",  // version 10
                      "ALTER TABLE forecast DROP COLUMN p_el_w_p50",
                      "ALTER TABLE forecast DROP COLUMN q_th_w_p50",
                      "CREATE VIEW forecast_latest(ts) AS SELECT ts FROM forecast",
                      "CREATE VIEW forecast_skill(day) AS SELECT ts FROM measurement_1min"});
    downgrade.push_back("PRAGMA user_version = 7");
    for (const std::string& sql : downgrade) ASSERT_EQ(db.Exec(sql), SQLITE_OK) << sql;
  }
};

TEST_F(StoreMigrationTest, AnOldStoreIsCopiedBesideItselfBeforeItIsMigrated) {
  ASSERT_NO_FATAL_FAILURE(MakeVersion7Store());
  const std::string backup = DbPath() + ".schema-v7.bak";
  ASSERT_FALSE(std::filesystem::exists(backup));
  std::vector<std::string> lines;
  {
    auto store = OpenLogged(&lines);
    ASSERT_NE(store, nullptr);
    EXPECT_EQ(store->upgrade().from_version, 7);
    EXPECT_EQ(store->upgrade().to_version, kStoreSchemaVersion);
    EXPECT_EQ(store->upgrade().backup_path, backup);
  }
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], DbPath() + ": migrating store schema 7 → " +
                          std::to_string(kStoreSchemaVersion) + " (backup: " + backup + ")");
  {
    RawDb db(DbPath());
    EXPECT_EQ(db.Number("PRAGMA user_version"), static_cast<double>(kStoreSchemaVersion));
  }
  // The copy is the store as it was: version 7, its rows, no version 8 column.
  ASSERT_TRUE(std::filesystem::exists(backup));
  RawDb copy(backup);
  EXPECT_EQ(copy.Number("PRAGMA user_version"), 7.0);
  EXPECT_EQ(copy.Number("SELECT COUNT(*) FROM sample_5s"), 3.0);
  EXPECT_EQ(copy.Number("SELECT SUM(p_el_w) FROM sample_5s"), 303.0);
  EXPECT_EQ(copy.Number("SELECT COUNT(*) FROM pragma_table_info('forecast') "
                        "WHERE name = 'p_el_w_p50'"),
            0.0);
  EXPECT_EQ(copy.Text("PRAGMA integrity_check"), "ok");

  // Opened again, the store is current: no line, no second copy.
  lines.clear();
  auto again = OpenLogged(&lines);
  ASSERT_NE(again, nullptr);
  EXPECT_TRUE(lines.empty());
  EXPECT_EQ(again->upgrade().from_version, 0);
  EXPECT_FALSE(std::filesystem::exists(DbPath() + ".schema-v7.1.bak"));
}

TEST_F(StoreMigrationTest, AnEarlierBackupIsNeverOverwritten) {
  ASSERT_NO_FATAL_FAILURE(MakeVersion7Store());
  const std::string earlier = DbPath() + ".schema-v7.bak";
  std::ofstream(earlier) << "an earlier backup the operator keeps";
  std::vector<std::string> lines;
  auto store = OpenLogged(&lines);
  ASSERT_NE(store, nullptr);
  EXPECT_EQ(testing::ReadFile(earlier), "an earlier backup the operator keeps");
  const std::string backup = DbPath() + ".schema-v7.1.bak";
  EXPECT_EQ(store->upgrade().backup_path, backup);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("(backup: " + backup + ")"), std::string::npos) << lines[0];
  RawDb copy(backup);
  EXPECT_EQ(copy.Number("PRAGMA user_version"), 7.0);
}

// No backup, no migration: when the copy cannot be written the store stays
// at its version, untouched, and the error says why.
TEST_F(StoreMigrationTest, WithoutABackupTheStoreIsNotMigrated) {
  ASSERT_NO_FATAL_FAILURE(MakeVersion7Store());
  // The copy's name leads into a directory that does not exist.
  std::filesystem::create_symlink(dir_ / "missing" / "copy.db", DbPath() + ".schema-v7.bak");
  StoreOptions options;
  std::vector<std::string> lines;
  options.log = [&lines](int, const std::string& line) { lines.push_back(line); };
  std::string error;
  EXPECT_EQ(Store::Open(DbPath(), options, &error), nullptr);
  EXPECT_NE(error.find("not migrating store schema 7 → " + std::to_string(kStoreSchemaVersion) +
                       " without a backup"),
            std::string::npos)
      << error;
  EXPECT_TRUE(lines.empty());
  RawDb db(DbPath());
  EXPECT_EQ(db.Number("PRAGMA user_version"), 7.0);
}

}  // namespace
}  // namespace pvtwin
