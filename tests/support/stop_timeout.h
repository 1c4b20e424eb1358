// How long the daemon may take to stop. systemd sends SIGKILL
// TimeoutStopSec after SIGTERM (systemd/pvtwin.service), and the samples
// still in memory are lost with it. The tests that stop the daemon while a
// fetch, an upload or a fit hangs allow half of that: the daemon finishes
// the loop's pass in progress (one forecast at most, seconds under the
// sanitizers on a loaded machine), never the hanging work.
#pragma once

#include <filesystem>
#include <regex>
#include <string>

#include "tests/support/files.h"

namespace pvtwin::testing {

// TimeoutStopSec of the unit in the tree, in seconds ("30s" or "30"); 0
// when the unit has none, which fails every test that uses it.
inline double UnitStopTimeoutS() {
  const std::string unit =
      ReadFile(std::filesystem::path(PVTWIN_SOURCE_DIR) / "systemd" / "pvtwin.service");
  std::smatch m;
  if (!std::regex_search(unit, m, std::regex("\nTimeoutStopSec=([0-9]+)s?\n"))) return 0.0;
  return std::stod(m.str(1));
}

}  // namespace pvtwin::testing
