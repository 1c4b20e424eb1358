// A problem found in an input file or config, located precisely enough for a
// user to fix it: "file:line: key = value: rule" (STYLE.md, errors).
#pragma once

#include <string>
#include <vector>

namespace pvtwin {

struct Diagnostic {
  std::string file;
  int line = 0;         // 1-based; 0 when the problem is not tied to a line
  std::string field;    // config key or CSV column
  std::string value;    // the offending value as written (may be empty)
  std::string rule;     // what was expected

  // "file:line: field = value: rule", leaving out the parts that are empty.
  std::string ToString() const;
};

using Diagnostics = std::vector<Diagnostic>;

}  // namespace pvtwin
