#include "io/platform/child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "core/common/clock.h"

extern char** environ;

namespace pvtwin {

namespace {

bool Spawn(const std::vector<std::string>& argv, posix_spawn_file_actions_t* actions, pid_t* pid,
           std::string* error) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const int rc = posix_spawn(pid, args[0], actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(actions);
  if (rc != 0) {
    *error = "cannot start " + argv[0] + ": " + std::strerror(rc);
    return false;
  }
  return true;
}

}  // namespace

ChildProcess::~ChildProcess() {
  Kill();
  ClosePipes();
}

void ChildProcess::ClosePipes() {
  if (to_child_ >= 0) ::close(to_child_);
  if (from_child_ >= 0) ::close(from_child_);
  to_child_ = from_child_ = -1;
  pending_.clear();
}

bool ChildProcess::Start(const std::vector<std::string>& argv, const std::string& output_path,
                         std::string* error) {
  if (running()) {
    *error = "a child process is already running";
    return false;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, output_path.c_str(),
                                   O_WRONLY | O_CREAT | O_APPEND, 0640);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  return Spawn(argv, &actions, &pid_, error);
}

bool ChildProcess::StartPiped(const std::vector<std::string>& argv, const std::string& stderr_path,
                              std::string* error) {
  if (running()) {
    *error = "a child process is already running";
    return false;
  }
  ClosePipes();
  int in[2], out[2];
  if (::pipe2(in, O_CLOEXEC) != 0) {
    *error = std::string("pipe: ") + std::strerror(errno);
    return false;
  }
  if (::pipe2(out, O_CLOEXEC) != 0) {
    *error = std::string("pipe: ") + std::strerror(errno);
    ::close(in[0]);
    ::close(in[1]);
    return false;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // dup2 onto 0/1 clears close-on-exec on the child's copies only.
  posix_spawn_file_actions_adddup2(&actions, in[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, stderr_path.c_str(),
                                   O_WRONLY | O_CREAT | O_APPEND, 0640);
  const bool ok = Spawn(argv, &actions, &pid_, error);
  ::close(in[0]);
  ::close(out[1]);
  to_child_ = in[1];
  from_child_ = out[0];
  if (!ok) ClosePipes();
  return ok;
}

bool ChildProcess::SendLine(const std::string& line) {
  if (to_child_ < 0) return false;
  const std::string text = line + "\n";
  return ::write(to_child_, text.data(), text.size()) == static_cast<ssize_t>(text.size());
}

bool ChildProcess::ReadUntil(const std::string& until, double timeout_s,
                             std::vector<std::string>* lines) {
  if (from_child_ < 0) return false;
  const double deadline = WallNowS() + timeout_s;
  for (;;) {
    for (std::size_t eol; (eol = pending_.find('\n')) != std::string::npos;) {
      lines->push_back(pending_.substr(0, eol));
      pending_.erase(0, eol + 1);
      if (lines->back().rfind(until, 0) == 0) return true;
    }
    const double left_s = deadline - WallNowS();
    if (left_s <= 0) return false;
    pollfd p{from_child_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left_s * 1000) + 1) <= 0) continue;
    char buf[1024];
    const ssize_t n = ::read(from_child_, buf, sizeof(buf));
    if (n <= 0) return false;
    pending_.append(buf, static_cast<std::size_t>(n));
  }
}

bool ChildProcess::Finished(int* exit_code) {
  if (!running()) return false;
  int status = 0;
  const pid_t r = ::waitpid(pid_, &status, WNOHANG);
  if (r == 0) return false;
  pid_ = -1;
  if (r < 0) {
    *exit_code = -SIGCHLD;
  } else if (WIFEXITED(status)) {
    *exit_code = WEXITSTATUS(status);
  } else {
    *exit_code = WIFSIGNALED(status) ? -WTERMSIG(status) : -1;
  }
  return true;
}

int ChildProcess::Wait() {
  if (!running()) return -1;
  int status = 0;
  pid_t r = -1;
  while ((r = ::waitpid(pid_, &status, 0)) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  if (r < 0) return -SIGCHLD;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return WIFSIGNALED(status) ? -WTERMSIG(status) : -1;
}

int ChildProcess::Stop(int signal, double grace_s) {
  int code = -SIGKILL;
  if (to_child_ >= 0) {
    ::close(to_child_);
    to_child_ = -1;
  }
  if (running() && signal != 0) ::kill(pid_, signal);
  const double deadline = WallNowS() + grace_s;
  while (running() && !Finished(&code) && WallNowS() < deadline) ::usleep(20000);
  if (running()) {
    Kill();
    code = -SIGKILL;
  }
  ClosePipes();
  return code;
}

void ChildProcess::Kill() {
  if (!running()) return;
  ::kill(pid_, SIGKILL);
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
}

std::string SelfExecutable() {
  // The kernel resolves this link to the image the process runs, also when
  // its file has been replaced or deleted since; the name readlink gives is
  // then "… (deleted)", which nothing can start.
  if (::access("/proc/self/exe", X_OK) == 0) return "/proc/self/exe";
  return "pvtwin";
}

std::string LastOutputLine(const std::string& output_path) {
  std::ifstream in(output_path);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

}  // namespace pvtwin
