// Child processes run without blocking the caller: the daemon's nightly
// calibration (`pvtwin calibrate` in its own process, so a fit that crashes
// or runs too long costs a record in `calibration`, never the polling loop),
// and the simulator that `pvtwin demo` and the end-to-end tests talk to over
// its stdin/stdout.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace pvtwin {

class ChildProcess {
 public:
  ChildProcess() = default;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess();  // kills a child still running, closes the pipes

  // Starts argv[0] with stdin from /dev/null and stdout and stderr appended
  // to output_path.
  bool Start(const std::vector<std::string>& argv, const std::string& output_path,
             std::string* error);
  // Starts argv[0] with pipes to its stdin and from its stdout (SendLine,
  // ReadUntil); stderr is appended to stderr_path.
  bool StartPiped(const std::vector<std::string>& argv, const std::string& stderr_path,
                  std::string* error);

  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }

  // Piped children: one line to stdin; lines from stdout until one starts
  // with `until` (true), or timeout_s of wall time pass or stdout closes (false).
  bool SendLine(const std::string& line);
  bool ReadUntil(const std::string& until, double timeout_s, std::vector<std::string>* lines);

  // Non-blocking. True once the child has ended; then *exit_code is its exit
  // status, or −N when signal N ended it.
  bool Finished(int* exit_code);
  // Blocks until the child ends; returns the exit code as Finished does
  // (-1 when no child is running).
  int Wait();
  // Sends `signal` (0: only closes stdin), waits up to grace_s for the end,
  // then SIGKILL. Returns the exit code as Finished does.
  int Stop(int signal, double grace_s);
  // SIGKILL and reap.
  void Kill();

 private:
  void ClosePipes();

  pid_t pid_ = -1;
  int to_child_ = -1;
  int from_child_ = -1;
  std::string pending_;  // stdout read but not yet returned as a line
};

// A path that starts the running executable: /proc/self/exe, so that the
// daemon's children (the nightly calibration and diagnosis) run the daemon's
// own version even after a package upgrade replaced or deleted its file
// under it (the file's own path then starts nothing, or another version).
// "pvtwin" (found on PATH) where /proc is not mounted.
std::string SelfExecutable();

// The last non-empty line of a child's output file (Start's output_path):
// why it failed, in its own words. Empty when the file is empty or missing.
std::string LastOutputLine(const std::string& output_path);

}  // namespace pvtwin
