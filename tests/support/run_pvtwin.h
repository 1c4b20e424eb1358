// Runs the real pvtwin binary (PVTWIN_BINARY, set by tests/CMakeLists.txt) as
// a child process and captures its exit code, stdout and stderr.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/files.h"

namespace pvtwin::testing {

struct ProcessResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// A shell command line run in directory `dir`.
inline ProcessResult RunCommand(const std::filesystem::path& dir, const std::string& command_line) {
  namespace fs = std::filesystem;
  static int counter = 0;
  const fs::path err_path = fs::temp_directory_path() / ("pvtwin_test_" + std::to_string(getpid()) +
                                                         "_" + std::to_string(counter++) + ".err");
  const std::string command =
      "cd '" + dir.string() + "' && " + command_line + " 2>'" + err_path.string() + "'";
  ProcessResult run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buf;
  std::size_t n = 0;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) run.out.append(buf.data(), n);
  const int status = pclose(pipe);
  if (WIFEXITED(status)) run.exit_code = WEXITSTATUS(status);
  run.err = ReadFile(err_path);
  fs::remove(err_path);
  return run;
}

// `pvtwin <args>` run through the shell in directory `dir`.
inline ProcessResult RunPvtwin(const std::filesystem::path& dir, const std::string& args) {
  return RunCommand(dir, "'" + std::string(PVTWIN_BINARY) + "' " + args);
}

}  // namespace pvtwin::testing
