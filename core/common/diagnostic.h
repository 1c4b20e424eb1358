// A problem found in an input file or config, located precisely enough for a
// user to fix it: "file:line: key = value: rule" (STYLE.md, errors).
#pragma once

#include <string>
#include <vector>

namespace pvtwin {

struct Diagnostic {
  std::string file;
  int line = 0;       // 1-based; 0 when the problem is not tied to a line
  std::string field;  // config key or CSV column
  std::string value;  // the offending value as written (may be empty)
  std::string rule;   // what was expected

  // "file:line: field = value: rule", leaving out the parts that are empty;
  // field and value as PrintableExcerpt shows them.
  std::string ToString() const;
};

using Diagnostics = std::vector<Diagnostic>;

// Field and value excerpts in messages are cut to this many bytes.
inline constexpr std::size_t kMaxExcerptBytes = 80;

// text as a message may quote it: control bytes and invalid UTF-8 as \xNN,
// cut after kMaxExcerptBytes with the total length said ("... (1048576
// bytes)"), so a binary or huge cell never reaches a terminal or journal.
std::string PrintableExcerpt(const std::string& text);

}  // namespace pvtwin
