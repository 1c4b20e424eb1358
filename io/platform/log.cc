#include "io/platform/log.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <ctime>

namespace pvtwin {

namespace {

const char* PriorityName(int priority) {
  switch (priority) {
    case kErr:
      return "error";
    case kWarning:
      return "warning";
    case kNotice:
      return "notice";
    case kInfo:
      return "info";
    default:
      return "debug";
  }
}

}  // namespace

bool StderrIsTheJournal() {
  // systemd sets JOURNAL_STREAM to "<device>:<inode>" of the stream it
  // connected; a child that inherited the variable but writes elsewhere (a
  // terminal, a file) must not use the journal's prefix.
  const char* stream = std::getenv("JOURNAL_STREAM");
  if (stream == nullptr) return false;
  std::uintmax_t device = 0, inode = 0;
  if (std::sscanf(stream, "%ju:%ju", &device, &inode) != 2) return false;
  struct stat st {};
  if (::fstat(STDERR_FILENO, &st) != 0) return false;
  return static_cast<std::uintmax_t>(st.st_dev) == device &&
         static_cast<std::uintmax_t>(st.st_ino) == inode;
}

void LogToStderr(int priority, const std::string& line) {
  // Under systemd stderr is a journal stream and the "<N>" prefix carries the
  // priority; elsewhere the date, time (UTC) and the priority's name.
  static const bool journal = StderrIsTheJournal();
  std::string text;
  if (journal) {
    text = "<" + std::to_string(priority) + ">" + line + "\n";
  } else {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    ::gmtime_r(&now, &tm);
    char stamp[32];
    std::strftime(stamp, sizeof(stamp), "%Y-%m-%dT%H:%M:%SZ", &tm);
    text = std::string(stamp) + " " + PriorityName(priority) + ": " + line + "\n";
  }
  // One write(2): lines from several threads do not interleave.
  const ssize_t written = ::write(STDERR_FILENO, text.data(), text.size());
  (void)written;
}

}  // namespace pvtwin
