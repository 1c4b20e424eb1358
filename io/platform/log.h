// Log lines of the long-running parts (poller, simulator, daemon): a priority
// as syslog/journald number it and one line of text. The daemon prints them
// to stderr with a "<N>" prefix, which journald reads as the priority.
#pragma once

#include <functional>
#include <string>

namespace pvtwin {

enum LogPriority { kErr = 3, kWarning = 4, kNotice = 5, kInfo = 6, kDebug = 7 };

using LogFn = std::function<void(int priority, const std::string& line)>;

// Whether stderr is the journal stream systemd connected: JOURNAL_STREAM
// names its device and inode, and stderr is that file (not merely a process
// that inherited the variable and writes to a terminal or a file).
bool StderrIsTheJournal();

// One line on stderr, one write per line (safe from several threads): "<N>line"
// on the journal (journald reads the priority), "YYYY-MM-DDTHH:MM:SSZ level:
// line" otherwise.
void LogToStderr(int priority, const std::string& line);

}  // namespace pvtwin
