#include "io/platform/log.h"

#include <unistd.h>

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

void LogToStderr(int priority, const std::string& line) {
  // Under systemd stderr is a journal stream (JOURNAL_STREAM is set) and the
  // "<N>" prefix carries the priority; on a terminal the time and the
  // priority's name read better.
  static const bool journal = std::getenv("JOURNAL_STREAM") != nullptr;
  std::string text;
  if (journal) {
    text = "<" + std::to_string(priority) + ">" + line + "\n";
  } else {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    ::gmtime_r(&now, &tm);
    char stamp[32];
    std::strftime(stamp, sizeof(stamp), "%H:%M:%SZ", &tm);
    text = std::string(stamp) + " " + PriorityName(priority) + ": " + line + "\n";
  }
  // One write(2): lines from several threads do not interleave.
  const ssize_t written = ::write(STDERR_FILENO, text.data(), text.size());
  (void)written;
}

}  // namespace pvtwin
