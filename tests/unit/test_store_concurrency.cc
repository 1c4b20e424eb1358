// The store under concurrent access and crashes, with real processes and
// connections: a reader holding a read transaction (another connection and
// the sqlite3 shell) does not stop ingestion; a competing writer makes a
// write fail with a value, not a crash; SIGKILL in the middle of a long
// insert loop loses no committed batch and corrupts nothing.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "io/store/store.h"
#include "tests/support/fixtures.h"
#include "tests/support/sqlite_db.h"

namespace pvtwin {
namespace {

using testing::RawDb;

using testing::kJune1Noon2024UtcS;
constexpr int kWaitMs = 20000;            // bound of every wait on a child process

std::vector<Sample> Batch(int index) {
  std::vector<Sample> batch(12);
  for (int i = 0; i < 12; ++i) {
    Sample& s = batch[static_cast<std::size_t>(i)];
    s.ts_s = kJune1Noon2024UtcS + 60 * index + 5 * i;
    s.Set(Channel::kPElW, 100.0 + index);
    s.Set(Channel::kTAmbC, 20.0);
  }
  return batch;
}

class StoreConcurrency : public testing::TempDirTest {
 protected:
  std::string DbPath() const { return (dir_ / "pvtwin.db").string(); }
};

TEST_F(StoreConcurrency, AnOpenReadTransactionDoesNotBlockIngestion) {
  std::string error;
  StoreOptions options;
  options.busy_timeout_ms = 100;  // a blocked writer would fail fast, not wait
  options.busy_retries = 0;
  auto store = Store::Open(DbPath(), options, &error);
  ASSERT_NE(store, nullptr) << error;
  ASSERT_TRUE(store->InsertSamples(Batch(0), &error)) << error;

  RawDb reader(DbPath());
  ASSERT_EQ(reader.Exec("BEGIN"), SQLITE_OK);
  EXPECT_EQ(reader.Number("SELECT COUNT(*) FROM sample_5s"), 12.0);  // snapshot taken
  for (int k = 1; k <= 5; ++k) {
    ASSERT_TRUE(store->InsertSamples(Batch(k), &error)) << error;
  }
  int written = 0;
  ASSERT_TRUE(store->AggregateMinutes(kJune1Noon2024UtcS + 6 * 60, &written, &error)) << error;
  EXPECT_EQ(written, 6);
  ASSERT_TRUE(store->Checkpoint(nullptr, &error)) << error;          // best effort with a reader
  EXPECT_EQ(reader.Number("SELECT COUNT(*) FROM sample_5s"), 12.0);  // still its snapshot
  ASSERT_EQ(reader.Exec("COMMIT"), SQLITE_OK);
  EXPECT_EQ(reader.Number("SELECT COUNT(*) FROM sample_5s"), 72.0);
  EXPECT_EQ(reader.Number("SELECT COUNT(*) FROM measurement_1min"), 6.0);
}

// The sqlite3 shell as a child process with pipes on stdin and stdout.
class SqliteShell {
 public:
  explicit SqliteShell(const std::string& db_path) {
    int in_pipe[2], out_pipe[2];
    if (pipe(in_pipe) != 0 || pipe(out_pipe) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      dup2(in_pipe[0], STDIN_FILENO);
      dup2(out_pipe[1], STDOUT_FILENO);
      close(in_pipe[1]);
      close(out_pipe[0]);
      execlp("sqlite3", "sqlite3", "-batch", db_path.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(in_pipe[0]);
    close(out_pipe[1]);
    to_shell_ = in_pipe[1];
    from_shell_ = out_pipe[0];
  }
  ~SqliteShell() {
    if (to_shell_ >= 0) close(to_shell_);
    if (from_shell_ >= 0) close(from_shell_);
    if (pid_ > 0) {
      for (int i = 0; i < kWaitMs / 10; ++i) {
        if (waitpid(pid_, nullptr, WNOHANG) == pid_) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  bool started() const { return pid_ > 0; }
  void Send(const std::string& sql) {
    const std::string line = sql + "\n";
    ASSERT_EQ(write(to_shell_, line.data(), line.size()), static_cast<ssize_t>(line.size()));
  }
  // One line of output, "" after kWaitMs without one.
  std::string ReadLine() {
    std::string line;
    char c = 0;
    while (true) {
      pollfd pfd{from_shell_, POLLIN, 0};
      if (poll(&pfd, 1, kWaitMs) <= 0 || read(from_shell_, &c, 1) != 1) return "";
      if (c == '\n') return line;
      line += c;
    }
  }

 private:
  pid_t pid_ = -1;
  int to_shell_ = -1, from_shell_ = -1;
};

TEST_F(StoreConcurrency, TheSqliteShellHoldingAReadTransactionDoesNotBlockIngestion) {
  std::string error;
  StoreOptions options;
  options.busy_timeout_ms = 100;
  options.busy_retries = 0;
  auto store = Store::Open(DbPath(), options, &error);
  ASSERT_NE(store, nullptr) << error;
  ASSERT_TRUE(store->InsertSamples(Batch(0), &error)) << error;

  SqliteShell shell(DbPath());
  ASSERT_TRUE(shell.started());
  shell.Send("BEGIN; SELECT COUNT(*) FROM sample_5s;");
  ASSERT_EQ(shell.ReadLine(), "12");  // the shell now holds a read transaction
  for (int k = 1; k <= 3; ++k) ASSERT_TRUE(store->InsertSamples(Batch(k), &error)) << error;
  shell.Send("SELECT COUNT(*) FROM sample_5s;");
  EXPECT_EQ(shell.ReadLine(), "12");
  shell.Send("COMMIT; SELECT COUNT(*) FROM sample_5s;");
  EXPECT_EQ(shell.ReadLine(), "48");
  shell.Send(".quit");
}

TEST_F(StoreConcurrency, ACompetingWriterMakesAWriteFailWithAReasonThenItSucceeds) {
  std::string error;
  StoreOptions options;
  options.busy_timeout_ms = 50;
  options.busy_retries = 1;
  auto store = Store::Open(DbPath(), options, &error);
  ASSERT_NE(store, nullptr) << error;
  ASSERT_TRUE(store->InsertSamples(Batch(0), &error)) << error;

  RawDb writer(DbPath());  // e.g. a program filling weather_forecast
  ASSERT_EQ(writer.Exec("BEGIN IMMEDIATE"), SQLITE_OK);
  EXPECT_FALSE(store->InsertSamples(Batch(1), &error));
  EXPECT_NE(error.find("busy"), std::string::npos) << error;
  EXPECT_NE(error.find(DbPath()), std::string::npos) << error;
  std::vector<Sample> read;
  ASSERT_TRUE(store->ReadSamples(0, kJune1Noon2024UtcS + 3600, &read, &error))
      << error;  // still readable
  EXPECT_EQ(read.size(), 12u);
  ASSERT_EQ(writer.Exec("ROLLBACK"), SQLITE_OK);
  ASSERT_TRUE(store->InsertSamples(Batch(1), &error)) << error;  // the caller's retry
  ASSERT_TRUE(store->ReadSamples(0, kJune1Noon2024UtcS + 3600, &read, &error)) << error;
  EXPECT_EQ(read.size(), 24u);
}

TEST_F(StoreConcurrency, SigkillDuringALongInsertLoopLosesNoCommittedBatch) {
  {
    std::string error;
    ASSERT_NE(Store::Open(DbPath(), &error), nullptr) << error;  // schema before the fork
  }
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // The child inserts batches until it is killed and reports each commit.
    close(fds[0]);
    std::string error;
    auto store = Store::Open(DbPath(), &error);
    if (store == nullptr) _exit(2);
    for (int k = 0;; ++k) {
      if (!store->InsertSamples(Batch(k), &error)) _exit(3);
      if (write(fds[1], &k, sizeof k) != sizeof k) _exit(4);
    }
  }
  close(fds[1]);
  std::set<int> committed;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(kWaitMs);
  while (committed.size() < 300 && std::chrono::steady_clock::now() < deadline) {
    pollfd pfd{fds[0], POLLIN, 0};
    int k = 0;
    if (poll(&pfd, 1, kWaitMs) <= 0 || read(fds[0], &k, sizeof k) != sizeof k) break;
    committed.insert(k);
  }
  kill(child, SIGKILL);  // in the middle of the loop: the child never stops by itself
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "child exit " << status;
  int k = 0;
  while (read(fds[0], &k, sizeof k) == sizeof k) committed.insert(k);  // reported before death
  close(fds[0]);
  ASSERT_GE(committed.size(), 300u);

  RawDb db(DbPath());
  EXPECT_EQ(db.Rows("PRAGMA integrity_check"), (std::vector<std::vector<std::string>>{{"ok"}}));
  std::string error;
  auto store = Store::Open(DbPath(), &error);
  ASSERT_NE(store, nullptr) << error;
  std::vector<Sample> samples;
  ASSERT_TRUE(store->ReadSamples(0, kJune1Noon2024UtcS + 100000 * 60, &samples, &error)) << error;
  std::set<std::int64_t> stored;
  for (const Sample& s : samples) stored.insert(s.ts_s);
  for (const int batch : committed) {
    for (const Sample& s : Batch(batch)) ASSERT_TRUE(stored.count(s.ts_s)) << "batch " << batch;
  }
  // Whole batches only (one transaction each): at most one more than reported.
  EXPECT_EQ(samples.size() % 12, 0u);
  EXPECT_LE(samples.size() / 12, committed.size() + 1);
  int written = 0;
  ASSERT_TRUE(store->AggregateMinutes(kJune1Noon2024UtcS + 100000 * 60, &written, &error)) << error;
  EXPECT_EQ(static_cast<std::size_t>(written), samples.size() / 12);
}

}  // namespace
}  // namespace pvtwin
