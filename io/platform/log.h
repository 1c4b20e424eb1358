// Log lines of the long-running parts (poller, simulator, daemon): a priority
// as syslog/journald number it and one line of text. The daemon prints them
// to stderr with a "<N>" prefix, which journald reads as the priority.
#pragma once

#include <functional>
#include <string>

namespace pvtwin {

enum LogPriority { kErr = 3, kWarning = 4, kNotice = 5, kInfo = 6, kDebug = 7 };

using LogFn = std::function<void(int priority, const std::string& line)>;

// One line on stderr, one write per line (safe from several threads): "<N>line"
// under systemd (journald reads the priority), "HH:MM:SSZ level: line" otherwise.
void LogToStderr(int priority, const std::string& line);

}  // namespace pvtwin
