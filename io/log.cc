#include "io/log.h"

#include <unistd.h>

namespace pvtwin {

void LogToStderr(int priority, const std::string& line) {
  const std::string text = "<" + std::to_string(priority) + ">" + line + "\n";
  // One write(2): lines from several threads do not interleave.
  const ssize_t written = ::write(STDERR_FILENO, text.data(), text.size());
  (void)written;
}

}  // namespace pvtwin
